#include "display_check.h"

#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string_view>

namespace pinball::cli {
namespace {

std::string env(const char* name) {
  const char* value = std::getenv(name);
  return value == nullptr ? std::string() : std::string(value);
}

// A stream socket to `path` (a leading '@' is Linux's abstract namespace).
bool unix_answers(const std::string& path) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof(address.sun_path)) return false;
  std::memcpy(address.sun_path, path.data(), path.size());
  socklen_t length = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + path.size());
  if (path[0] == '@') address.sun_path[0] = '\0';
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  const bool ok = ::connect(fd, reinterpret_cast<const sockaddr*>(&address), length) == 0;
  ::close(fd);
  return ok;
}

// A TCP connection to host:port within `timeout_ms`.
bool tcp_answers(const std::string& host, int port, int timeout_ms) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found) != 0) return false;
  bool ok = false;
  for (const addrinfo* a = found; a != nullptr && !ok; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    if (::connect(fd, a->ai_addr, a->ai_addrlen) == 0) {
      ok = true;
    } else if (errno == EINPROGRESS) {
      pollfd p{fd, POLLOUT, 0};
      int error = 0;
      socklen_t size = sizeof error;
      ok = ::poll(&p, 1, timeout_ms) == 1 && ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &size) == 0 && error == 0;
    }
    ::close(fd);
  }
  ::freeaddrinfo(found);
  return ok;
}

}  // namespace

std::string display_problem() {
  const std::string platform = env("QT_QPA_PLATFORM");
  if (platform.starts_with("offscreen") || platform.starts_with("minimal")) return "";
  const std::string wayland = env("WAYLAND_DISPLAY");
  std::string wayland_problem;
  if (!wayland.empty()) {
    const std::string path = wayland[0] == '/' ? wayland : env("XDG_RUNTIME_DIR") + "/" + wayland;
    if (unix_answers(path)) return "";
    wayland_problem = "WAYLAND_DISPLAY " + wayland + ": no compositor answers at " + path;
  }
  const std::string display = env("DISPLAY");
  if (display.empty()) return wayland_problem.empty() ? "DISPLAY is not set" : wayland_problem;
  // [host]:number[.screen]; an empty host or "unix" is this machine's socket.
  const std::size_t colon = display.rfind(':');
  const std::string host = colon == std::string::npos ? std::string() : display.substr(0, colon);
  const std::string number = display.substr(colon == std::string::npos ? 0 : colon + 1);
  const std::size_t digits = number.find_first_not_of("0123456789");
  const std::string n = number.substr(0, digits);
  if (colon == std::string::npos || n.empty()) return "DISPLAY " + display + " names no display (host:number)";
  if (host.empty() || host == "unix") {
    const std::string socket = "/tmp/.X11-unix/X" + n;
    if (unix_answers(socket) || unix_answers("@" + socket)) return "";
    return "DISPLAY " + display + ": no X server answers at " + socket;
  }
  const int port = 6000 + std::atoi(n.c_str());
  if (tcp_answers(host, port, 1000)) return "";
  return "DISPLAY " + display + ": no X server answers at " + host + ":" + std::to_string(port) +
         " (a forwarding that has ended?)";
}

}  // namespace pinball::cli
