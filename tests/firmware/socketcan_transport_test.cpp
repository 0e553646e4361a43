#include "pinball/firmware/socketcan_transport.h"

#include <gtest/gtest.h>

#include "pinball/firmware/codec.h"

namespace pinball::firmware {
namespace {

// Needs a kernel with CAN and a virtual interface:
//   modprobe vcan && ip link add dev vcan0 type vcan && ip link set vcan0 up
TEST(SocketCanTransport, LoopsAFrameThroughVcan0WithAKernelTimestamp) {
  const std::string why = SocketCanTransport::unavailable_reason("vcan0");
  if (!why.empty()) GTEST_SKIP() << "SocketCAN unavailable here: " << why;
  SocketCanOptions o;
  o.interface = "vcan0";
  SocketCanTransport tx(o);
  SocketCanTransport rx(o);
  const CanFrame sent = encode(1, Fire{0, FireMode::kPulseHold, 0, 5});
  ASSERT_EQ(tx.send(sent), TxStatus::kOk);
  CanFrame got;
  ASSERT_EQ(rx.receive(got, 200), RxStatus::kFrame);
  EXPECT_TRUE(same_frame(got, sent));
  EXPECT_GT(got.rx_time_ns, 0);
  // The filter drops ids that are not ours.
  CanFrame foreign = sent;
  foreign.id = 0x321;
  ASSERT_EQ(tx.send(foreign), TxStatus::kOk);
  EXPECT_EQ(rx.receive(got, 50), RxStatus::kTimeout);
  EXPECT_TRUE(rx.reopen());
}

TEST(SocketCanTransport, AMissingInterfaceIsAClearError) {
  const std::string why = SocketCanTransport::unavailable_reason("nosuchcan9");
  EXPECT_FALSE(why.empty());
  SocketCanOptions o;
  o.interface = "nosuchcan9";
  try {
    SocketCanTransport t(o);
    FAIL() << "opened a missing interface";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nosuchcan9"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pinball::firmware
