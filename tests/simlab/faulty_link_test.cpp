#include "pinball/simlab/faulty_link.h"

#include <gtest/gtest.h>

#include <vector>

#include "pinball/firmware/codec.h"
#include "pinball/firmware/stream_transport.h"

namespace pinball::simlab {
namespace {

std::vector<std::uint16_t> pass(FaultyLinkOptions o, int n, FaultyLinkCounters* counters = nullptr) {
  auto [a, b] = firmware::StreamTransport::make_pair();
  FaultyLink link(*a, o);
  std::vector<std::uint16_t> seen;
  for (int i = 1; i <= n; ++i) {
    EXPECT_EQ(link.send(firmware::encode(0, firmware::Heartbeat{firmware::kProtocolVersion, static_cast<std::uint16_t>(i)})), firmware::TxStatus::kOk);
    firmware::CanFrame f;
    while (b->receive(f, 0) == firmware::RxStatus::kFrame) {
      const firmware::DecodeResult r = firmware::decode(f);
      seen.push_back(r.ok() ? std::get<firmware::Heartbeat>(r.message.payload).seq : 0);  // 0: corrupted
    }
  }
  if (counters != nullptr) *counters = link.fault_counters();
  return seen;
}

TEST(FaultyLink, IsTransparentWithNoFaults) {
  const auto seen = pass({}, 50);
  ASSERT_EQ(seen.size(), 50u);
  for (int i = 0; i < 50; ++i) EXPECT_EQ(seen[static_cast<std::size_t>(i)], i + 1);
}

TEST(FaultyLink, SameSeedSameFaults) {
  FaultyLinkOptions o;
  o.drop_p = o.delay_p = o.duplicate_p = o.corrupt_p = 0.2;
  o.seed = 11;
  EXPECT_EQ(pass(o, 300), pass(o, 300));
  FaultyLinkOptions other = o;
  other.seed = 12;
  EXPECT_NE(pass(o, 300), pass(other, 300));
}

TEST(FaultyLink, EachFaultDoesWhatItSays) {
  FaultyLinkCounters c;
  FaultyLinkOptions o;
  o.drop_p = 0.3;
  auto seen = pass(o, 1000, &c);
  EXPECT_NEAR(static_cast<double>(c.dropped), 300.0, 60.0);
  EXPECT_EQ(seen.size(), 1000u - c.dropped);

  o = {};
  o.duplicate_p = 0.5;
  seen = pass(o, 200, &c);
  EXPECT_EQ(seen.size(), 200u + c.duplicated);

  o = {};
  o.delay_p = 0.3;
  o.max_delay_frames = 3;
  seen = pass(o, 200, &c);
  int inversions = 0;
  for (std::size_t i = 1; i < seen.size(); ++i) inversions += seen[i] < seen[i - 1];
  EXPECT_GT(inversions, 10);  // reordered
  EXPECT_GT(c.delayed, 30u);

  o = {};
  o.corrupt_p = 1.0;
  seen = pass(o, 200, &c);
  EXPECT_EQ(c.corrupted, 200u);
  for (std::uint16_t s : seen) EXPECT_EQ(s, 0) << "a corrupted frame decoded";
}

TEST(FaultyLink, AppliesToReceivedFramesToo) {
  auto [a, b] = firmware::StreamTransport::make_pair();
  FaultyLinkOptions o;
  o.on_send = false;
  o.on_receive = true;
  o.duplicate_p = 1.0;
  FaultyLink link(*b, o);
  ASSERT_EQ(a->send(firmware::encode(0, firmware::ReleaseAll{1})), firmware::TxStatus::kOk);
  firmware::CanFrame f;
  EXPECT_EQ(link.receive(f, 10), firmware::RxStatus::kFrame);
  EXPECT_EQ(link.receive(f, 0), firmware::RxStatus::kFrame);
  EXPECT_EQ(link.receive(f, 0), firmware::RxStatus::kTimeout);
}

TEST(FaultyLink, RejectsBadProbabilities) {
  auto [a, b] = firmware::StreamTransport::make_pair();
  FaultyLinkOptions o;
  o.drop_p = 1.5;
  EXPECT_THROW(FaultyLink(*a, o), std::invalid_argument);
  o = {};
  o.max_delay_frames = 0;
  EXPECT_THROW(FaultyLink(*a, o), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::simlab
