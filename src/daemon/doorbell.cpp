#include "pinball/daemon/doorbell.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

namespace pinball::daemon {

Doorbell::Doorbell() : fd_(eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {
  if (fd_ < 0) throw std::runtime_error(std::string("eventfd: ") + std::strerror(errno));
}

Doorbell::~Doorbell() {
  if (fd_ >= 0) close(fd_);
}

void Doorbell::ring() const {
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = write(fd_, &one, sizeof one);
}

bool Doorbell::wait(double timeout_s) const {
  std::uint64_t value = 0;
  if (read(fd_, &value, sizeof value) == static_cast<ssize_t>(sizeof value)) return true;
  pollfd p{fd_, POLLIN, 0};
  const int ms = timeout_s < 0.0 ? -1 : static_cast<int>(std::ceil(timeout_s * 1e3));
  if (poll(&p, 1, ms) <= 0) return false;
  return read(fd_, &value, sizeof value) == static_cast<ssize_t>(sizeof value);
}

}  // namespace pinball::daemon
