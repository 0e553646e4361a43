#include "pinball/firmware/can_frame.h"

#include <linux/can.h>
#include <linux/can/error.h>

#include <cstdio>

namespace pinball::firmware {

bool is_bus_off(const CanFrame& frame) { return frame.error && (frame.id & CAN_ERR_BUSOFF) != 0; }

bool is_restarted(const CanFrame& frame) { return frame.error && (frame.id & CAN_ERR_RESTARTED) != 0; }

CanFrame make_error_frame(std::uint32_t error_class) {
  CanFrame f;
  f.error = true;
  f.id = error_class & CAN_ERR_MASK;
  f.len = CAN_ERR_DLC;
  return f;
}

std::string to_candump(const CanFrame& frame) {
  char buf[48];
  int n = frame.error ? std::snprintf(buf, sizeof buf, "%08X#", static_cast<unsigned>(frame.id | CAN_ERR_FLAG))
                      : std::snprintf(buf, sizeof buf, "%03X#", static_cast<unsigned>(frame.id & CAN_SFF_MASK));
  for (int i = 0; i < frame.len && i < 8; ++i) {
    n += std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n), "%02X", frame.data[static_cast<std::size_t>(i)]);
  }
  return std::string(buf, static_cast<std::size_t>(n));
}

bool same_frame(const CanFrame& a, const CanFrame& b) {
  if (a.id != b.id || a.len != b.len || a.error != b.error) return false;
  for (int i = 0; i < a.len && i < 8; ++i) {
    if (a.data[static_cast<std::size_t>(i)] != b.data[static_cast<std::size_t>(i)]) return false;
  }
  return true;
}

}  // namespace pinball::firmware
