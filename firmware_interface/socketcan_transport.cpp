#include "pinball/firmware/socketcan_transport.h"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "frame_io.h"
#include "pinball/firmware/protocol.h"

namespace pinball::firmware {
namespace {

std::string errno_text(const char* call) { return std::string(call) + ": " + std::strerror(errno); }

}  // namespace

SocketCanTransport::SocketCanTransport(SocketCanOptions options) : options_(std::move(options)) {
  fd_ = open_socket();
}

SocketCanTransport::~SocketCanTransport() {
  if (fd_ >= 0) ::close(fd_);
}

std::string SocketCanTransport::unavailable_reason(const std::string& interface) {
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) return "socket(PF_CAN, SOCK_RAW, CAN_RAW) failed (" + std::string(std::strerror(errno)) + "): the kernel has no CAN support (modprobe can can_raw)";
  ::close(fd);
  if (::if_nametoindex(interface.c_str()) == 0) {
    return "no interface " + interface + " (" + std::strerror(errno) + "); create one with: ip link add dev vcan0 type vcan && ip link set vcan0 up";
  }
  return {};
}

int SocketCanTransport::open_socket() {
  const std::string where = "SocketCanTransport(" + options_.interface + "): ";
  if (options_.interface.empty() || options_.interface.size() >= IFNAMSIZ) {
    throw std::runtime_error(where + "interface name empty or longer than 15 characters");
  }
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) throw std::runtime_error(where + errno_text("socket(PF_CAN, SOCK_RAW, CAN_RAW)"));
  auto fail = [&](const char* call) {
    const std::string text = where + errno_text(call);
    ::close(fd);
    throw std::runtime_error(text);
  };
  // Only our standard-frame ids: 0x100..0x1FF, no extended, no remote frames.
  can_filter filter{};
  filter.can_id = kIdBase;
  filter.can_mask = kIdMask | CAN_EFF_FLAG | CAN_RTR_FLAG;
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, &filter, sizeof filter) != 0) fail("setsockopt(CAN_RAW_FILTER)");
  if (options_.error_frames) {
    const can_err_mask_t mask = CAN_ERR_TX_TIMEOUT | CAN_ERR_CRTL | CAN_ERR_BUSOFF | CAN_ERR_RESTARTED |
                                CAN_ERR_PROT | CAN_ERR_ACK | CAN_ERR_BUSERROR | CAN_ERR_TRX;
    if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &mask, sizeof mask) != 0) fail("setsockopt(CAN_RAW_ERR_FILTER)");
  }
  const int own = options_.receive_own ? 1 : 0;
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_RECV_OWN_MSGS, &own, sizeof own) != 0) fail("setsockopt(CAN_RAW_RECV_OWN_MSGS)");
  const int on = 1;
  if (::setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) != 0) fail("setsockopt(SO_TIMESTAMPNS)");
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, options_.interface.c_str(), IFNAMSIZ - 1);
  if (::ioctl(fd, SIOCGIFINDEX, &ifr) != 0) fail("ioctl(SIOCGIFINDEX)");
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) fail("bind");
  return fd;
}

bool SocketCanTransport::reopen() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  try {
    fd_ = open_socket();
  } catch (const std::runtime_error&) {
    counters_.tx_failures.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  return true;
}

TxStatus SocketCanTransport::send(const CanFrame& frame) {
  return detail::send_frame(fd_, frame, options_.retry, counters_);
}

TxStatus SocketCanTransport::send_without_waiting(const CanFrame& frame) {
  return detail::send_frame(fd_, frame, TxRetryPolicy{0, 0}, counters_);
}

RxStatus SocketCanTransport::receive(CanFrame& frame, int timeout_ms) {
  return detail::receive_frame(fd_, frame, timeout_ms, counters_);
}

}  // namespace pinball::firmware
