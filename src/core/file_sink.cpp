#include "pinball/core/file_sink.h"

#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <stdexcept>

namespace pinball {
namespace {

sigset_t sigpipe_set() {
  sigset_t s;
  sigemptyset(&s);
  sigaddset(&s, SIGPIPE);
  return s;
}

// Takes back the SIGPIPE that a failed write left pending on this thread (blocked there).
void consume_sigpipe() {
  const sigset_t s = sigpipe_set();
  sigset_t pending;
  if (sigpending(&pending) != 0 || sigismember(&pending, SIGPIPE) != 1) return;
  const timespec zero{0, 0};
  while (sigtimedwait(&s, nullptr, &zero) == SIGPIPE) {
  }
}

}  // namespace

bool write_if_ready(int fd, std::string_view text) {
  while (!text.empty()) {
    pollfd p{fd, POLLOUT, 0};
    if (::poll(&p, 1, 0) != 1 || (p.revents & POLLOUT) == 0) return false;
    const std::size_t piece = std::min<std::size_t>(text.size(), PIPE_BUF);
    const ssize_t n = ::write(fd, text.data(), piece);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    text.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

int exit_status_after_stdout(const char* program, int code) {
  std::cout.flush();
  const bool written = std::cout.good() && std::fflush(stdout) == 0 && std::ferror(stdout) == 0;
  if (written) return code;
  // The failed write was earlier, its errno long gone: the likely causes instead.
  std::fprintf(stderr, "%s: the output did not all reach standard output (a full disk, or its reader left)\n",
               program);
  return code == 0 ? 1 : code;
}

void block_sigpipe_in_this_thread() {
  const sigset_t s = sigpipe_set();
  pthread_sigmask(SIG_BLOCK, &s, nullptr);
}

FileSink::FileSink(const std::string& path, bool append) : path_(path) {
  // Non-blocking from the open on: a named pipe nobody reads yet is refused (ENXIO) rather
  // than waited on for good, and a full pipe makes write(2) return EAGAIN instead of holding
  // the thread.
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | O_NONBLOCK | (append ? O_APPEND : O_TRUNC), 0666);
  if (fd_ < 0 && errno == ENXIO) {
    throw std::runtime_error("cannot open " + path + " for writing: a named pipe that nobody reads yet (start its "
                             "reader first)");
  }
  if (fd_ < 0) throw std::runtime_error("cannot open " + path + " for writing: " + std::strerror(errno));
}

FileSink::~FileSink() { close(); }

SinkWrite FileSink::write(const char* data, std::size_t size, const std::function<bool()>& give_up,
                          double poll_s) {
  SinkWrite w;
  if (fd_ < 0 || gone_) {
    w.error = gone_ ? EPIPE : EBADF;
    return w;
  }
  while (w.bytes < size) {
    const ssize_t n = ::write(fd_, data + w.bytes, size - w.bytes);
    if (n > 0) {
      w.bytes += static_cast<std::size_t>(n);
      continue;
    }
    const int err = n < 0 ? errno : EIO;
    if (err == EINTR) continue;
    if (err == EAGAIN || err == EWOULDBLOCK) {
      if (wait_writable(give_up, poll_s)) continue;
      w.error = ETIMEDOUT;
      return w;
    }
    if (err == EPIPE) consume_sigpipe();
    // A pipe without a reader or a bad descriptor never takes bytes again; a full disk may.
    if (err == EPIPE || err == EBADF || err == EINVAL) gone_ = true;
    w.error = err;
    return w;
  }
  return w;
}

// Waits until the sink takes bytes again; false when `give_up` said so first.
bool FileSink::wait_writable(const std::function<bool()>& give_up, double poll_s) const {
  const int timeout_ms = std::max(1, static_cast<int>(std::lround(poll_s * 1e3)));
  for (;;) {
    // Asked first: a caller past its deadline pays no poll for each of the writes it still tries.
    if (give_up && give_up()) return false;
    pollfd p{fd_, POLLOUT, 0};
    if (::poll(&p, 1, timeout_ms) > 0) return true;  // writable, or an error that the next write names
  }
}

int FileSink::close() {
  if (fd_ < 0) return 0;
  const int r = ::close(fd_);
  fd_ = -1;
  return r == 0 ? 0 : errno;
}

}  // namespace pinball
