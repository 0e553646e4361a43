#pragma once
// Bring-up check of a SocketCAN interface: read what the kernel says about it
// (up or down, the controller's state, its bit rate: libsocketcan), then
// judge it with a plain function, so that the rules are tested without CAN
// hardware. A host that talks to the board on a bus that is down, bus-off or
// at another bit rate gets no answer, or destroys every frame on the wire:
// pinballd refuses to start instead (docs/daemon.md, CAN bring-up).

#include <cstdint>
#include <string>

#include "pinball/core/writer_lock.h"

namespace pinball::firmware {

/// The controller's state, as linux/can/netlink.h numbers it (CAN_STATE_*).
enum class CanControllerState : int {
  kUnknown = -1,      ///< not read (a virtual interface has none)
  kErrorActive = 0,   ///< normal: error counters < 96
  kErrorWarning = 1,  ///< error counters >= 96: still sends
  kErrorPassive = 2,  ///< error counters >= 128: still sends, but something on the bus is wrong
  kBusOff = 3,        ///< error counter >= 256: the controller sends nothing until restarted
  kStopped = 4,       ///< the interface is down
  kSleeping = 5,      ///< the controller sleeps
};

/// What the kernel says about one CAN interface.
struct CanLinkStatus {
  bool exists = false;      ///< an interface of that name is there
  bool up = false;          ///< administratively up (IFF_UP)
  bool is_can = false;      ///< a CAN interface (link type ARPHRD_CAN), real or virtual
  bool is_virtual = false;  ///< vcan, vxcan: no controller, no bit rate
  CanControllerState state = CanControllerState::kUnknown;  ///< the controller's state
  std::uint32_t bitrate_bps = 0;  ///< the configured bit rate (bit/s); 0: unknown or not set
  /// The automatic restart after bus-off (ms; 0: none, the controller stays
  /// off until `ip link ... restart`); -1: not read.
  std::int64_t restart_ms = -1;
  std::string read_error;   ///< why state or bit rate could not be read (empty: read, or virtual)
};

/// Whether to start on an interface, and why.
struct CanLinkVerdict {
  bool ok = false;      ///< true: start
  std::string message;  ///< the reason to refuse, or a note when ok (a virtual interface); "" when all is well
};

/// Reads `interface`'s flags (SIOCGIFFLAGS), its link type (SIOCGIFHWADDR), whether it is virtual
/// (/sys/devices/virtual/net) and, for a real controller, its state, bit
/// rate and restart (libsocketcan: can_get_state, can_get_bittiming,
/// can_get_restart_ms). Never throws.
CanLinkStatus read_can_link(const std::string& interface);

/// The rules: refuse an interface that is missing, not CAN, down, stopped, asleep,
/// bus-off, of unknown state, at a bit rate other than `bitrate_bps`, or with no
/// automatic restart after bus-off (reopening the socket restarts no controller); a
/// virtual interface has no bit rate and is accepted with a note. Messages
/// name the interface and say the command that fixes it.
CanLinkVerdict judge_can_link(const CanLinkStatus& status, const std::string& interface, std::uint32_t bitrate_bps);

/// The lock file of driver board `board_id` on `interface`, which the one
/// host that drives it holds (pinballd in the lab, `calibrate latency`):
/// under /run/lock, or the temporary folder where there is none. Two hosts on
/// one board each switched off the other's coils, both reporting "running".
std::string driver_board_lock_path(const std::string& interface, int board_id);

/// Takes that lock, or throws std::runtime_error naming the interface, the
/// board, the lock file and what to do (another process holds it).
WriterLock lock_driver_board(const std::string& interface, int board_id);

/// The `ip link` command that brings `interface` up at `bitrate_bps`, with
/// the automatic restart after bus-off that PROTOCOL.md asks for.
std::string can_bring_up_command(const std::string& interface, std::uint32_t bitrate_bps);

}  // namespace pinball::firmware
