#include "pinball/firmware/stream_transport.h"

#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

#include "frame_io.h"

namespace pinball::firmware {

StreamTransport::StreamTransport(int fd, TxRetryPolicy retry) : fd_(fd), retry_(retry) {
  int type = 0;
  socklen_t len = sizeof type;
  if (fd < 0 || ::getsockopt(fd, SOL_SOCKET, SO_TYPE, &type, &len) != 0) {
    if (fd >= 0) ::close(fd);
    fd_ = -1;
    throw std::invalid_argument("StreamTransport: fd " + std::to_string(fd) + " is not a socket");
  }
  if (type != SOCK_SEQPACKET && type != SOCK_DGRAM) {
    ::close(fd);
    fd_ = -1;
    throw std::invalid_argument("StreamTransport: the socket must be SOCK_SEQPACKET or SOCK_DGRAM (one frame per message)");
  }
  const int on = 1;
  (void)::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);  // best effort; wall clock otherwise
}

StreamTransport::~StreamTransport() { close(); }

void StreamTransport::close() {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
}

std::pair<std::unique_ptr<StreamTransport>, std::unique_ptr<StreamTransport>> StreamTransport::make_pair(
    TxRetryPolicy retry) {
  int fds[2];
  if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0, fds) != 0) {
    throw std::runtime_error(std::string("StreamTransport: socketpair failed: ") + std::strerror(errno));
  }
  auto a = std::make_unique<StreamTransport>(fds[0], retry);
  auto b = std::make_unique<StreamTransport>(fds[1], retry);
  return {std::move(a), std::move(b)};
}

TxStatus StreamTransport::send(const CanFrame& frame) { return detail::send_frame(fd_, frame, retry_, counters_); }

TxStatus StreamTransport::send_without_waiting(const CanFrame& frame) {
  return detail::send_frame(fd_, frame, TxRetryPolicy{0, 0}, counters_);
}

RxStatus StreamTransport::receive(CanFrame& frame, int timeout_ms) {
  return detail::receive_frame(fd_, frame, timeout_ms, counters_);
}

}  // namespace pinball::firmware
