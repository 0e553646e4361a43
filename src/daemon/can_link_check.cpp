#include "pinball/daemon/can_link_check.h"

#include "pinball/firmware/can_link.h"

namespace pinball::daemon {

std::string check_can_link(const CanSettings& can) {
  const firmware::CanLinkStatus status = firmware::read_can_link(can.interface);
  const firmware::CanLinkVerdict verdict = firmware::judge_can_link(status, can.interface, can.bitrate_bps);
  if (!verdict.ok) {
    throw ConfigError("can.interface: " + verdict.message + "; can.bitrate_bps is " +
                      std::to_string(can.bitrate_bps));
  }
  return verdict.message.empty() ? "" : "can.interface: " + verdict.message;
}

}  // namespace pinball::daemon
