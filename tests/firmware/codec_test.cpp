#include "pinball/firmware/codec.h"

#include <gtest/gtest.h>

#include <vector>

#include "pinball/core/rng.h"

namespace pinball::firmware {
namespace {

std::vector<Payload> one_of_each() {
  return {Hello{kProtocolVersion, 250},
          HelloAck{kProtocolVersion, 6, 2, 7},
          Configure{3, DriverConfig{25, 30, 35, 4000, 12}},
          Fire{7, FireMode::kPulseOnly, 20, 0xBEEF},
          Release{5, 0x1234},
          ReleaseAll{0xFFFF},
          Heartbeat{kProtocolVersion, 42},
          Status{0x2A19, 0x81, 0x0F, kFaultBitWatchdog | kFaultBitArmed, 999},
          Fault{FaultCode::kHoldCapReached, 2, 5000, 17}};
}

TEST(Codec, EveryMessageRoundTrips) {
  for (const Payload& p : one_of_each()) {
    for (std::uint8_t board : {0, 5, 15}) {
      const CanFrame f = encode(board, p);
      EXPECT_EQ(f.id, make_id(kind_of(p), board));
      EXPECT_EQ(f.len, frame_length(static_cast<std::uint8_t>(kind_of(p))));
      const DecodeResult r = decode(f);
      ASSERT_TRUE(r.ok()) << r.reason;
      EXPECT_EQ(r.message.board, board);
      ASSERT_EQ(r.message.payload.index(), p.index());
      // Re-encoding the decoded message gives the same bytes.
      EXPECT_TRUE(same_frame(encode(board, r.message.payload), f));
    }
  }
  const DecodeResult c = decode(encode(1, Configure{3, DriverConfig{25, 30, 35, 4000, 12}}));
  const auto& cfg = std::get<Configure>(c.message.payload).config;
  EXPECT_EQ(cfg.pulse_ms, 25);
  EXPECT_EQ(cfg.hold_duty_pct, 30);
  EXPECT_EQ(cfg.max_pulse_ms, 35);
  EXPECT_EQ(cfg.max_hold_ms, 4000);
  EXPECT_EQ(cfg.recycle_ms, 12);
  const auto st = std::get<Status>(decode(encode(0, Status{0x2A19, 0x81, 0x0F, 0x81, 999})).message.payload);
  EXPECT_EQ(st.coil(0), CoilState::kPulse);
  EXPECT_EQ(st.coil(1), CoilState::kHold);
  EXPECT_EQ(st.last_seq, 999);
}

TEST(Codec, ByteLayoutIsLittleEndianWithCrcLast) {
  const CanFrame f = encode(2, Fire{4, FireMode::kPulseHold, 0, 0x1234});
  EXPECT_EQ(f.id, 0x122u);
  ASSERT_EQ(f.len, 6);
  EXPECT_EQ(f.data[0], 4);
  EXPECT_EQ(f.data[1], 1);
  EXPECT_EQ(f.data[2], 0);
  EXPECT_EQ(f.data[3], 0x34);  // seq low byte first
  EXPECT_EQ(f.data[4], 0x12);
  EXPECT_EQ(f.data[5], frame_crc(0x122, std::span<const std::uint8_t>(f.data.data(), 5)));
  EXPECT_EQ(to_candump(f), "122#040100341277");  // the example in PROTOCOL.md
  // The CRC covers the id: the same bytes under another board's id fail.
  CanFrame other = f;
  other.id = 0x123;
  EXPECT_EQ(decode(other).error, DecodeError::kBadChecksum);
}

TEST(Codec, ReleaseAllHasTheHighestPriorityId) {
  for (const Payload& p : one_of_each()) {
    EXPECT_LE(encode(0, ReleaseAll{}).id, encode(0, p).id);
  }
}

// Re-seals a frame after tampering so that only the tampered check fails.
CanFrame reseal(CanFrame f) {
  f.data[f.len - 1u] = frame_crc(f.id, std::span<const std::uint8_t>(f.data.data(), f.len - 1u));
  return f;
}

TEST(Codec, RejectsEveryMalformedCase) {
  struct Case {
    const char* name;
    CanFrame frame;
    DecodeError expected;
  };
  std::vector<Case> cases;
  CanFrame f = encode(0, Release{1, 2});
  cases.push_back({"error frame", make_error_frame(0x40), DecodeError::kErrorFrame});
  f.id = 0x200;
  cases.push_back({"foreign id", f, DecodeError::kForeignId});
  f.id = 0x1000;
  cases.push_back({"id above 11 bits", f, DecodeError::kForeignId});
  f = encode(0, Release{1, 2});
  f.id = kIdBase | (0x6u << 4);
  cases.push_back({"unknown kind 6", reseal(f), DecodeError::kUnknownKind});
  f.id = kIdBase | (0xFu << 4);
  cases.push_back({"unknown kind 15", reseal(f), DecodeError::kUnknownKind});
  for (const Payload& p : one_of_each()) {
    CanFrame longer = encode(0, p);
    if (longer.len < 8) {
      ++longer.len;
      cases.push_back({"one byte too long", reseal(longer), DecodeError::kWrongLength});
    }
    CanFrame shorter = encode(0, p);
    --shorter.len;
    cases.push_back({"one byte too short", reseal(shorter), DecodeError::kWrongLength});
    CanFrame flipped = encode(0, p);
    flipped.data[0] ^= 0x10;
    cases.push_back({"bit flip", flipped, DecodeError::kBadChecksum});
  }
  CanFrame empty = encode(0, ReleaseAll{});
  empty.len = 0;
  cases.push_back({"empty", empty, DecodeError::kWrongLength});
  auto tamper = [&](const char* name, const Payload& p, int byte, std::uint8_t value, DecodeError e) {
    CanFrame t = encode(0, p);
    t.data[static_cast<std::size_t>(byte)] = value;
    cases.push_back({name, reseal(t), e});
  };
  tamper("Hello version", Hello{}, 0, kProtocolVersion + 1, DecodeError::kWrongVersion);
  tamper("HelloAck version", HelloAck{}, 0, 0, DecodeError::kWrongVersion);
  tamper("Heartbeat version", Heartbeat{}, 0, 99, DecodeError::kWrongVersion);
  cases.push_back({"Hello watchdog too short", encode(0, Hello{kProtocolVersion, 9}), DecodeError::kOutOfRange});
  cases.push_back({"Hello watchdog too long", encode(0, Hello{kProtocolVersion, 1001}), DecodeError::kOutOfRange});
  tamper("HelloAck 0 drivers", HelloAck{}, 1, 0, DecodeError::kOutOfRange);
  tamper("HelloAck 9 drivers", HelloAck{}, 1, 9, DecodeError::kOutOfRange);
  cases.push_back({"Configure driver 8", encode(0, Configure{8, {}}), DecodeError::kOutOfRange});
  cases.push_back({"Configure pulse 0", encode(0, Configure{0, {0, 25, 40, 100, 0}}), DecodeError::kOutOfRange});
  cases.push_back({"Configure pulse > max", encode(0, Configure{0, {41, 25, 40, 100, 0}}), DecodeError::kOutOfRange});
  cases.push_back({"Configure max pulse > abs", encode(0, Configure{0, {30, 25, 101, 100, 0}}), DecodeError::kOutOfRange});
  cases.push_back({"Configure duty > abs", encode(0, Configure{0, {30, 51, 40, 100, 0}}), DecodeError::kOutOfRange});
  cases.push_back({"Configure hold 0", encode(0, Configure{0, {30, 25, 40, 0, 0}}), DecodeError::kOutOfRange});
  cases.push_back({"Configure hold > abs", encode(0, Configure{0, {30, 25, 40, 10001, 0}}), DecodeError::kOutOfRange});
  cases.push_back({"Fire driver 8", encode(0, Fire{8, FireMode::kPulseHold, 0, 1}), DecodeError::kOutOfRange});
  tamper("Fire mode 2", Fire{}, 1, 2, DecodeError::kOutOfRange);
  cases.push_back({"Fire pulse > abs", encode(0, Fire{0, FireMode::kPulseHold, 101, 1}), DecodeError::kOutOfRange});
  cases.push_back({"Release driver 9", encode(0, Release{9, 1}), DecodeError::kOutOfRange});
  cases.push_back({"Status coil state 3", encode(0, Status{0x0300, 0, 0, 0, 0}), DecodeError::kOutOfRange});
  cases.push_back({"Status reserved bit", encode(0, Status{0, 0, 0, 0x40, 0}), DecodeError::kOutOfRange});
  tamper("Fault code 0", Fault{}, 0, 0, DecodeError::kOutOfRange);
  tamper("Fault code 10", Fault{}, 0, 10, DecodeError::kOutOfRange);
  tamper("Fault driver 8", Fault{}, 1, 8, DecodeError::kOutOfRange);
  for (const Case& c : cases) {
    const DecodeResult r = decode(c.frame);
    EXPECT_EQ(r.error, c.expected) << c.name << ": got " << to_string(r.error) << " (" << r.reason << ")";
    EXPECT_FALSE(r.ok()) << c.name;
    EXPECT_GT(std::string(r.reason).size(), 3u) << c.name;
  }
}

TEST(Codec, ValidateNamesTheBadField) {
  EXPECT_EQ(validate(DriverConfig{}), nullptr);
  EXPECT_NE(std::string(validate(DriverConfig{50, 25, 40, 100, 0})).find("pulse_ms"), std::string::npos);
  EXPECT_NE(std::string(validate(DriverConfig{30, 60, 40, 100, 0})).find("hold_duty_pct"), std::string::npos);
}

TEST(Codec, FuzzRandomBytesAlwaysGetAVerdict) {
  Rng rng(20240601);
  int ok = 0;
  int by_error[8] = {};
  for (int i = 0; i < 300'000; ++i) {
    CanFrame f;
    const std::uint64_t a = rng.next_u64();
    // Half the frames use our id range so the later checks are reached.
    f.id = (i % 2 == 0) ? static_cast<std::uint32_t>(kIdBase | (a & 0xFF)) : static_cast<std::uint32_t>(a & 0x1FFFFFFF);
    f.len = static_cast<std::uint8_t>((a >> 32) % 10);  // includes invalid 9
    if (f.len > 8) f.len = 8;
    const std::uint64_t b = rng.next_u64();
    for (int k = 0; k < 8; ++k) f.data[static_cast<std::size_t>(k)] = k < f.len ? static_cast<std::uint8_t>(b >> (8 * k)) : 0;
    if (i % 4 == 2) {  // right length and CRC: exercise the range checks
      const int len = frame_length(static_cast<std::uint8_t>((f.id >> 4) & 0x0F));
      if (len > 0) {
        f.len = static_cast<std::uint8_t>(len);
        for (int k = 0; k < 8; ++k) f.data[static_cast<std::size_t>(k)] = k < f.len ? static_cast<std::uint8_t>(b >> (8 * k)) : 0;
        f = reseal(f);
      }
    }
    const DecodeResult r = decode(f);
    ASSERT_LE(static_cast<int>(r.error), static_cast<int>(DecodeError::kWrongVersion));
    ++by_error[static_cast<int>(r.error)];
    if (r.ok()) {
      ++ok;
      // Anything accepted is canonical: it re-encodes to the same frame.
      ASSERT_TRUE(same_frame(encode(r.message.board, r.message.payload), f)) << to_candump(f);
    } else {
      ASSERT_NE(r.reason, nullptr);
    }
  }
  EXPECT_GT(ok, 100);  // the fuzzer reaches valid messages
  EXPECT_GT(by_error[static_cast<int>(DecodeError::kBadChecksum)], 1000);
  EXPECT_GT(by_error[static_cast<int>(DecodeError::kOutOfRange)], 100);
  EXPECT_GT(by_error[static_cast<int>(DecodeError::kWrongLength)], 1000);
}

}  // namespace
}  // namespace pinball::firmware
