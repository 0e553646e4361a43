// `pinball identify` as a lab runs it: logs in, a report and an overlay out;
// bad logs refused with one line naming the file, and nothing written.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "common/command_test.h"
#include "common/thesis_board.h"
#include "learn/model_recording.h"
#include "pinball/table/board_overlay.h"

namespace pinball {
namespace {

class IdentifyCommand : public pinball::testing::CommandTest {
 protected:
  // A log of `balls` balls played in the thesis model with a flatter slope.
  std::string record(const std::string& name, int balls, std::uint64_t seed) {
    table::Board world = pinball::testing::thesis_board();
    world.gravity_mps2 = 0.95;
    bus::RecordedPlay play = pinball::testing::record_model_play(world, balls, 0.0005, seed);
    const std::filesystem::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << bus::recorded_play_log(play);
    return path.string();
  }
  // The same play seen 60 mm to the right: a log of another table (or another camera calibration).
  std::string record_shifted(const std::string& name, int balls, std::uint64_t seed) {
    bus::RecordedPlay play = pinball::testing::record_model_play(pinball::testing::thesis_board(), balls, 0.0005, seed);
    for (bus::RecordedFrame& f : play.frames) f.p_board.x() += 0.06;
    const std::filesystem::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << bus::recorded_play_log(play);
    return path.string();
  }
  std::string write(const std::string& name, const std::string& bytes) {
    const std::filesystem::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << bytes;
    return path.string();
  }
};

// A log shifted 60 mm was fitted and gave an overlay that lost every ball, with no word of doubt.
TEST_F(IdentifyCommand, ALogTheBoardMissesByCentimetresIsWarnedOf) {
  const std::string log = record_shifted("shifted.lcm", 6, 4);
  const pinball::testing::CommandResult r = run("identify " + log + " --bootstrap 2 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("warnings").size(), 1u) << r.out;
  EXPECT_NE(j.at("warnings")[0].get<std::string>().find("the board's own model misses the ball by "),
            std::string::npos);
  const pinball::testing::CommandResult good = run("identify " + record("good.lcm", 6, 4) + " --bootstrap 2 --json");
  ASSERT_EQ(good.exit_code, 0) << good.err;
  EXPECT_TRUE(nlohmann::json::parse(good.out).at("warnings").empty());
}

TEST_F(IdentifyCommand, FitsWritesTheOverlayAndJudgesItOnHeldOutPlay) {
  const std::string train = record("train.lcm", 30, 3);
  const std::string held = record("held.lcm", 10, 4);
  const std::string overlay = (dir_ / "identified.yaml").string();
  const pinball::testing::CommandResult r =
      run("identify " + train + " --held-out " + held + " --out " + overlay + " --bootstrap 5 --sigma-m 0.0005 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["gravity"]["g_mps2"].get<double>(), 0.95, 0.02);
  // Not a terminal, no --progress: stderr stays quiet for a script.
  EXPECT_EQ(r.err.find("identify: "), std::string::npos) << r.err;
  EXPECT_EQ(j["gravity"]["bootstrap_resamples"], 5);
  EXPECT_GT(j["gravity"]["g_stderr_mps2"].get<double>(), 0.0);
  EXPECT_GT(j["free_flights"].get<int>(), 20);
  EXPECT_EQ(j["malformed_messages"], 0);
  EXPECT_TRUE(j["first_malformed"].is_null());
  EXPECT_EQ(j["overlay"], overlay);
  EXPECT_FALSE(j["not_identified"].empty());
  // The recording's flippers never rose: each is reported, none identified, no delay.
  ASSERT_EQ(j["flippers"].size(), 2u);
  EXPECT_EQ(j["flippers"][0]["name"], "left_flipper");
  EXPECT_FALSE(j["flippers"][0]["identified"].get<bool>());
  // The board's values beside the fit's, as the text gives them.
  EXPECT_DOUBLE_EQ(j["flippers"][0]["board_omega_rad_s"].get<double>(),
                   pinball::testing::thesis_board().flippers[0].omega_rad_s);
  EXPECT_DOUBLE_EQ(j["flippers"][0]["board_mu"].get<double>(), pinball::testing::thesis_board().flippers[0].mu);
  EXPECT_EQ(j["flipper_shots"], 0);
  EXPECT_TRUE(j["actuation_delay_s"].is_null());
  EXPECT_TRUE(j["actuation_delay_stderr_s"].is_null());
  // The model's ball never skids: no friction measured (null), not a friction of 0.
  if (j["sliding_friction"]["skidding"].get<int>() == 0) {
    EXPECT_TRUE(j["sliding_friction"]["decel_mps2"].is_null()) << j["sliding_friction"].dump();
  }
  EXPECT_GT(j["held_out"]["nominal"]["moments"].get<int>(), 50);
  EXPECT_LT(j["held_out"]["identified"]["mean_m"].get<double>(), j["held_out"]["nominal"]["mean_m"].get<double>());
  EXPECT_NEAR(j["held_out"]["error_ratio"].get<double>(),
              j["held_out"]["identified"]["mean_m"].get<double>() / j["held_out"]["nominal"]["mean_m"].get<double>(), 1e-9);
  EXPECT_GT(j["held_out"]["error_ratio_ci95"].get<double>(), 0.0);
  EXPECT_EQ(j["held_out"]["error_ratio_moments"], j["held_out"]["nominal"]["moments"]);
  const table::BoardOverlay written = table::read_board_overlay(overlay);
  ASSERT_TRUE(written.gravity_mps2.has_value());
  EXPECT_DOUBLE_EQ(written.gravity_mps2->value, j["gravity"]["g_mps2"].get<double>());
  EXPECT_EQ(written.recordings, std::vector<std::string>{train});
  // Each identified group's wall friction: in the JSON, in the overlay, the same figure.
  bool friction_seen = false;
  for (const nlohmann::json& g : j["obstacle_groups"]) {
    if (!g["identified"].get<bool>() || g["friction"].is_null()) continue;
    friction_seen = true;
    EXPECT_GE(g["friction"]["value"].get<double>(), 0.0);
    EXPECT_LE(g["tangent_rms_fitted_mps"].get<double>(), g["tangent_rms_frictionless_mps"].get<double>());
    for (const table::ObstacleGroupOverlay& w : written.obstacle_groups)
      if (w.board_rho == g["board_rho"].get<double>() && w.board_kick_mps == g["board_kick_mps"].get<double>()) {
        ASSERT_TRUE(w.friction.has_value());
        EXPECT_DOUBLE_EQ(w.friction->value, g["friction"]["value"].get<double>());
      }
  }
  EXPECT_TRUE(friction_seen);
  // The walls' thickness: the scan behind it, and the overlay's value.
  ASSERT_TRUE(j["wall_thickness"]["identified"].get<bool>()) << j["wall_thickness"].dump();
  EXPECT_EQ(j["wall_thickness"]["scan"].size(), 9u);
  // A value on the scan's edge (this world's walls are lines: 0 mm) is known no finer than half a step, not ± 0.
  EXPECT_GT(j["wall_thickness"]["stderr_m"].get<double>(), 0.0);
  if (j["wall_thickness"]["at_scan_edge"].get<bool>()) {
    EXPECT_GE(j["wall_thickness"]["stderr_m"].get<double>(), 0.00025);
  }
  EXPECT_LE(j["wall_thickness"]["error_fitted_m"].get<double>(), j["wall_thickness"]["error_at_zero_m"].get<double>());
  ASSERT_TRUE(written.wall_thickness_m.has_value());
  EXPECT_DOUBLE_EQ(written.wall_thickness_m->value, j["wall_thickness"]["thickness_m"].get<double>());

  // The text report says the same and where the overlay went.
  const pinball::testing::CommandResult text = run("identify " + held + " --bootstrap 0 --sigma-m 0.0005");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("g along the table"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("not identified: camera latency"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("; friction "), std::string::npos) << text.out;
  // Without a bootstrap the thickness has no uncertainty, so it is not claimed.
  EXPECT_NE(text.out.find("not identified: two-sided wall thickness: its uncertainty needs a bootstrap"),
            std::string::npos)
      << text.out;
  EXPECT_EQ(run("identify " + held + " --bootstrap 1").exit_code, 2) << "one resample gives no spread";
}

// Each stage's meter starts with the stage: the first line of one is 0 done, so the
// time of the first unit is counted (it had said "1/50, 0 ms elapsed, ETA 0 ms").
TEST_F(IdentifyCommand, ProgressShowsEveryStageFromItsStart) {
  const std::string log = record("progress.lcm", 10, 5);
  const pinball::testing::CommandResult r = run("identify " + log + " --bootstrap 3 --progress");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* first : {"identify: reading logs: 0/1 logs (0 %)", "identify: free flights: 0/1 (0 %)",
                            "identify: gravity bootstrap: 0/3 (0 %)", "identify: wall thickness: 0/9 (0 %)"}) {
    EXPECT_NE(r.err.find(first), std::string::npos) << first << "\n" << r.err;
  }
  EXPECT_NE(r.err.find("identify: gravity bootstrap: 3/3 (100 %)"), std::string::npos) << r.err;
}

TEST_F(IdentifyCommand, BadLogsAreRefusedNamingTheFileAndNothingIsWritten) {
  const std::string overlay = (dir_ / "identified.yaml").string();
  bus::RecordedPlay frames_only = pinball::testing::record_model_play(pinball::testing::thesis_board(), 1, 0.0005, 2);
  frames_only.commands.clear();
  const std::string good_log = bus::recorded_play_log(pinball::testing::record_model_play(
      pinball::testing::thesis_board(), 1, 0.0005, 2));
  const std::vector<std::pair<std::string, std::string>> cases{
      {write("empty.lcm", ""), "empty"},
      {write("cut.lcm", good_log.substr(0, good_log.size() - 7)), "truncated"},
      {write("notes.lcm", "this is not a log\n"), "notes.lcm"},
      {write("nocmd.lcm", bus::recorded_play_log(frames_only)), "PINBALL_FLIPPER_CMD"},
  };
  for (const auto& [log, says] : cases) {
    const pinball::testing::CommandResult r = run("identify " + log + " --out " + overlay);
    EXPECT_EQ(r.exit_code, 1) << log;
    EXPECT_EQ(pinball::testing::count_lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(log), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(overlay)) << log;
  }
  // Two runs appended to one log (mode=a): the clock goes back, and sorting would shuffle the games.
  const std::string appended = write("appended.lcm", good_log + good_log);
  const pinball::testing::CommandResult twice = run("identify " + appended + " --out " + overlay);
  EXPECT_EQ(twice.exit_code, 1);
  EXPECT_NE(twice.err.find(appended + ": its clock goes back"), std::string::npos) << twice.err;
  EXPECT_FALSE(std::filesystem::exists(overlay));
  const pinball::testing::CommandResult no_folder =
      run("identify " + write("ok.lcm", good_log) + " --out " + (dir_ / "no" / "such.yaml").string());
  EXPECT_EQ(no_folder.exit_code, 1);
  EXPECT_NE(no_folder.err.find("does not exist"), std::string::npos) << no_folder.err;
}

// What would count events twice, test on what was fitted, or replace an input
// (or a device) is refused before the fit; the inputs are left as they were.
TEST_F(IdentifyCommand, RefusesRepeatedInputsAndAnOutThatIsNoNewFile) {
  const std::string log = record("one.lcm", 2, 5);
  const std::string bytes = pinball::testing::slurp(log);
  const pinball::testing::CommandResult twice = run("identify " + log + " " + log);
  EXPECT_EQ(twice.exit_code, 1);
  EXPECT_NE(twice.err.find("identify: log " + log + " is given twice: its events would count twice"),
            std::string::npos)
      << twice.err;
  const std::string other = record("two.lcm", 2, 6);
  const pinball::testing::CommandResult held_twice = run("identify " + other + " --held-out " + log + " " + log);
  EXPECT_EQ(held_twice.exit_code, 1);
  EXPECT_NE(held_twice.err.find("identify: --held-out " + log + " is given twice"), std::string::npos)
      << held_twice.err;
  const pinball::testing::CommandResult held = run("identify " + log + " --held-out " + log);
  EXPECT_EQ(held.exit_code, 1);
  EXPECT_NE(held.err.find("is also a fitted log"), std::string::npos) << held.err;
  // A copy of a fitted log held out measured the fit on its own data, exit 0.
  const std::string copy = log + ".copy.lcm";
  std::filesystem::copy_file(log, copy);
  const pinball::testing::CommandResult held_copy = run("identify " + log + " --held-out " + copy);
  EXPECT_EQ(held_copy.exit_code, 1);
  EXPECT_NE(held_copy.err.find("identify: --held-out " + copy + " is also a fitted log (a copy of " + log + ")"),
            std::string::npos)
      << held_copy.err;
  // A copy whose bytes differ (its last quarter cut) is the same recording: fitted twice, or fitted and held out.
  bus::RecordedPlay cut_play = bus::read_recorded_play(log);
  cut_play.frames.resize(cut_play.frames.size() * 3 / 4);
  const std::string cut = write("cut_copy.lcm", bus::recorded_play_log(cut_play));
  const pinball::testing::CommandResult fitted_cut = run("identify " + log + " " + cut);
  EXPECT_EQ(fitted_cut.exit_code, 1);
  EXPECT_NE(fitted_cut.err.find("identify: log " + cut + " and " + log + " share "), std::string::npos)
      << fitted_cut.err;
  EXPECT_NE(fitted_cut.err.find("one recording twice; its events would count twice"), std::string::npos)
      << fitted_cut.err;
  const pinball::testing::CommandResult held_cut = run("identify " + log + " --held-out " + cut);
  EXPECT_EQ(held_cut.exit_code, 1);
  EXPECT_NE(held_cut.err.find("one recording twice; a held-out log must be one never fitted"), std::string::npos)
      << held_cut.err;
  const pinball::testing::CommandResult over = run("identify " + log + " --out " + log);
  EXPECT_EQ(over.exit_code, 1);
  EXPECT_NE(over.err.find("--out " + log + " is the input"), std::string::npos) << over.err;
  EXPECT_EQ(pinball::testing::slurp(log), bytes);
  const pinball::testing::CommandResult device = run("identify " + log + " --bootstrap 0 --out /dev/null");
  EXPECT_EQ(device.exit_code, 1);
  EXPECT_NE(device.err.find("/dev/null: is not a regular file"), std::string::npos) << device.err;
  EXPECT_TRUE(std::filesystem::is_character_file("/dev/null"));
}

// A held-out log too short to test on is said so, not scored as a ratio of 0.
TEST_F(IdentifyCommand, AHeldOutLogWithNoMomentIsRefused) {
  const std::string log = record("fit.lcm", 2, 6);
  bus::RecordedPlay tiny = pinball::testing::record_model_play(pinball::testing::thesis_board(), 1, 0.0005, 7);
  tiny.frames.resize(20);
  const std::string held = write("tiny.lcm", bus::recorded_play_log(tiny));
  const pinball::testing::CommandResult r = run("identify " + log + " --held-out " + held);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--held-out " + held + " holds no moment to predict from"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace pinball
