#include "pinball/firmware/frame_log.h"

#include <gtest/gtest.h>
#include <linux/can/error.h>

#include <fstream>
#include <string>

#include "pinball/firmware/codec.h"

namespace pinball::firmware {
namespace {

TEST(FrameLog, FormatsLikeCandump) {
  CanFrame f;
  f.id = 0x123;
  f.len = 4;
  f.data = {0xDE, 0xAD, 0xBE, 0xEF};
  EXPECT_EQ(format_log_line(f, 1700000000.123456, "can0"), "(1700000000.123456) can0 123#DEADBEEF");
  EXPECT_EQ(to_candump(make_error_frame(CAN_ERR_BUSOFF)), "20000040#0000000000000000");
  f.len = 0;
  EXPECT_EQ(format_log_line(f, 1.9999999, "vcan0"), "(2.000000) vcan0 123#");
}

TEST(FrameLog, ParsesWhatItWrites) {
  for (const CanFrame& f : {encode(2, Fire{1, FireMode::kPulseHold, 0, 9}), encode(0, Status{}), make_error_frame(CAN_ERR_CRTL)}) {
    const auto e = parse_log_line(format_log_line(f, 12.5, "can0"));
    ASSERT_TRUE(e.has_value());
    EXPECT_TRUE(same_frame(e->frame, f)) << to_candump(f);
    EXPECT_EQ(e->interface, "can0");
    EXPECT_DOUBLE_EQ(e->time_s, 12.5);
  }
  for (const char* bad : {"", "can0 123#00", "(1.0) can0 12#00", "(x) can0 123#00", "(1.0) can0 123#0", "(1.0) can0 123#GG",
                          "(1.0) can0 12345678#00", "(1.0) can0 123#000000000000000000"}) {
    EXPECT_FALSE(parse_log_line(bad).has_value()) << bad;
  }
}

TEST(FrameLog, WritesOneLinePerFrameToAFile) {
  const std::string path = ::testing::TempDir() + "/frame_log_test.log";
  {
    FrameLog log(path, "can0");
    log.record(encode(0, Heartbeat{kProtocolVersion, 1}), 100.0);
    log.record(encode(0, Heartbeat{kProtocolVersion, 2}), 100.02);
    EXPECT_EQ(log.lines(), 2u);
  }
  std::ifstream in(path);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    const auto e = parse_log_line(line);
    ASSERT_TRUE(e.has_value()) << line;
    const DecodeResult r = decode(e->frame);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(std::get<Heartbeat>(r.message.payload).seq, ++n);
  }
  EXPECT_EQ(n, 2);
  EXPECT_THROW(FrameLog("/nonexistent-dir/x.log"), std::runtime_error);
}

}  // namespace
}  // namespace pinball::firmware
