// `pinball view` without a display: snapshots of a log and of a live source,
// and its errors.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "common/command_test.h"
#include "pinball/bus/lcm_log_format.h"
#include "pinball/bus/recorded_play.h"
#include "pinball/view/view_render.h"
#include "view/view_log.h"

namespace pinball::testing {
namespace {

class ViewCommand : public CommandTest {
 protected:
  void SetUp() override {
    CommandTest::SetUp();
    log_ = (dir_ / "game.lcmlog").string();
    events_ = write_view_log(log_);
  }
  // Runs without a display, as on a lab server or in CI.
  CommandResult view(const std::string& args) { return run_shell("env -u DISPLAY -u WAYLAND_DISPLAY " PINBALL_EXE " view " + args); }
  std::string log_;
  int events_ = 0;
};

cv::Point2d ball_in(const std::string& png) {
  return ball_on_table(cv::imread(png, cv::IMREAD_COLOR));
}

TEST_F(ViewCommand, SnapshotOfALogShowsTheBallWhereTheLogSaysItWas) {
  const std::string png = (dir_ / "at.png").string();
  const CommandResult r = view(log_ + " --snapshot " + png + " --at 0.4001 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const Vec2 truth = view_log_ball(0.4);
  EXPECT_NEAR(j["ball"]["x_m"].get<double>(), truth.x(), 1e-9);
  EXPECT_NEAR(j["ball"]["y_m"].get<double>(), truth.y(), 1e-9);
  EXPECT_EQ(j["snapshot"], png);
  EXPECT_EQ(j["frames_dropped"], 1);  // frame 50 is missing
  const cv::Point2d c = ball_in(png);
  EXPECT_NEAR(c.x, j["ball"]["u_px"].get<double>(), 1.0);
  EXPECT_NEAR(c.y, j["ball"]["v_px"].get<double>(), 1.0);
}

// Two runs appended to one log (lcm_url mode=a) had played interleaved on one timeline.
TEST_F(ViewCommand, ALogOfTwoRunsAppendedIsRefusedAsReplayRefusesIt) {
  bus::RecordedPlay run;  // 5 s of frames: the second run's clock starts again 5 s back
  for (int i = 0; i < 500; ++i) run.frames.push_back({0.01 * i, i, true, Vec2(0.25, 0.5), false, false});
  run.commands.push_back({1.0, 0, true, 0});
  const std::string twice = (dir_ / "twice.lcmlog").string();
  {
    std::ofstream out(twice, std::ios::binary);
    out << bus::recorded_play_log(run) << bus::recorded_play_log(run);
  }
  const CommandResult r = view(twice + " --snapshot " + (dir_ / "t.png").string() + " --at 0.5");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(twice + ": its clock goes back"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("several runs appended to one log (mode=a)?"), std::string::npos) << r.err;
}

// A live URL that writes a log had emptied the recording it named (liblcm opens it for writing), so
// `view --config rec.yaml` lost the run that configuration recorded.
TEST_F(ViewCommand, ALiveUrlThatWritesALogIsRefusedAndTheLogKept) {
  const std::uintmax_t bytes = std::filesystem::file_size(log_);
  const std::string png = (dir_ / "w.png").string();
  const CommandResult r = view("--lcm-url 'file://" + log_ + "?mode=w' --snapshot " + png + " --wait-s 0.2");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("writes a log, and listening there would replace " + log_), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("pinball view " + log_), std::string::npos) << r.err;
  const std::string config = (dir_ / "rec.yaml").string();
  std::ofstream(config) << "version: 1\nlcm_url: file://" << log_ << "?mode=a\n";
  const CommandResult c = view("--config " + config + " --snapshot " + png + " --wait-s 0.2");
  EXPECT_EQ(c.exit_code, 1);
  EXPECT_NE(c.err.find(config + "'s lcm_url"), std::string::npos) << c.err;
  EXPECT_EQ(std::filesystem::file_size(log_), bytes);
  EXPECT_FALSE(std::filesystem::exists(png));
}

// An option the mode would drop is refused: a log's view read no --lcm-url or --wait-s, a snapshot at
// --at no --speed, and --at beside --quit-at had turned into a window that dropped --at.
TEST_F(ViewCommand, AnOptionTheModeWouldDropIsRefused) {
  const std::string png = (dir_ / "x.png").string();
  for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
           {log_ + " --snapshot " + png + " --at 0.5 --lcm-url memq://", "log excludes --lcm-url"},
           {log_ + " --snapshot " + png + " --at 0.5 --wait-s 2", "log excludes --wait-s"},
           {log_ + " --snapshot " + png + " --at 0.5 --speed 2", "--at excludes --speed"},
           {log_ + " --snapshot " + png + " --at 0.5 --quit-at 1", "--at excludes --quit-at"},
           {"--lcm-url memq:// --snapshot " + png + " --speed 2", "--speed requires log"},
           {"--lcm-url '' --snapshot " + png, "--lcm-url: an empty URL names no LCM provider"},  // had meant udpm
       }) {
    const CommandResult r = view(args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_NE(r.err.find(says), std::string::npos) << args << "\n" << r.err;
  }
}

// A log of another program had drawn an empty table and exited 0.
TEST_F(ViewCommand, ALogWithNoDaemonMessageIsRefused) {
  std::string bytes;
  const std::uint8_t pose[4] = {1, 2, 3, 4};
  bus::append_lcm_event(bytes, 0, 1000, "POSE", pose, sizeof pose);
  const std::string other = (dir_ / "other.lcmlog").string();
  std::ofstream(other, std::ios::binary) << bytes;
  const CommandResult r = view(other + " --snapshot " + (dir_ / "o.png").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(other + ": none of its 1 messages is on the daemon's channels"), std::string::npos) << r.err;
}

// A configuration that keeps pinballd's default controller names the shipped
// file, found from any folder as pinballd finds it.
TEST_F(ViewCommand, AConfigurationsDefaultFilesAreFoundFromAnyFolder) {
  const std::string config = (dir_ / "m.yaml").string();
  std::ofstream(config) << "lcm_url: \"memq://\"\n";
  const std::string png = (dir_ / "cfg.png").string();
  const CommandResult r = run_shell("cd " + dir_.string() + " && env -u DISPLAY -u WAYLAND_DISPLAY " PINBALL_EXE
                                    " view " + log_ + " --config m.yaml --snapshot " + png + " --at 0.1");
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST_F(ViewCommand, SnapshotOfALiveSourceThroughLiblcm) {
  const std::string png = (dir_ / "live.png").string();
  const CommandResult r = view("--lcm-url 'file://" + log_ + "?speed=0' --snapshot " + png + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["observations"], kViewLogFrames - 1);
  EXPECT_DOUBLE_EQ(j["frame_to_can_p99_us"].get<double>(), 812.0);
  EXPECT_GT(ball_in(png).x, 0.0);
}

// The lab's way: pinballd publishing on UDP multicast, the view listening on
// the same URL (a port of its own, so no other test's daemon is heard).
TEST_F(ViewCommand, LiveFromARunningPinballdOverUdpMulticast) {
  const std::string url = "'udpm://239.255.76.67:7671?ttl=0'";
  const std::string png = (dir_ / "udpm.png").string();
  // pinballd stops at 8 s at the latest, or when the view has its snapshot.
  const CommandResult r = run_shell("(sleep 0.3; exec timeout -s INT 8 " PINBALLD_EXE " --lcm-url " + url +
                                    " --realtime --balls 1 > /dev/null 2>&1) & daemon=$!; env -u DISPLAY " PINBALL_EXE
                                    " view --lcm-url " + url + " --snapshot " + png +
                                    " --at 1 --wait-s 15 --json; status=$?; kill -INT $daemon 2>/dev/null; wait; exit $status");
  if (r.exit_code == 1 && r.err.find("nothing arrived") != std::string::npos) {
    GTEST_SKIP() << "UDP multicast does not loop back on this machine: " << r.err;
  }
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_GE(j["t_s"].get<double>(), 1.0);
  EXPECT_GT(j["observations"].get<int>(), 100);  // 200 frames/s for a second
  EXPECT_EQ(j["malformed"], 0);
  EXPECT_TRUE(std::filesystem::exists(png));
}

TEST_F(ViewCommand, AWindowWithoutADisplayIsAClearError) {
  const CommandResult r = view(log_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("needs a display"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--snapshot"), std::string::npos) << r.err;
}

TEST_F(ViewCommand, BadLogsAreNamedAndNothingIsWritten) {
  const std::string png = (dir_ / "never.png").string();
  std::ofstream(dir_ / "empty.lcmlog").close();
  std::ofstream(dir_ / "text.lcmlog") << "not a log at all";
  std::string cut = slurp(log_);
  cut.resize(cut.size() - 7);
  std::ofstream(dir_ / "cut.lcmlog", std::ios::binary) << cut;
  for (const auto& [name, what] : {std::pair<std::string, std::string>{"empty.lcmlog", "is empty"},
                                   {"text.lcmlog", "not an LCM log"},
                                   {"cut.lcmlog", "damaged LCM log"}}) {
    const CommandResult r = view((dir_ / name).string() + " --snapshot " + png + " --at 0");
    EXPECT_EQ(r.exit_code, 1) << name;
    EXPECT_NE(r.err.find(name), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
    EXPECT_EQ(count_lines(r.err), 1) << r.err;
    EXPECT_FALSE(std::filesystem::exists(png)) << name;
  }
}

TEST_F(ViewCommand, ATimePastTheEndOfTheLogIsRefused) {
  const std::string png = (dir_ / "late.png").string();
  const CommandResult r = view(log_ + " --snapshot " + png + " --at 5");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("ends at 1 s"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(png));
  // --quit-at past the end had played on for ever: the view holds at the end and never reaches it.
  const CommandResult q = run_shell("env -u DISPLAY -u WAYLAND_DISPLAY QT_QPA_PLATFORM=offscreen timeout 60 "
                                    PINBALL_EXE " view " + log_ + " --snapshot " + png + " --quit-at 100");
  EXPECT_EQ(q.exit_code, 1);
  EXPECT_NE(q.err.find("--quit-at 100: the log " + log_ + " ends at 1 s"), std::string::npos) << q.err;
  EXPECT_FALSE(std::filesystem::exists(png));
}

// A snapshot named as the log (or the board) had replaced it with a picture, exit 0.
TEST_F(ViewCommand, ASnapshotOverItsOwnInputIsRefused) {
  const std::string log = (dir_ / "log.png").string();  // a log under a picture's name
  std::filesystem::copy_file(log_, log);
  const std::uintmax_t bytes = std::filesystem::file_size(log);
  const CommandResult r = view(log + " --snapshot " + log + " --at 0.5");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--snapshot " + log + " is the input log " + log + "; it would be replaced"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(std::filesystem::file_size(log), bytes);
}

TEST_F(ViewCommand, ASnapshotIntoAMissingFolderIsRefusedFirst) {
  const CommandResult r = view(log_ + " --snapshot " + (dir_ / "no" / "x.png").string() + " --at 0.1");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace pinball::testing
