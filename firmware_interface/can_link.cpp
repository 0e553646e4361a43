#include "pinball/firmware/can_link.h"

#include <libsocketcan.h>
#include <linux/can/netlink.h>
#include <net/if_arp.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace pinball::firmware {

static_assert(static_cast<int>(CanControllerState::kErrorActive) == CAN_STATE_ERROR_ACTIVE);
static_assert(static_cast<int>(CanControllerState::kBusOff) == CAN_STATE_BUS_OFF);
static_assert(static_cast<int>(CanControllerState::kStopped) == CAN_STATE_STOPPED);
static_assert(static_cast<int>(CanControllerState::kSleeping) == CAN_STATE_SLEEPING);

CanLinkStatus read_can_link(const std::string& interface) {
  CanLinkStatus s;
  if (interface.empty() || interface.size() >= IFNAMSIZ) {
    s.read_error = "not an interface name";
    return s;
  }
  // Flags through any datagram socket: this works without PF_CAN in the kernel.
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    s.read_error = std::string("socket: ") + std::strerror(errno);
    return s;
  }
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, interface.c_str(), IFNAMSIZ - 1);
  const bool found = ::ioctl(fd, SIOCGIFFLAGS, &ifr) == 0;
  const int flags_errno = errno;
  if (found) s.up = (ifr.ifr_flags & IFF_UP) != 0;
  const bool typed = found && ::ioctl(fd, SIOCGIFHWADDR, &ifr) == 0;
  ::close(fd);
  if (!found) {
    s.read_error = std::strerror(flags_errno);
    return s;
  }
  s.exists = true;
  s.is_can = typed && ifr.ifr_hwaddr.sa_family == ARPHRD_CAN;
  if (!s.is_can) return s;
  std::error_code ec;
  s.is_virtual = std::filesystem::exists("/sys/devices/virtual/net/" + interface, ec);
  if (s.is_virtual) return s;  // vcan: no controller to ask
  int state = -1;
  if (::can_get_state(interface.c_str(), &state) == 0) {
    s.state = static_cast<CanControllerState>(state);
  } else {
    s.read_error = "libsocketcan could not read the controller's state";
  }
  can_bittiming bt{};
  if (::can_get_bittiming(interface.c_str(), &bt) == 0) {
    s.bitrate_bps = bt.bitrate;
  } else if (s.read_error.empty()) {
    s.read_error = "libsocketcan could not read the bit timing";
  }
  __u32 restart_ms = 0;
  if (::can_get_restart_ms(interface.c_str(), &restart_ms) == 0) s.restart_ms = restart_ms;
  return s;
}

std::string driver_board_lock_path(const std::string& interface, int board_id) {
  std::error_code ec;
  const std::filesystem::path folder =
      ::access("/run/lock", W_OK) == 0 ? std::filesystem::path("/run/lock") : std::filesystem::temp_directory_path(ec);
  return (folder / ("pinball-" + interface + "-board" + std::to_string(board_id) + ".lock")).string();
}

WriterLock lock_driver_board(const std::string& interface, int board_id) {
  const std::string path = driver_board_lock_path(interface, board_id);
  return WriterLock(path, interface + " board " + std::to_string(board_id) +
                              " is driven by another process (a pinballd service, or a calibrate latency: `fuser " +
                              path + "` names it): two hosts would each switch off the other's coils");
}

std::string can_bring_up_command(const std::string& interface, std::uint32_t bitrate_bps) {
  return "sudo ip link set " + interface + " down; sudo ip link set " + interface + " up type can bitrate " +
         std::to_string(bitrate_bps) + " restart-ms 100";
}

CanLinkVerdict judge_can_link(const CanLinkStatus& s, const std::string& interface, std::uint32_t bitrate_bps) {
  const std::string fix = " (" + can_bring_up_command(interface, bitrate_bps) + ")";
  const auto refuse = [](std::string why) { return CanLinkVerdict{false, std::move(why)}; };
  if (!s.exists) {
    return refuse("no interface " + interface + (s.read_error.empty() ? "" : " (" + s.read_error + ")") +
                  "; `ip -details link show type can` lists the CAN interfaces (a virtual one for tests: "
                  "`sudo modprobe vcan; sudo ip link add dev " + interface + " type vcan; sudo ip link set " +
                  interface + " up`)");
  }
  if (!s.is_can) return refuse(interface + " is not a CAN interface; `ip -details link show type can` lists them");
  // A virtual interface has no bit rate to set: it only needs to be up.
  if (!s.up && s.is_virtual) return refuse(interface + " is down (sudo ip link set " + interface + " up)");
  if (!s.up) return refuse(interface + " is down" + fix);
  if (s.is_virtual) {
    return {true, interface + " is a virtual interface: no controller, no bit rate to check"};
  }
  switch (s.state) {
    case CanControllerState::kBusOff:
      return refuse(interface + " is bus-off: the controller sends nothing (check the wiring, the termination "
                                "and every node's bit rate; then" + fix + ")");
    case CanControllerState::kStopped: return refuse(interface + " is stopped" + fix);
    case CanControllerState::kSleeping: return refuse(interface + " is asleep" + fix);
    case CanControllerState::kUnknown:
      return refuse("cannot read " + interface + "'s controller state (" +
                    (s.read_error.empty() ? std::string("unknown") : s.read_error) +
                    "): is it a CAN interface? `ip -details link show " + interface + "`");
    case CanControllerState::kErrorActive:
    case CanControllerState::kErrorWarning:
    case CanControllerState::kErrorPassive: break;
  }
  if (s.bitrate_bps == 0) return refuse(interface + " has no bit rate set" + fix);
  if (s.bitrate_bps != bitrate_bps) {
    return refuse(interface + " runs at " + std::to_string(s.bitrate_bps) + " bit/s, the bus at " +
                  std::to_string(bitrate_bps) + fix);
  }
  if (s.restart_ms == 0) {
    return refuse(interface + " has no automatic restart after bus-off: one bus-off would silence it until "
                              "someone runs `ip link set " + interface + " type can restart`" + fix);
  }
  if (s.state == CanControllerState::kErrorPassive || s.state == CanControllerState::kErrorWarning) {
    return {true, interface + " is error-" + (s.state == CanControllerState::kErrorPassive ? "passive" : "warning") +
                      ": frames are being lost on the bus (`ip -details -statistics link show " + interface +
                      "`)"};
  }
  return {true, ""};
}

}  // namespace pinball::firmware
