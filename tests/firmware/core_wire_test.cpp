// The C core's wire format (firmware_interface/core/wire.c), tested through its C API:
// the layout PROTOCOL.md gives, every kind both ways, and every single-bit
// error caught.

#include "pinball/firmware/core/wire.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace {

pbfw_message fire(std::uint8_t board, std::uint8_t driver, std::uint8_t mode, std::uint8_t pulse_ms, std::uint16_t seq) {
  pbfw_message m{};
  m.board = board;
  m.kind = PBFW_FIRE;
  m.u.fire = {driver, mode, pulse_ms, seq};
  return m;
}

std::string hex(const pbfw_frame& f) {
  static const char* digits = "0123456789ABCDEF";
  std::string s;
  for (unsigned i = 0; i < f.len; ++i) {
    s += digits[f.data[i] >> 4];
    s += digits[f.data[i] & 15];
  }
  return s;
}

// One valid message of every kind.
std::vector<pbfw_message> one_of_each() {
  std::vector<pbfw_message> out;
  pbfw_message m{};
  m.board = 3;
  m.kind = PBFW_HELLO;
  m.u.hello = {PBFW_PROTOCOL_VERSION, 250};
  out.push_back(m);
  m.kind = PBFW_HELLO_ACK;
  m.u.hello_ack = {PBFW_PROTOCOL_VERSION, 6, 1, 4};
  out.push_back(m);
  m.kind = PBFW_CONFIGURE;
  m.u.configure = {5, {30, 25, 40, 5000, 10}};
  out.push_back(m);
  out.push_back(fire(3, 7, PBFW_PULSE_HOLD, 0, 0xBEEF));
  m.kind = PBFW_RELEASE;
  m.u.release = {2, 0x8001};
  out.push_back(m);
  m.kind = PBFW_RELEASE_ALL;
  m.u.release_all = {0xFFFF};
  out.push_back(m);
  m.kind = PBFW_HEARTBEAT;
  m.u.heartbeat = {PBFW_PROTOCOL_VERSION, 42};
  out.push_back(m);
  m.kind = PBFW_STATUS;
  m.u.status = {0x2A11, 0x81, 0xFF, PBFW_FAULT_BIT_ARMED | PBFW_FAULT_BIT_HOLD_CAP, 1234};
  out.push_back(m);
  m.kind = PBFW_FAULT;
  m.u.fault = {PBFW_FAULT_STALE, 4, 0x1234, 9};
  out.push_back(m);
  return out;
}

TEST(CoreWire, FireIsLaidOutAsProtocolMdSays) {
  pbfw_frame f;
  const pbfw_message m = fire(2, 4, PBFW_PULSE_HOLD, 0, 0x1234);
  pbfw_encode(&m, &f);
  EXPECT_EQ(f.id, 0x122u);
  EXPECT_EQ(hex(f), "040100341277");  // PROTOCOL.md's example, CRC included
}

TEST(CoreWire, EveryKindRoundTripsAtItsFixedLength) {
  for (const pbfw_message& m : one_of_each()) {
    pbfw_frame f;
    pbfw_encode(&m, &f);
    EXPECT_EQ(f.len, pbfw_frame_length(m.kind)) << "kind " << m.kind;
    pbfw_message back{};
    const char* reason = nullptr;
    ASSERT_EQ(pbfw_decode(&f, &back, &reason), PBFW_DECODE_OK) << "kind " << m.kind << ": " << reason;
    EXPECT_EQ(back.board, m.board);
    EXPECT_EQ(back.kind, m.kind);
    pbfw_frame again;
    pbfw_encode(&back, &again);
    EXPECT_EQ(hex(again), hex(f)) << "kind " << m.kind;
  }
}

TEST(CoreWire, EverySingleBitErrorIsRejected) {
  for (const pbfw_message& m : one_of_each()) {
    pbfw_frame f;
    pbfw_encode(&m, &f);
    for (unsigned bit = 0; bit < 8u * f.len; ++bit) {
      pbfw_frame bad = f;
      bad.data[bit / 8] = static_cast<std::uint8_t>(bad.data[bit / 8] ^ (1u << (bit % 8)));
      EXPECT_EQ(pbfw_decode(&bad, nullptr, nullptr), PBFW_DECODE_BAD_CHECKSUM) << "kind " << m.kind << " bit " << bit;
    }
    // The id is covered too: a bit flipped in the kind or board nibble.
    for (unsigned bit = 0; bit < 4; ++bit) {
      pbfw_frame bad = f;
      bad.id ^= 1u << bit;
      EXPECT_EQ(pbfw_decode(&bad, nullptr, nullptr), PBFW_DECODE_BAD_CHECKSUM) << "kind " << m.kind << " id bit " << bit;
    }
  }
}

TEST(CoreWire, RejectsWithTheReasonANamedCheckGives) {
  pbfw_frame f;
  const char* reason = nullptr;
  // Wrong length.
  pbfw_message m = fire(0, 1, 0, 0, 1);
  pbfw_encode(&m, &f);
  f.len = 5;
  EXPECT_EQ(pbfw_decode(&f, nullptr, &reason), PBFW_DECODE_WRONG_LENGTH);
  // Out of range, re-sealed so only the range check can catch it.
  m = fire(0, 8, 0, 0, 1);
  pbfw_encode(&m, &f);
  EXPECT_EQ(pbfw_decode(&f, nullptr, &reason), PBFW_DECODE_OUT_OF_RANGE);
  EXPECT_STREQ(reason, "Fire: driver >= 8");
  m = fire(0, 1, 2, 0, 1);
  pbfw_encode(&m, &f);
  EXPECT_EQ(pbfw_decode(&f, nullptr, &reason), PBFW_DECODE_OUT_OF_RANGE);
  m = fire(0, 1, 0, 101, 1);
  pbfw_encode(&m, &f);
  EXPECT_EQ(pbfw_decode(&f, nullptr, &reason), PBFW_DECODE_OUT_OF_RANGE);
  // A configuration past an absolute cap.
  m = pbfw_message{};
  m.kind = PBFW_CONFIGURE;
  m.u.configure = {0, {30, 51, 40, 5000, 10}};
  pbfw_encode(&m, &f);
  EXPECT_EQ(pbfw_decode(&f, nullptr, &reason), PBFW_DECODE_OUT_OF_RANGE);
  // Another protocol version.
  m = pbfw_message{};
  m.kind = PBFW_HEARTBEAT;
  m.u.heartbeat = {1, 7};
  pbfw_encode(&m, &f);
  EXPECT_EQ(pbfw_decode(&f, nullptr, &reason), PBFW_DECODE_WRONG_VERSION);
  // Not ours at all.
  f.id = 0x080;
  EXPECT_EQ(pbfw_decode(&f, nullptr, &reason), PBFW_DECODE_FOREIGN_ID);
  f.id = 0x170;  // kind 7 does not exist
  EXPECT_EQ(pbfw_decode(&f, nullptr, &reason), PBFW_DECODE_UNKNOWN_KIND);
  f.error = true;
  EXPECT_EQ(pbfw_decode(&f, nullptr, &reason), PBFW_DECODE_ERROR_FRAME);
}

// The CRC as PROTOCOL.md defines it, bit by bit.
std::uint8_t crc8_by_definition(std::uint32_t id, const std::uint8_t* bytes, unsigned n) {
  std::uint8_t crc = 0xFF;
  auto feed = [&crc](std::uint8_t b) {
    crc ^= b;
    for (int i = 0; i < 8; ++i) crc = (crc & 0x80) ? static_cast<std::uint8_t>((crc << 1) ^ 0x2F) : static_cast<std::uint8_t>(crc << 1);
  };
  feed(static_cast<std::uint8_t>(id & 0xFF));
  feed(static_cast<std::uint8_t>((id >> 8) & 0x07));
  for (unsigned i = 0; i < n; ++i) feed(bytes[i]);
  return static_cast<std::uint8_t>(crc ^ 0xFF);
}

TEST(CoreWire, TheCrcTableIsTheBitwiseDefinition) {
  std::uint8_t bytes[7];
  std::uint32_t x = 12345;
  for (int trial = 0; trial < 20000; ++trial) {
    for (auto& b : bytes) {
      x = x * 1664525u + 1013904223u;  // any bytes will do; a fixed LCG keeps the test repeatable
      b = static_cast<std::uint8_t>(x >> 24);
    }
    const std::uint32_t id = (x >> 8) & 0x7FF;
    const unsigned n = x % 8;
    ASSERT_EQ(pbfw_crc8(id, bytes, n), crc8_by_definition(id, bytes, n)) << "trial " << trial;
  }
}

TEST(CoreWire, ConfigurationLimitsAreTheAbsoluteOnes) {
  pbfw_driver_config c{30, 25, 40, 5000, 10};
  EXPECT_EQ(pbfw_validate_config(&c), nullptr);
  c.max_pulse_ms = 101;
  EXPECT_NE(pbfw_validate_config(&c), nullptr);
  c = {41, 25, 40, 5000, 10};  // pulse above its own cap
  EXPECT_NE(pbfw_validate_config(&c), nullptr);
  c = {30, 25, 40, 10001, 10};
  EXPECT_NE(pbfw_validate_config(&c), nullptr);
  c = {30, 0, 40, 1, 0};  // no hold, shortest hold cap, no recycle: valid
  EXPECT_EQ(pbfw_validate_config(&c), nullptr);
}

TEST(CoreWire, SerialArithmeticOrdersAcrossTheWrap) {
  EXPECT_TRUE(pbfw_seq_newer(1, 0));
  EXPECT_TRUE(pbfw_seq_newer(0, 0xFFFF));
  EXPECT_FALSE(pbfw_seq_newer(5, 5));
  EXPECT_FALSE(pbfw_seq_newer(0x8000, 0));  // exactly half way: neither is newer
  EXPECT_TRUE(pbfw_seq_newer(0x7FFF, 0));
}

}  // namespace
