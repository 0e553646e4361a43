#include "pinball/firmware/stream_transport.h"

#include <gtest/gtest.h>
#include <linux/can/error.h>
#include <sys/socket.h>

#include "pinball/firmware/codec.h"

namespace pinball::firmware {
namespace {

TEST(StreamTransport, CarriesFramesBothWaysWithTimestamps) {
  auto [a, b] = StreamTransport::make_pair();
  const CanFrame sent = encode(3, Fire{2, FireMode::kPulseHold, 0, 77});
  ASSERT_EQ(a->send(sent), TxStatus::kOk);
  CanFrame got;
  ASSERT_EQ(b->receive(got, 100), RxStatus::kFrame);
  EXPECT_TRUE(same_frame(got, sent));
  EXPECT_GT(got.rx_time_ns, 1'000'000'000LL * 1'000'000'000LL / 1'000'000'000LL);  // a real time, not 0
  ASSERT_EQ(b->send(encode(3, Status{})), TxStatus::kOk);
  ASSERT_EQ(a->receive(got, 100), RxStatus::kFrame);
  EXPECT_TRUE(decode(got).ok());
  EXPECT_EQ(a->counters().tx_frames, 1u);
  EXPECT_EQ(a->counters().rx_frames, 1u);
}

TEST(StreamTransport, TimesOutAndReportsAClosedPeer) {
  auto [a, b] = StreamTransport::make_pair();
  CanFrame f;
  EXPECT_EQ(b->receive(f, 0), RxStatus::kTimeout);
  EXPECT_EQ(b->receive(f, 5), RxStatus::kTimeout);
  a->close();
  EXPECT_EQ(b->receive(f, 5), RxStatus::kDown);
  EXPECT_EQ(a->send(encode(0, ReleaseAll{})), TxStatus::kDown);
}

TEST(StreamTransport, ErrorFramesTravelAsErrorFrames) {
  auto [a, b] = StreamTransport::make_pair();
  ASSERT_EQ(a->send(make_error_frame(CAN_ERR_BUSOFF)), TxStatus::kOk);
  CanFrame f;
  ASSERT_EQ(b->receive(f, 100), RxStatus::kFrame);
  EXPECT_TRUE(f.error);
  EXPECT_TRUE(is_bus_off(f));
  EXPECT_EQ(b->counters().error_frames, 1u);
  EXPECT_EQ(decode(f).error, DecodeError::kErrorFrame);
}

TEST(StreamTransport, AFullQueueBacksOffThenFailsAndCounts) {
  TxRetryPolicy retry;
  retry.max_retries = 2;
  retry.first_backoff_us = 10;
  auto [a, b] = StreamTransport::make_pair(retry);
  TxStatus s = TxStatus::kOk;
  int sent = 0;
  for (; sent < 100'000 && s == TxStatus::kOk; ++sent) s = a->send(encode(0, Heartbeat{kProtocolVersion, 1}));
  EXPECT_EQ(s, TxStatus::kBufferFull);
  EXPECT_GT(sent, 10);
  EXPECT_EQ(a->counters().tx_retries, 2u);
  EXPECT_EQ(a->counters().tx_failures, 1u);
  CanFrame f;
  ASSERT_EQ(b->receive(f, 0), RxStatus::kFrame);  // draining frees space again
  EXPECT_EQ(a->send(encode(0, ReleaseAll{})), TxStatus::kOk);
}

TEST(StreamTransport, RefusesAByteStreamSocket) {
  int fds[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0);
  EXPECT_THROW(StreamTransport{fds[0]}, std::invalid_argument);
  EXPECT_THROW(StreamTransport{fds[1]}, std::invalid_argument);  // both closed by the constructor
  EXPECT_THROW(StreamTransport{-1}, std::invalid_argument);
}

}  // namespace
}  // namespace pinball::firmware
