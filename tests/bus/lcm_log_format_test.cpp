#include "pinball/bus/lcm_log_format.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <lcm/lcm-cpp.hpp>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

#include "common/temp_path.h"

namespace pinball::bus {
namespace {

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

std::string two_events() {
  std::string log;
  const unsigned char a[3] = {1, 2, 3};
  append_lcm_event(log, 0, 1700000000000000, "PINBALL_OBSERVATION", a, sizeof a);
  append_lcm_event(log, 1, 1700000000000500, "PINBALL_STATS", nullptr, 0);
  return log;
}

TEST(LcmLogFormat, LiblcmReadsWhatIsWrittenHere) {
  const std::string path = pinball::testing::temp_path("lcm_log_format", "good.lcmlog");
  write_file(path, two_events());
  lcm::LogFile in(path, "r");
  ASSERT_TRUE(in.good());
  const lcm::LogEvent* e = in.readNextEvent();
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->eventnum, 0);
  EXPECT_EQ(e->timestamp, 1700000000000000);
  EXPECT_EQ(e->channel, "PINBALL_OBSERVATION");
  ASSERT_EQ(e->datalen, 3);
  EXPECT_EQ(static_cast<const unsigned char*>(e->data)[2], 3);
  e = in.readNextEvent();
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->eventnum, 1);
  EXPECT_EQ(e->channel, "PINBALL_STATS");
  EXPECT_EQ(e->datalen, 0);
  EXPECT_EQ(in.readNextEvent(), nullptr);
  const LcmLogCheck c = check_lcm_log(path);
  EXPECT_TRUE(c.ok) << c.problem;
  EXPECT_EQ(c.events, 2u);
  std::remove(path.c_str());
}

// `pinball replay FIFO` with no writer had waited for ever, and with one failed on "Illegal seek".
TEST(LcmLogFormat, APipeIsRefusedBeforeItIsOpened) {
  const std::string fifo = testing::temp_path("lcm_log_format", "log.fifo");
  std::remove(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  try {
    require_lcm_log(fifo);
    ADD_FAILURE() << "a pipe was read";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              fifo + ": is a pipe: an LCM log is read twice (checked, then played); give the file itself");
  }
  std::remove(fifo.c_str());
}

TEST(LcmLogFormat, HeaderFieldsAreBigEndian) {
  std::string log;
  append_lcm_event(log, 0x0102030405060708, -2, "AB", "xyz", 3);
  ASSERT_EQ(log.size(), kLcmEventHeaderBytes + 5);
  EXPECT_EQ(static_cast<unsigned char>(log[0]), 0xED);
  EXPECT_EQ(static_cast<unsigned char>(log[3]), 0x01);
  const LcmEventHeader h = read_lcm_event_header(reinterpret_cast<const unsigned char*>(log.data()));
  EXPECT_EQ(h.sync, kLcmLogSync);
  EXPECT_EQ(h.event_number, 0x0102030405060708);
  EXPECT_EQ(h.utime, -2);
  EXPECT_EQ(h.channel_bytes, 2);
  EXPECT_EQ(h.data_bytes, 3);
  EXPECT_EQ(log.substr(kLcmEventHeaderBytes), "ABxyz");
}

// Each damage is found at the byte where it starts, whatever comes before it.
TEST(LcmLogFormat, TheCheckNamesTheOffsetOfEachDamage) {
  const std::string good = two_events();
  const std::uint64_t end = good.size();
  std::string bad_length = good;
  append_lcm_event(bad_length, 2, 0, "PINBALL_OBSERVATION", "abcd", 4);
  bad_length[end + 24] = 0x7F;  // data length 0x7f000004
  std::string no_channel = good;
  append_lcm_event(no_channel, 2, 0, "", "abcd", 4);
  std::string bad_sync = good + good;
  bad_sync[end] = 0x00;
  struct Case {
    const char* name;
    std::string bytes;
    std::uint64_t offset;
    const char* words;
  };
  const Case cases[] = {
      {"truncated header", good + good.substr(0, 12), end, "truncated event header (12 of 28 bytes)"},
      {"truncated payload", good + good.substr(0, 30), end, "the file has 30 left"},
      {"huge length", bad_length, end, "data length 2130706436"},
      {"no channel", no_channel, end, "bad channel length 0"},
      {"bad sync mid-file", bad_sync, end, "sync word 0x00A1DA01"},
  };
  for (const Case& k : cases) {
    const std::string path = pinball::testing::temp_path("lcm_log_format", "bad.lcmlog");
    write_file(path, k.bytes);
    const LcmLogCheck c = check_lcm_log(path);
    EXPECT_FALSE(c.ok) << k.name;
    EXPECT_EQ(c.offset, k.offset) << k.name;
    EXPECT_EQ(c.events, 2u) << k.name;
    EXPECT_NE(c.problem.find(k.words), std::string::npos) << k.name << ": " << c.problem;
    std::remove(path.c_str());
  }
  EXPECT_THROW(check_lcm_log("/nonexistent/log.lcm"), std::runtime_error);
}

}  // namespace
}  // namespace pinball::bus
