#include "pinball/firmware/can_link.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <stdexcept>
#include <string>

#include <unistd.h>

namespace pinball::firmware {
namespace {

// A real controller, up, error-active, at `bitrate_bps`.
CanLinkStatus healthy(std::uint32_t bitrate_bps = 500000) {
  CanLinkStatus s;
  s.exists = true;
  s.up = true;
  s.is_can = true;
  s.state = CanControllerState::kErrorActive;
  s.bitrate_bps = bitrate_bps;
  return s;
}

TEST(CanLink, AHealthyInterfaceAtTheBusRateStarts) {
  const CanLinkVerdict v = judge_can_link(healthy(), "can0", 500000);
  EXPECT_TRUE(v.ok);
  EXPECT_EQ(v.message, "");
}

TEST(CanLink, AnotherBitRateIsRefusedSayingBoth) {
  const CanLinkVerdict v = judge_can_link(healthy(1000000), "can0", 500000);
  EXPECT_FALSE(v.ok);
  EXPECT_EQ(v.message,
            "can0 runs at 1000000 bit/s, the bus at 500000 (sudo ip link set can0 down; sudo ip link set can0 up "
            "type can bitrate 500000 restart-ms 100)");
  CanLinkStatus unset = healthy(0);
  EXPECT_FALSE(judge_can_link(unset, "can0", 500000).ok);
}

TEST(CanLink, DownStoppedAsleepOrBusOffIsRefused) {
  CanLinkStatus down = healthy();
  down.up = false;
  down.state = CanControllerState::kStopped;
  CanLinkVerdict v = judge_can_link(down, "can0", 500000);
  EXPECT_FALSE(v.ok);
  EXPECT_EQ(v.message.rfind("can0 is down (sudo ip link set can0 down; sudo ip link set can0 up type can bitrate "
                            "500000 restart-ms 100)", 0),
            0u)
      << v.message;
  for (CanControllerState state : {CanControllerState::kStopped, CanControllerState::kSleeping,
                                   CanControllerState::kBusOff, CanControllerState::kUnknown}) {
    CanLinkStatus s = healthy();
    s.state = state;
    v = judge_can_link(s, "can0", 500000);
    EXPECT_FALSE(v.ok) << static_cast<int>(state);
    EXPECT_NE(v.message.find("can0"), std::string::npos) << v.message;
  }
  CanLinkStatus off = healthy();
  off.state = CanControllerState::kBusOff;
  EXPECT_NE(judge_can_link(off, "can0", 500000).message.find("bus-off"), std::string::npos);
}

// Reopening a socket restarts no controller: without restart-ms one bus-off silenced the board for good.
TEST(CanLink, NoAutomaticRestartAfterBusOffIsRefused) {
  CanLinkStatus s = healthy();
  s.restart_ms = 0;
  const CanLinkVerdict v = judge_can_link(s, "can0", 500000);
  EXPECT_FALSE(v.ok);
  EXPECT_EQ(v.message.rfind("can0 has no automatic restart after bus-off", 0), 0u) << v.message;
  EXPECT_NE(v.message.find("restart-ms 100"), std::string::npos) << v.message;
  s.restart_ms = 100;
  EXPECT_TRUE(judge_can_link(s, "can0", 500000).ok);
  s.restart_ms = -1;  // not read (an old kernel): the bit rate and state checks stand alone
  EXPECT_TRUE(judge_can_link(s, "can0", 500000).ok);
}

// Two hosts on one board each switched off the other's coils (pinballd's service and a calibrate latency).
TEST(CanLink, OneHostAtATimeDrivesABoard) {
  const std::string iface = "pbtest" + std::to_string(::getpid() % 100000);
  const std::string path = driver_board_lock_path(iface, 3);
  EXPECT_NE(path.find("pinball-" + iface + "-board3.lock"), std::string::npos) << path;
  {
    const WriterLock first = lock_driver_board(iface, 3);
    try {
      (void)lock_driver_board(iface, 3);
      ADD_FAILURE() << "a second host took the board";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()).rfind(iface + " board 3 is driven by another process", 0), 0u) << e.what();
      EXPECT_NE(std::string(e.what()).find("`fuser " + path + "`"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW((void)lock_driver_board(iface, 4)) << "another board on the same bus is free";
  }
  EXPECT_NO_THROW((void)lock_driver_board(iface, 3)) << "released with its holder";
  std::remove(path.c_str());
  std::remove(driver_board_lock_path(iface, 4).c_str());
}

TEST(CanLink, ErrorPassiveStartsWithAWarning) {
  CanLinkStatus s = healthy();
  s.state = CanControllerState::kErrorPassive;
  const CanLinkVerdict v = judge_can_link(s, "can0", 500000);
  EXPECT_TRUE(v.ok);
  EXPECT_NE(v.message.find("error-passive"), std::string::npos) << v.message;
}

TEST(CanLink, AVirtualInterfaceHasNoBitRateAndIsAccepted) {
  CanLinkStatus s;
  s.exists = true;
  s.up = true;
  s.is_can = true;
  s.is_virtual = true;
  const CanLinkVerdict v = judge_can_link(s, "vcan0", 500000);
  EXPECT_TRUE(v.ok);
  EXPECT_EQ(v.message, "vcan0 is a virtual interface: no controller, no bit rate to check");
  s.up = false;
  const CanLinkVerdict down = judge_can_link(s, "vcan0", 500000);
  EXPECT_FALSE(down.ok);  // but it must be up, and bringing it up needs no bit rate
  EXPECT_EQ(down.message, "vcan0 is down (sudo ip link set vcan0 up)");
}

TEST(CanLink, AMissingInterfaceIsNamed) {
  const CanLinkStatus s = read_can_link("nosuchcan7");
  EXPECT_FALSE(s.exists);
  const CanLinkVerdict v = judge_can_link(s, "nosuchcan7", 500000);
  EXPECT_FALSE(v.ok);
  EXPECT_EQ(v.message.rfind("no interface nosuchcan7", 0), 0u) << v.message;
}

// The loopback interface exists and is up, and is no CAN controller: the
// reader must say so without throwing, and the judge refuse it.
TEST(CanLink, ANonCanInterfaceIsRefused) {
  const CanLinkStatus s = read_can_link("lo");
  if (!s.exists) GTEST_SKIP() << "no loopback interface here";
  EXPECT_TRUE(s.up);
  EXPECT_FALSE(s.is_can);
  const CanLinkVerdict v = judge_can_link(s, "lo", 500000);
  EXPECT_FALSE(v.ok);
  EXPECT_EQ(v.message, "lo is not a CAN interface; `ip -details link show type can` lists them");
}

}  // namespace
}  // namespace pinball::firmware
