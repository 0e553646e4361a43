#include "pinball/bus/recorded_play.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

#include "common/temp_path.h"
#include "pinball/bus/channels.h"
#include "pinball/bus/lcm_log_format.h"
#include "pinball/bus/message_convert.h"
#include "pinball_lcm/lcmt_pinball_game_event.hpp"

namespace pinball::bus {
namespace {

void write_log(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

RecordedPlay small_play() {
  RecordedPlay play;
  for (int i = 0; i < 20; ++i)
    play.frames.push_back({0.005 * i, i, i != 7, Vec2(0.1 + 0.001 * i, 0.5), i == 3, i == 4});
  play.commands.push_back({0.0125, 0, true, 0});
  play.commands.push_back({0.0500, -1, false, 2});
  return play;
}

// The message read_recorded_play throws for `bytes` written to a log file.
std::string error_for(const std::string& name, const std::string& bytes) {
  const std::string path = pinball::testing::temp_path("recorded_play", name);
  write_log(path, bytes);
  std::string what;
  try {
    read_recorded_play(path);
  } catch (const std::runtime_error& e) {
    what = e.what();
  }
  std::remove(path.c_str());
  return what;
}

TEST(RecordedPlay, ReadsBackWhatItWrites) {
  const RecordedPlay written = small_play();
  const std::string path = pinball::testing::temp_path("recorded_play", "good.lcm");
  write_log(path, recorded_play_log(written));
  const RecordedPlay read = read_recorded_play(path);
  std::remove(path.c_str());
  EXPECT_EQ(read.source, path);
  EXPECT_EQ(read.malformed, 0u);
  ASSERT_EQ(read.frames.size(), written.frames.size());
  for (std::size_t i = 0; i < read.frames.size(); ++i) {
    EXPECT_NEAR(read.frames[i].t_s, written.frames[i].t_s, 1e-6);
    EXPECT_EQ(read.frames[i].seq, written.frames[i].seq);
    EXPECT_EQ(read.frames[i].found, written.frames[i].found);
    if (written.frames[i].found) {
      EXPECT_NEAR((read.frames[i].p_board - written.frames[i].p_board).norm(), 0.0, 1e-12);
    }
    EXPECT_EQ(read.frames[i].contact_left, written.frames[i].contact_left);
    EXPECT_EQ(read.frames[i].contact_right, written.frames[i].contact_right);
  }
  ASSERT_EQ(read.commands.size(), 2u);
  EXPECT_EQ(read.commands[0].flipper, 0);
  EXPECT_TRUE(read.commands[0].energize);
  EXPECT_EQ(read.commands[1].flipper, -1);
  EXPECT_FALSE(read.commands[1].energize);
  EXPECT_EQ(read.commands[1].cause, 2);
  EXPECT_NEAR(read.duration_s(), 0.095, 1e-6);
}

TEST(SharedSightings, ACopyWhoseBytesDifferIsOneRecordingAnotherRunIsNot) {
  const RecordedPlay play = small_play();  // 19 frames after the first, 3 of them next to frame 7 (no ball)
  RecordedPlay cut = play;
  cut.frames.resize(12);  // a copy cut short, its bytes unlike the whole
  cut.commands.clear();
  const SharedSightings copy = shared_sightings(cut, play);
  EXPECT_EQ(copy.moving_a, 9u);  // frames 1-11 but 7, which saw no ball, and 8, which follows it
  EXPECT_EQ(copy.moving_b, 17u);
  EXPECT_EQ(copy.shared, 9u);
  EXPECT_EQ(copy.first_seq, 1);
  EXPECT_DOUBLE_EQ(copy.first_t_s, 0.005);
  EXPECT_TRUE(copy.same_recording());
  EXPECT_TRUE(shared_sightings(play, cut).same_recording());

  RecordedPlay other = play;  // another run: its ball 1 nm elsewhere in every frame
  for (RecordedFrame& f : other.frames) f.p_board.x() += 1e-9;
  EXPECT_EQ(shared_sightings(other, play).shared, 0u);
  EXPECT_FALSE(shared_sightings(other, play).same_recording());

  RecordedPlay same_launch = other;  // another game of one simulated seed: the same launch, then its own
  for (std::size_t i = 0; i < 5; ++i) same_launch.frames[i] = play.frames[i];
  const SharedSightings launch = shared_sightings(same_launch, play);
  EXPECT_EQ(launch.shared, 4u);
  EXPECT_FALSE(launch.same_recording());

  RecordedPlay at_rest = play;  // a ball that never moves looks the same in every run
  for (RecordedFrame& f : at_rest.frames) f.p_board = Vec2(0.1, 0.5);
  EXPECT_EQ(shared_sightings(at_rest, at_rest).moving_a, 0u);
  EXPECT_FALSE(shared_sightings(at_rest, at_rest).same_recording());
}

// One frame stamped 1e6 s ahead had been blamed on the frame after it, as "several runs appended".
TEST(RecordedPlay, ALoneTimestampThatLeapsAheadIsNamedNotTakenForASecondRun) {
  RunClock clock;
  for (int k = 0; k < 1030; ++k) check_one_run("a.lcm", clock, 0.005 * k, k);
  check_one_run("a.lcm", clock, 0.005 * 1030 + 1e6, 1030);
  try {
    check_one_run("a.lcm", clock, 0.005 * 1031, 1031);
    ADD_FAILURE() << "a leap was passed";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("a.lcm: the PINBALL_OBSERVATION of frame 1030 is stamped 1000000 s ahead of "
                                          "the frames around it: a damaged timestamp",
                                          0),
              0u)
        << e.what();
  }
  RunClock appended;  // a second run: its clock starts again near 0
  for (int k = 0; k < 1000; ++k) check_one_run("b.lcm", appended, 0.005 * k, k);
  try {
    check_one_run("b.lcm", appended, 0.0, 0);
    ADD_FAILURE() << "two runs were passed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("b.lcm: its clock goes back 5 s at the PINBALL_OBSERVATION of frame 0: "
                                         "several runs appended"),
              std::string::npos)
        << e.what();
  }
}

TEST(RecordedPlay, RefusesAnEmptyOrDamagedOrForeignFile) {
  EXPECT_NE(error_for("empty.lcm", "").find("empty"), std::string::npos) << error_for("empty.lcm", "");
  const std::string log = recorded_play_log(small_play());
  const std::string truncated = error_for("cut.lcm", log.substr(0, log.size() - 5));
  EXPECT_NE(truncated.find("cut.lcm"), std::string::npos) << truncated;
  EXPECT_NE(truncated.find("truncated"), std::string::npos) << truncated;
  const std::string text = error_for("text.lcm", "t,x,y\n0,0.1,0.2\n");
  EXPECT_NE(text.find("text.lcm"), std::string::npos) << text;
  EXPECT_THROW(read_recorded_play("/nonexistent/recording.lcm"), std::runtime_error);
}

TEST(RecordedPlay, NamesTheMissingChannelAndWhatTheLogHas) {
  RecordedPlay frames_only = small_play();
  frames_only.commands.clear();
  const std::string no_commands = error_for("nocmd.lcm", recorded_play_log(frames_only));
  EXPECT_NE(no_commands.find("nocmd.lcm"), std::string::npos) << no_commands;
  EXPECT_NE(no_commands.find(kFlipperCommandChannel), std::string::npos) << no_commands;
  EXPECT_NE(no_commands.find("PINBALL_OBSERVATION (20)"), std::string::npos) << no_commands;

  RecordedPlay commands_only = small_play();
  commands_only.frames.clear();
  const std::string no_frames = error_for("noobs.lcm", recorded_play_log(commands_only));
  EXPECT_NE(no_frames.find(kObservationChannel), std::string::npos) << no_frames;
}

TEST(RecordedPlay, RefusesMessagesOfAnotherTypeOnItsChannels) {
  // A game event where observations belong: it does not decode as one.
  std::string log;
  const auto event = encode_message(to_lcm_game_event(1000, 0, 0, 1, 10.0, 1.0));
  append_lcm_event(log, 0, 1000, kObservationChannel, event.data(), event.size());
  const auto cmd = encode_message(to_lcm_flipper_command(2000, 0, -1, 0, true, 0));
  append_lcm_event(log, 1, 2000, kFlipperCommandChannel, cmd.data(), cmd.size());
  const std::string what = error_for("foreign.lcm", log);
  EXPECT_NE(what.find("another type"), std::string::npos) << what;
  EXPECT_NE(what.find("lcmt_pinball_observation"), std::string::npos) << what;
}

TEST(RecordedPlay, CommandsOfOurTypeWithABadFieldAreNamedNotCalledAnotherType) {
  RecordedPlay play = small_play();
  for (RecordedCommand& c : play.commands) c.flipper = 7;
  const std::string what = error_for("flipper7.lcm", recorded_play_log(play));
  EXPECT_EQ(what.find("another type"), std::string::npos) << what;
  EXPECT_NE(what.find("none of its 2 PINBALL_FLIPPER_CMD messages is well formed"), std::string::npos) << what;
  EXPECT_NE(what.find("flipper outside -1..1"), std::string::npos) << what;
}

TEST(RecordedPlay, CountsAndNamesTheFirstBadMessageAmongGoodOnes) {
  RecordedPlay play = small_play();
  play.commands.push_back({0.0600, 5, true, 0});
  const std::string path = pinball::testing::temp_path("recorded_play", "one_bad.lcm");
  write_log(path, recorded_play_log(play));
  const RecordedPlay back = read_recorded_play(path);
  std::remove(path.c_str());
  EXPECT_EQ(back.commands.size(), 2u);
  EXPECT_EQ(back.malformed, 1u);
  EXPECT_NE(back.first_malformed.find("PINBALL_FLIPPER_CMD message 3"), std::string::npos) << back.first_malformed;
  EXPECT_NE(back.first_malformed.find("flipper outside"), std::string::npos) << back.first_malformed;
}

TEST(RecordedPlay, RefusesALogWhereTheBallIsNeverSeen) {
  RecordedPlay blind = small_play();
  for (RecordedFrame& f : blind.frames) f.found = false;
  const std::string what = error_for("blind.lcm", recorded_play_log(blind));
  EXPECT_NE(what.find("saw the ball"), std::string::npos) << what;
}

}  // namespace
}  // namespace pinball::bus
