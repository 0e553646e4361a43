#include "pinball/firmware/frame_log.h"

#include <gtest/gtest.h>
#include <linux/can/error.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

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
  // No stamp overflows the cast (UBSan float-cast-overflow): impossible ones are written as 0.
  for (const double bad : {std::nan(""), -1.0, 1e300}) EXPECT_EQ(format_log_line(f, bad, "can0"), "(0.000000) can0 123#");
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
    EXPECT_TRUE(log.flush());
    EXPECT_EQ(log.counters().written, 2u);
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

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The writer thread must not change a byte of what format_log_line gives, nor lose a frame
// when the sink keeps up.
TEST(FrameLog, ANormalRunWritesEveryFrameByteForByte) {
  const std::string path = ::testing::TempDir() + "/frame_log_all_" + std::to_string(getpid()) + ".log";
  constexpr int kFrames = 20000;
  std::string expected;
  FrameLogCounters c;
  {
    FrameLog log(path, "simcan");
    for (int i = 0; i < kFrames; ++i) {
      const CanFrame f = encode(1, Fire{static_cast<std::uint8_t>(i % 2), FireMode::kPulseHold, 0,
                                        static_cast<std::uint16_t>(i)});
      const double t = 1700000000.0 + i * 1e-4;
      expected += format_log_line(f, t, "simcan") + "\n";
      log.record(f, t);
      // Bursts of 1000, far faster than any CAN bus, each drained before the
      // next: a fixed 2 ms pause between them failed on a loaded 2-core
      // machine, where the writer thread can wait longer than that for a core.
      if (i % 1000 == 999) {
        ASSERT_TRUE(log.flush());
      }
    }
    log.close();
    c = log.counters();
  }
  EXPECT_EQ(c.written, static_cast<std::uint64_t>(kFrames));
  EXPECT_EQ(c.dropped(), 0u);
  EXPECT_TRUE(c.complete());
  EXPECT_EQ(c.first_errno, 0);
  EXPECT_EQ(c.first_error, "");
  EXPECT_EQ(read_all(path), expected);
  std::remove(path.c_str());
}

// The pipe's write end opened by path, as `pinballd --can-log /dev/stdout | ...` would.
std::string pipe_path(int fd) { return "/proc/self/fd/" + std::to_string(fd); }

TEST(FrameLog, RecordNeverBlocksOnAPipeNobodyReadsAndCloseEnds) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  ::testing::internal::CaptureStderr();
  constexpr int kFrames = 100000;
  FrameLogCounters c;
  double close_s = 0.0;
  {
    FrameLog log(pipe_path(fds[1]), "can0", 0.2);
    const CanFrame f = encode(0, Heartbeat{kProtocolVersion, 7});
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < kFrames; ++i) log.record(f, 1.0 + i);
    const double record_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_LT(record_s, 2.0);  // a blocked sink would hold the first record that fills the pipe forever
    const auto t1 = std::chrono::steady_clock::now();
    log.close();
    close_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    c = log.counters();
  }
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_LT(close_s, 1.5);  // 0.2 s to give the sink, and a poll period
  EXPECT_GT(c.dropped_queue_full, 0u);
  EXPECT_GT(c.dropped_at_close, 0u);
  EXPECT_EQ(c.written + c.dropped(), static_cast<std::uint64_t>(kFrames));  // every frame accounted for
  EXPECT_NE(err.find("queue of 8192 frames full"), std::string::npos) << err;
  EXPECT_NE(c.first_error.find(pipe_path(fds[1])), std::string::npos) << c.first_error;
  ::close(fds[0]);
  ::close(fds[1]);
}

TEST(FrameLog, APipeWhoseReaderLeftCountsDropsAndDoesNotKillTheProcess) {
  // SIGPIPE keeps its default action here (death): the writer must not raise it at the process.
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  ::testing::internal::CaptureStderr();
  FrameLogCounters c;
  {
    FrameLog log(pipe_path(fds[1]), "can0", 0.2);
    ::close(fds[0]);  // the reader goes away
    ::close(fds[1]);
    for (int i = 0; i < 1000; ++i) log.record(encode(0, Heartbeat{kProtocolVersion, 1}), 1.0);
    EXPECT_TRUE(log.flush());
    c = log.counters();
  }
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(c.written, 0u);
  EXPECT_EQ(c.dropped_write_error, 1000u);
  EXPECT_EQ(c.first_errno, EPIPE);
  EXPECT_NE(err.find(std::strerror(EPIPE)), std::string::npos) << err;
}

TEST(FrameLog, AFullDiskReportsTheErrorOnceAndCountsTheDrops) {
  ::testing::internal::CaptureStderr();
  FrameLogCounters c;
  {
    FrameLog log("/dev/full", "can0");
    for (int round = 0; round < 3; ++round) {
      for (int i = 0; i < 300; ++i) log.record(encode(0, Heartbeat{kProtocolVersion, 1}), 1.0);
      EXPECT_TRUE(log.flush());  // several batches, several failed writes
    }
    c = log.counters();
  }
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(c.written, 0u);
  EXPECT_EQ(c.dropped_write_error, 900u);
  EXPECT_FALSE(c.complete());
  EXPECT_EQ(c.first_errno, ENOSPC);
  EXPECT_NE(c.first_error.find("/dev/full: write failed: No space left on device"), std::string::npos)
      << c.first_error;
  // Once per kind of error, not once per frame.
  const std::size_t first = err.find("No space left on device");
  ASSERT_NE(first, std::string::npos) << err;
  EXPECT_EQ(err.find("No space left on device", first + 1), std::string::npos) << err;
}

TEST(FrameLog, FramesRecordedAfterCloseAreCountedAsDropped) {
  const std::string path = ::testing::TempDir() + "/frame_log_closed_" + std::to_string(getpid()) + ".log";
  FrameLog log(path, "can0");
  log.record(encode(0, Heartbeat{kProtocolVersion, 1}), 1.0);
  log.close();
  log.record(encode(0, Heartbeat{kProtocolVersion, 2}), 2.0);
  log.close();  // idempotent
  const FrameLogCounters c = log.counters();
  EXPECT_EQ(c.written, 1u);
  EXPECT_EQ(c.dropped_at_close, 1u);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace pinball::firmware
