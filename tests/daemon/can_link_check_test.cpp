#include "pinball/daemon/can_link_check.h"

#include <gtest/gtest.h>

#include <string>

namespace pinball::daemon {
namespace {

std::string refusal(const std::string& interface) {
  CanSettings can;
  can.interface = interface;
  try {
    (void)check_can_link(can);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

// The decisions themselves are tests/firmware/can_link_test.cpp's; here, that
// pinballd's refusal names the key (this machine has no CAN interface).
TEST(CanLinkCheck, ARefusalNamesTheKey) {
  EXPECT_EQ(refusal("nosuchcan7").rfind("can.interface: no interface nosuchcan7", 0), 0u) << refusal("nosuchcan7");
  EXPECT_EQ(refusal("lo"),
            "can.interface: lo is not a CAN interface; `ip -details link show type can` lists them; "
            "can.bitrate_bps is 500000");
}

}  // namespace
}  // namespace pinball::daemon
