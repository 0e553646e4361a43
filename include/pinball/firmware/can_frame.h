#pragma once
// One classic CAN 2.0 frame as the host sees it: id, up to 8 bytes, and the
// kernel's receive time. Error frames (SocketCAN's CAN_ERR_FLAG) use the same
// struct with `error` set and the error class in `id`.

#include <array>
#include <cstdint>
#include <string>

namespace pinball::firmware {

/// A CAN frame (data or error).
struct CanFrame {
  std::uint32_t id = 0;                   ///< 11-bit id; for error frames the CAN_ERR_* class bits
  std::uint8_t len = 0;                   ///< data bytes, 0..8
  bool error = false;                     ///< an error frame reported by the controller, not data
  std::array<std::uint8_t, 8> data{};     ///< payload (bytes past len are zero)
  std::int64_t rx_time_ns = 0;            ///< receive time (ns since the epoch, kernel timestamp when there is one); 0 on send
};

/// True when the frame is an error frame reporting bus-off.
bool is_bus_off(const CanFrame& frame);
/// True when the frame is an error frame reporting a controller restart (after bus-off).
bool is_restarted(const CanFrame& frame);

/// An error frame with the given CAN_ERR_* class bits (for transports and tests).
CanFrame make_error_frame(std::uint32_t error_class);

/// candump's compact form: "123#DEADBEEF" (error frames: "20000040#...").
std::string to_candump(const CanFrame& frame);

/// Equality of id, kind, length and the first `len` bytes (timestamps ignored).
bool same_frame(const CanFrame& a, const CanFrame& b);

}  // namespace pinball::firmware
