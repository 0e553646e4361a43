// A game recorded by pinballd into an LCM log replays to the same decisions;
// a log whose decisions were altered does not; bad messages are skipped; a
// damaged log (tests/bad_input/lcm/) is refused naming the byte.

#include "pinball/daemon/replay.h"

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "pinball/bus/channels.h"
#include "pinball/bus/message_convert.h"
#include "pinball/control/controller_file.h"
#include "pinball/daemon/daemon.h"
#include "pinball_lcm/lcmt_pinball_flipper_command.hpp"
#include "pinball_lcm/lcmt_pinball_observation_v1.hpp"

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

// `from` with every observation rewritten in the layout logs had before the
// delivery stamp (lcmt_pinball_observation_v1), dated at its exposure.
std::string rewritten_as_v1(const std::string& from, const std::string& name) {
  const std::string to = ::testing::TempDir() + "/" + name + "_" + std::to_string(getpid()) + ".lcmlog";
  lcm::LogFile in(from, "r");
  lcm::LogFile out(to, "w");
  EXPECT_TRUE(in.good() && out.good());
  for (const lcm::LogEvent* e = in.readNextEvent(); e != nullptr; e = in.readNextEvent()) {
    lcm::LogEvent copy = *e;
    std::vector<std::uint8_t> data;
    if (e->channel == bus::kObservationChannel) {
      pinball_lcm::lcmt_pinball_observation m{};
      EXPECT_EQ(bus::decode_observation(e->data, static_cast<std::size_t>(e->datalen), m),
                bus::ObservationLayout::kCurrent);
      const pinball_lcm::lcmt_pinball_observation_v1 old{m.utime, m.seq,  m.found,      m.x_m,        m.y_m,
                                                         m.u_px,  m.v_px, m.confidence, m.contact_left, m.contact_right};
      data = bus::encode_message(old);
      copy.data = data.data();
      copy.datalen = static_cast<std::int32_t>(data.size());
    }
    out.writeEvent(&copy);
  }
  return to;
}

// `from` without the events `drop` says to leave out (channel, its index on that channel).
std::string without(const std::string& from, const std::string& name,
                    const std::function<bool(const lcm::LogEvent&, int)>& drop) {
  const std::string to = ::testing::TempDir() + "/" + name + "_" + std::to_string(getpid()) + ".lcmlog";
  lcm::LogFile in(from, "r");
  lcm::LogFile out(to, "w");
  EXPECT_TRUE(in.good() && out.good());
  std::map<std::string, int> seen;
  for (const lcm::LogEvent* e = in.readNextEvent(); e != nullptr; e = in.readNextEvent()) {
    if (!drop(*e, seen[e->channel]++)) {
      lcm::LogEvent copy = *e;
      out.writeEvent(&copy);
    }
  }
  return to;
}

// A udpm recording that lost one observation had never reproduced: the replay numbered its frames
// itself and every later decision was one frame early. Decisions are compared by camera frame now.
TEST(Replay, AnObservationTheLogLostShiftsNoLaterDecision) {
  const ReplayReport whole = replay_log(recorded_log(), config_for_test());
  ASSERT_TRUE(whole.reproduced) << whole.mismatch;
  // The first frame without the ball after the first decision: the tracker's input is the same without
  // it (a frame that showed the ball would change its fits, and rightly its decisions), and the later
  // decisions are all one frame number off if frames are counted.
  bool decided = false;
  bool dropped = false;
  const std::string lost = without(recorded_log(), "pinballd_replay_lost", [&](const lcm::LogEvent& e, int) {
    decided = decided || e.channel == bus::kFlipperCommandChannel;
    if (dropped || !decided || e.channel != bus::kObservationChannel) return false;
    pinball_lcm::lcmt_pinball_observation m{};
    bus::decode_observation(e.data, static_cast<std::size_t>(e.datalen), m);
    dropped = !m.found;
    return dropped;
  });
  ASSERT_TRUE(dropped);
  const ReplayReport r = replay_log(lost, config_for_test());
  EXPECT_EQ(r.observations + 1, whole.observations);
  EXPECT_EQ(r.recorded_commands, whole.recorded_commands);
  EXPECT_TRUE(r.reproduced) << r.mismatch;
  std::remove(lost.c_str());
  // With nothing to compare it with, no verdict: exit 1, naming what is missing.
  const std::string blind = without(recorded_log(), "pinballd_replay_blind", [](const lcm::LogEvent& e, int) {
    return e.channel == bus::kFlipperCommandChannel;
  });
  try {
    replay_log(blind, config_for_test());
    ADD_FAILURE() << "a log without commands was replayed";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), blind + ": no PINBALL_FLIPPER_CMD message: nothing to compare the replay with "
                                             "(recorded without that channel?)");
  }
  std::remove(blind.c_str());
}

TEST(Replay, ALogFromBeforeTheDeliveryStampStillReplays) {
  // The ideal camera stamps at exposure: nothing is lost in the old layout.
  const std::string old = rewritten_as_v1(recorded_log(), "pinballd_replay_v1");
  const ReplayReport r = replay_log(old, config_for_test());
  EXPECT_GT(r.observations, 1000u);
  EXPECT_EQ(r.observations_without_latency, r.observations);
  EXPECT_EQ(r.malformed, 0u);
  EXPECT_TRUE(r.reproduced) << r.mismatch;
  std::remove(old.c_str());
}

// A leading controller adds each frame's camera latency to its lead: through
// the typical camera (8 ms and more) its replay is exact only because the log
// carries the delivery stamp; without it, its decisions come on other frames.
TEST(Replay, ALeadingControllerBehindALateCameraReplaysFrameForFrame) {
  control::ControllerSpec led = control::load_controller(kSource + "/controllers/best.json");
  led.actuator.lead_actuation_delay_s = 0.004;
  DaemonConfig c = config_for_test();
  c.controller = ::testing::TempDir() + "/pinballd_replay_led_" + std::to_string(getpid()) + ".json";
  control::save_controller(led, c.controller);
  c.sim.camera = "typical";
  c.sim.balls = 6;
  c.sim.max_ball_time_s = 10.0;
  const std::string log = ::testing::TempDir() + "/pinballd_replay_led_" + std::to_string(getpid()) + ".lcmlog";
  std::remove(log.c_str());
  {
    DaemonConfig recording = c;
    recording.lcm_url = "file://" + log + "?mode=w";
    Daemon d(recording);
    d.run();
  }
  const ReplayReport r = replay_log(log, c);
  EXPECT_GT(r.recorded_commands, 2u);
  EXPECT_EQ(r.observations_without_latency, 0u);
  EXPECT_TRUE(r.reproduced) << r.mismatch;

  const std::string old = rewritten_as_v1(log, "pinballd_replay_led_v1");
  const ReplayReport without = replay_log(old, c);
  EXPECT_EQ(without.observations_without_latency, without.observations);
  EXPECT_FALSE(without.reproduced) << "the latency was not needed: the test proves nothing";
  for (const std::string& f : {log, old, c.controller}) std::remove(f.c_str());
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

// The first `bytes` bytes of `from`, written to `to`.
void copy_prefix(const std::string& from, const std::string& to, std::uintmax_t bytes) {
  std::ifstream in(from, std::ios::binary);
  std::string data(static_cast<std::size_t>(bytes), '\0');
  in.read(data.data(), static_cast<std::streamsize>(bytes));
  std::ofstream(to, std::ios::binary) << data;
}

// A recording cut short (a full disk, a killed logger) used to replay as
// "reproduced": its decisions up to the cut still matched.
TEST(Replay, ATruncatedRecordingIsRefusedNamingTheByte) {
  const std::uintmax_t size = std::filesystem::file_size(recorded_log());
  const std::string cut = ::testing::TempDir() + "/pinballd_replay_cut_" + std::to_string(getpid()) + ".lcmlog";
  for (const std::uintmax_t bytes : {size - 1, std::uintmax_t{40}, std::uintmax_t{20}}) {
    copy_prefix(recorded_log(), cut, bytes);
    try {
      replay_log(cut, config_for_test());
      FAIL() << "cut at " << bytes;
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(cut + ": damaged LCM log at byte "), std::string::npos) << what;
      EXPECT_NE(what.find("truncated event"), std::string::npos) << what;
    }
  }
  std::remove(cut.c_str());
}

struct BadLog {
  const char* file;   // in tests/bad_input/lcm/ (tests/bad_input/make_lcm_logs.py)
  const char* words;  // what the error says after the file's name
};
constexpr BadLog kBadLogs[] = {
    {"empty.lcmlog", ": is empty (0 bytes), not an LCM log"},
    {"random_bytes.lcmlog", ": not an LCM log (no LCM event header at byte 0)"},
    {"truncated_header.lcmlog", ": damaged LCM log at byte 134: truncated event header (12 of 28 bytes)"},
    {"truncated_payload.lcmlog", ": damaged LCM log at byte 134: truncated event"},
    {"huge_length.lcmlog", ": damaged LCM log at byte 0: truncated event: channel length 19 and data length 2147483647"},
    {"huge_channel_length.lcmlog", ": damaged LCM log at byte 134: bad channel length 2147483647"},
    {"bad_sync_mid_file.lcmlog", ": damaged LCM log at byte 67: no event starts here (sync word 0xDEADBEEF"},
};

std::string bad_log(const BadLog& b) { return kSource + "/tests/bad_input/lcm/" + b.file; }

// Progress comes as observations are replayed; `pinball replay` prints it only
// on a terminal or with --progress, so a script's stderr stays quiet.
TEST(Replay, ProgressComesEveryStepAndOnlyWhenAsked) {
  std::vector<ReplayProgress> steps;
  const ReplayReport r =
      replay_log(recorded_log(), config_for_test(), [&](const ReplayProgress& p) { steps.push_back(p); }, 500);
  ASSERT_EQ(steps.size(), r.observations / 500 + 1);  // and once at the end
  EXPECT_EQ(steps.front().observations, 500u);
  EXPECT_EQ(steps.back().bytes_total, std::filesystem::file_size(recorded_log()));
  EXPECT_EQ(steps.back().bytes_read, steps.back().bytes_total);
  EXPECT_LT(steps.front().bytes_read, steps.back().bytes_read);
  // With --progress: the share of the log, the ETA and the observations, as the meter prints them.
  const std::string shown_file = ::testing::TempDir() + "/pinball_replay_shown_" + std::to_string(getpid()) + ".err";
  ASSERT_EQ(std::system((std::string(PINBALL_EXE) + " replay " + recorded_log() + " --controller " + kSource +
                         "/controllers/best.json --progress > /dev/null 2> " + shown_file)
                            .c_str()),
            0);
  std::ifstream shown_in(shown_file);
  const std::string shown((std::istreambuf_iterator<char>(shown_in)), std::istreambuf_iterator<char>());
  EXPECT_NE(shown.find("MB of the log (100 %)"), std::string::npos) << shown;
  EXPECT_NE(shown.find(" observations"), std::string::npos) << shown;
  std::remove(shown_file.c_str());
  const std::string err = ::testing::TempDir() + "/pinball_replay_quiet_" + std::to_string(getpid()) + ".err";
  const std::string cmd = std::string(PINBALL_EXE) + " replay " + recorded_log() + " --controller " + kSource +
                          "/controllers/best.json > /dev/null 2> " + err;
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::ifstream in(err);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()), "");
  std::remove(err.c_str());
}

TEST(Replay, DamagedLogsAreRefusedBeforeLiblcmReadsThem) {
  for (const BadLog& b : kBadLogs) {
    try {
      replay_log(bad_log(b), config_for_test());
      FAIL() << b.file;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(bad_log(b) + b.words), std::string::npos) << e.what();
    }
  }
}

// As users run it: exit 1 and one line naming the file and the byte (huge_length.lcmlog was a
// segfault in liblcm 1.3.1, the others "NOT reproduced" or "reproduced").
TEST(Replay, PinballReplayExitsOneOnEachDamagedLog) {
  for (const BadLog& b : kBadLogs) {
    const std::string err = ::testing::TempDir() + "/pinball_replay_bad_" + std::to_string(getpid()) + ".err";
    const std::string cmd = std::string(PINBALL_EXE) + " replay " + bad_log(b) + " > /dev/null 2> " + err;
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status)) << b.file << " died";
    EXPECT_EQ(WEXITSTATUS(status), 1) << b.file;
    std::ifstream in(err);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("pinball: " + bad_log(b) + b.words), std::string::npos) << text;
    std::remove(err.c_str());
  }
}

// A log whose observation channel carries another message type: the
// command says that nothing decoded, not that the channel is missing.
TEST(Replay, ALogOfAnotherTypeOnTheChannelIsSaidToBeMalformed) {
  const std::string log = ::testing::TempDir() + "/pinball_replay_type_" + std::to_string(getpid()) + ".lcmlog";
  {
    lcm::LogFile out(log, "w");
    pinball_lcm::lcmt_pinball_flipper_command m{};
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
    m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    for (int i = 0; i < 5; ++i) {
      lcm::LogEvent e{};
      e.eventnum = i;
      e.timestamp = 1000 * i;
      e.channel = bus::kObservationChannel;
      e.datalen = static_cast<int32_t>(bytes.size());
      e.data = bytes.data();
      out.writeEvent(&e);
    }
  }
  // Nothing to compare is no verdict: it had said "NOT reproduced" and exited 3.
  const std::string text_out = ::testing::TempDir() + "/pinball_replay_type_" + std::to_string(getpid()) + ".out";
  const int status = std::system((std::string(PINBALL_EXE) + " replay " + log + " > " + text_out + " 2>&1").c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
  std::ifstream in(text_out);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find(log + ": no PINBALL_OBSERVATION message decoded among its 5 events (5 malformed: another "
                            "message type on the daemon's channels, or a log of another version); nothing replayed"),
            std::string::npos)
      << text;
  std::remove(log.c_str());
  std::remove(text_out.c_str());
}

// Two runs in one log (lcm_url mode=a): the second's clock starts again.
// Replayed as one run its decisions would meet the first run's ball: refused.
TEST(Replay, TwoRunsAppendedToOneLogAreRefused) {
  const std::string both = ::testing::TempDir() + "/pinball_replay_appended_" + std::to_string(getpid()) + ".lcmlog";
  {
    std::ifstream in(recorded_log(), std::ios::binary);
    const std::string run((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(both, std::ios::binary) << run << run;
  }
  try {
    replay_log(both, config_for_test());
    FAIL() << "an appended log replayed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(both + ": its clock goes back"), std::string::npos) << e.what();
  }
  std::remove(both.c_str());
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
