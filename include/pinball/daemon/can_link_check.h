#pragma once
// pinballd's CAN bring-up check: before it opens a SocketCAN interface, the
// daemon reads the interface's state and bit rate (firmware/can_link.h) and
// refuses, naming `can.interface`, one that is missing, down, bus-off or at
// another rate than `can.bitrate_bps`.

#include <string>

#include "pinball/daemon/daemon_config.h"

namespace pinball::daemon {

/// Throws ConfigError ("can.interface: can0 is down (sudo ip link set ...)")
/// when `can.interface` is not fit to run; returns a note worth a warning
/// (a virtual interface, an error-passive bus), or "".
std::string check_can_link(const CanSettings& can);

}  // namespace pinball::daemon
