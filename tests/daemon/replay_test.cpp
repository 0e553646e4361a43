// A game recorded by pinballd into an LCM log replays to the same decisions;
// a log whose decisions were altered does not; bad messages are skipped.

#include "pinball/daemon/replay.h"

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "pinball/bus/channels.h"
#include "pinball/daemon/daemon.h"
#include "pinball_lcm/lcmt_pinball_flipper_command.hpp"

namespace pinball::daemon {
namespace {

const std::string kSource = PINBALL_SOURCE_DIR;

DaemonConfig config_for_test() {
  DaemonConfig c;
  c.sim.board = kSource + "/boards/mit1993.board";
  c.controller = kSource + "/controllers/best.json";
  c.sim.balls = 2;
  c.sim.seed = 21;
  return c;
}

// Records one run once for every test here.
const std::string& recorded_log() {
  static const std::string path = [] {
    // ctest runs each test in its own process, two at a time: one log per process.
    const std::string p = ::testing::TempDir() + "/pinballd_replay_" + std::to_string(getpid()) + ".lcmlog";
    std::remove(p.c_str());
    DaemonConfig c = config_for_test();
    c.lcm_url = "file://" + p + "?mode=w";
    Daemon d(c);
    d.run();
    return p;
  }();
  return path;
}

TEST(Replay, ReproducesTheRecordedDecisions) {
  const ReplayReport r = replay_log(recorded_log(), config_for_test());
  EXPECT_GT(r.observations, 1000u);
  EXPECT_GT(r.recorded_commands, 2u);
  EXPECT_EQ(r.replayed_commands, r.recorded_commands);
  EXPECT_EQ(r.matched, r.recorded_commands);
  EXPECT_EQ(r.malformed, 0u);
  EXPECT_TRUE(r.reproduced) << r.mismatch;
}

TEST(Replay, AnAlteredDecisionIsFoundAndBadMessagesAreSkipped) {
  const std::string altered =
      ::testing::TempDir() + "/pinballd_replay_altered_" + std::to_string(getpid()) + ".lcmlog";
  {
    lcm::LogFile in(recorded_log(), "r");
    lcm::LogFile out(altered, "w");
    ASSERT_TRUE(in.good() && out.good());
    int commands = 0;
    for (const lcm::LogEvent* e = in.readNextEvent(); e != nullptr; e = in.readNextEvent()) {
      lcm::LogEvent copy = *e;
      std::vector<std::uint8_t> data(static_cast<const std::uint8_t*>(e->data),
                                     static_cast<const std::uint8_t*>(e->data) + e->datalen);
      if (e->channel == bus::kFlipperCommandChannel && ++commands == 2) {
        pinball_lcm::lcmt_pinball_flipper_command m{};
        m.decode(data.data(), 0, static_cast<int>(data.size()));
        m.flipper = static_cast<std::int8_t>(1 - m.flipper);  // the other flipper
        m.encode(data.data(), 0, static_cast<int>(data.size()));
      }
      copy.data = data.data();
      out.writeEvent(&copy);
      if (commands == 1 && e->channel == bus::kFlipperCommandChannel) {
        std::uint8_t junk[3] = {9, 9, 9};
        lcm::LogEvent bad = copy;
        bad.channel = bus::kObservationChannel;
        bad.data = junk;
        bad.datalen = sizeof junk;
        out.writeEvent(&bad);
      }
    }
  }
  const ReplayReport r = replay_log(altered, config_for_test());
  EXPECT_FALSE(r.reproduced);
  EXPECT_EQ(r.first_mismatch, 1);
  EXPECT_EQ(r.malformed, 1u);
  EXPECT_NE(r.mismatch.find("recorded"), std::string::npos);
}

TEST(Replay, AFileThatIsNoLcmLogIsRefusedNamingIt) {
  for (const std::string& path : {std::string(PINBALL_SOURCE_DIR "/README.md"),
                                  std::string(PINBALL_SOURCE_DIR "/.gitignore")}) {
    try {
      replay_log(path, config_for_test());
      FAIL() << path;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path + ": not an LCM log"), std::string::npos) << e.what();
    }
  }
  const std::string empty = (std::filesystem::temp_directory_path() / "pinball_replay_empty.lcmlog").string();
  std::ofstream(empty).close();
  EXPECT_THROW(replay_log(empty, config_for_test()), std::runtime_error);
  std::filesystem::remove(empty);
}

TEST(Replay, MissingLogIsNamed) {
  try {
    replay_log("/nonexistent/log.lcm", config_for_test());
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/log.lcm"), std::string::npos);
  }
}

}  // namespace
}  // namespace pinball::daemon
