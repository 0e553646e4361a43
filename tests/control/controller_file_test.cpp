#include "pinball/control/controller_file.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "common/error_text.h"
#include "common/temp_path.h"
#include "common/thesis_board.h"

namespace pinball::control {
namespace {

TEST(ControllerFile, RoundTripKeepsEveryValue) {
  ControllerSpec s;
  ActionFunctionConfig c = uniform_partition(3);
  c.h_borders = {1.0};
  c.rolling_minicontrollers = true;
  c.gain_range = {0.1, 0.2, 0.3, 0.4};
  s.action_function = ActionFunction(c);
  Rng rng(3);
  s.action_function.randomise(rng);
  s.actuator.max_hold_s = 0.75;
  s.actuator.lead_actuation_delay_s = 0.004;
  s.launcher_pull = 0.95;
  s.randomise_launch = true;
  s.launch_pull_min = 0.6;
  s.note = "test";
  const std::string path = ::testing::TempDir() + "/controller_roundtrip.json";
  save_controller(s, path);
  const ControllerSpec r = load_controller(path);
  EXPECT_EQ(r.action_function.config().angle_borders_rad, c.angle_borders_rad);
  EXPECT_EQ(r.action_function.config().h_borders, c.h_borders);
  EXPECT_TRUE(r.action_function.config().rolling_minicontrollers);
  EXPECT_EQ(r.action_function.config().gain_range, c.gain_range);
  ASSERT_EQ(r.action_function.partitions(), s.action_function.partitions());
  for (int i = 0; i < r.action_function.partitions(); ++i) {
    EXPECT_EQ(r.action_function.minicontroller(i).a, s.action_function.minicontroller(i).a);  // bit for bit
    EXPECT_EQ(r.action_function.minicontroller(i).flipper, s.action_function.minicontroller(i).flipper);
  }
  EXPECT_EQ(r.actuator.max_hold_s, 0.75);
  EXPECT_EQ(r.actuator.lead_actuation_delay_s, 0.004);
  EXPECT_EQ(r.launcher_pull, 0.95);
  EXPECT_TRUE(r.randomise_launch);
  EXPECT_EQ(r.launch_pull_min, 0.6);
  EXPECT_EQ(r.note, "test");
  EXPECT_EQ(controller_to_json(r), controller_to_json(s));
  std::remove(path.c_str());
}

void expect_error(const std::string& text, const std::string& fragment) {
  try {
    controller_from_json(text, "bad.json");
    FAIL() << "no error for " << text;
  } catch (const ControllerFileError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind("bad.json: ", 0), 0u) << e.what();
  }
}

TEST(ControllerFile, BadFilesGiveClearErrors) {
  ControllerSpec s;
  const std::string good = controller_to_json(s);
  expect_error("{not json", "not valid JSON");
  expect_error("[1,2]", "JSON object");
  expect_error(R"({"format":"other","version":1})", "format");
  std::string v2 = good;
  v2.replace(v2.find("\"version\": 1"), 12, "\"version\": 2");
  expect_error(v2, "version: unsupported");
  std::string flip = good;
  flip.replace(flip.find("\"left\""), 6, "\"up\"");
  expect_error(flip, "minicontrollers[0].flipper");
  std::string missing = good;
  missing.replace(missing.find("\"minicontrollers\""), 17, "\"minis\"");
  expect_error(missing, "minicontrollers: missing");
  // A misspelt key kept its default in silence; every file refuses it now, by the key it lacks.
  std::string pul = good;
  pul.replace(pul.find("\"pull\""), 6, "\"pul\"");
  expect_error(pul, "launcher.pull: missing");
  std::string pul_too = good;
  pul_too.replace(pul_too.find("\"pull\""), 6, "\"pul\": 1, \"pull\"");
  expect_error(pul_too, "launcher.pul: unknown key");
  // A dropped key, or a section that is null, played the defaults (a planner with every default).
  nlohmann::json dropped = nlohmann::json::parse(good);
  ASSERT_EQ(dropped.at("actuator").erase("max_hold_s"), 1u);
  expect_error(dropped.dump(), "actuator.max_hold_s: missing");
  std::string null_section = good;
  null_section.replace(null_section.find("\"note\""), 6, "\"planner\": null, \"note\"");
  expect_error(null_section, "bad.json: planner: expected a mapping, got null");
  // minicontrollers[i].partition is for a reader; one that contradicts the order misled it.
  nlohmann::json reordered = nlohmann::json::parse(good);
  reordered["minicontrollers"][0]["partition"] = 5;
  expect_error(reordered.dump(), "minicontrollers[0].partition: must be 0, got 5: its place in the list decides");
  reordered["minicontrollers"][0]["partition"] = "0";  // "must be 0" of a "0" read as nonsense
  expect_error(reordered.dump(), "minicontrollers[0].partition: must be 0, got \"0\"");
  std::string quoted_version = good;
  quoted_version.replace(quoted_version.find("\"version\": 1"), 12, "\"version\": \"1\"");
  expect_error(quoted_version, "version: must be a whole number (1), got \"1\"");
  std::string extra = good;
  extra.replace(extra.find("\"note\""), 6, "\"bogus\": 1, \"note\"");
  expect_error(extra, "bad.json: bogus: unknown key");
  EXPECT_THROW(load_controller("/nonexistent/controller.json"), ControllerFileError);
}

ControllerSpec with_shots() {
  ControllerSpec s;
  ImitationConfig c;
  c.neighbours = 5;
  c.angle_scale_rad = 0.07;
  c.h_scale = 0.2;
  c.speed_scale_mps = 0.4;
  c.max_hold_s = 0.8;
  c.lead_s = 0.001;
  s.shot_table = std::make_shared<const ShotTable>(std::vector<ShotExample>{{0, false, -1.0 / 3.0, 0.5, 2.25, 1, 0.0512345678901234, 0.03},
                                                {1, true, 0.436, 1.3, 1.0, -1, 0.0, 0.0}},
                       c);
  return s;
}

TEST(ControllerFile, ShotTableRoundTripsOneShotPerLine) {
  const ControllerSpec s = with_shots();
  const std::string text = controller_to_json(s);
  EXPECT_NE(text.find("\n      [0,0,"), std::string::npos) << text;
  const ControllerSpec r = controller_from_json(text, "shots.json");
  ASSERT_NE(r.shot_table, nullptr);
  const ImitationConfig& c = r.shot_table->config();
  EXPECT_EQ(c.neighbours, 5);
  EXPECT_EQ(c.angle_scale_rad, 0.07);
  EXPECT_EQ(c.h_scale, 0.2);
  EXPECT_EQ(c.speed_scale_mps, 0.4);
  EXPECT_EQ(c.max_hold_s, 0.8);
  EXPECT_EQ(c.lead_s, 0.001);
  ASSERT_EQ(r.shot_table->examples().size(), 2u);
  const ShotExample& a = r.shot_table->examples()[0];
  EXPECT_EQ(a.angle_rad, -1.0 / 3.0);  // bit for bit
  EXPECT_EQ(a.d_fire_m, 0.0512345678901234);
  EXPECT_EQ(a.fired_flipper, 1);
  EXPECT_TRUE(r.shot_table->examples()[1].rolling);
  EXPECT_EQ(controller_to_json(r), text);
  EXPECT_NE(dynamic_cast<ImitationController*>(make_flipper_controller(r).get()), nullptr);
  EXPECT_NE(dynamic_cast<ActuatorController*>(make_flipper_controller(ControllerSpec{}).get()), nullptr);
}

TEST(ControllerFile, BadShotTablesNameTheField) {
  const std::string good = controller_to_json(with_shots());
  std::string short_row = good;
  short_row.replace(short_row.find("[0,0,"), 5, "[0,");
  expect_error(short_row, "imitation.shots[0]: must have 8 numbers");
  std::string bad_flipper = good;
  bad_flipper.replace(bad_flipper.find("[0,0,"), 5, "[7,0,");
  expect_error(bad_flipper, "imitation.shots[0]: flipper must be 0 (left) or 1 (right)");
  std::string half = good;
  half.replace(half.find("[0,0,"), 5, "[0.5,0,");
  expect_error(half, "imitation.shots[0]: flipper must be 0 (left) or 1 (right)");
  std::string k = good;
  k.replace(k.find("\"neighbours\": 5"), 15, "\"neighbours\": 0");
  expect_error(k, "imitation.neighbours: must be in [1, 32]");
  // The rows are read in this build's order, whatever shot_fields says: another order is refused.
  nlohmann::json reversed = nlohmann::json::parse(good);
  std::swap(reversed["imitation"]["shot_fields"][0], reversed["imitation"]["shot_fields"][1]);
  expect_error(reversed.dump(), "imitation.shot_fields: must be [\"flipper\",\"rolling\",");
}

// `text` with its first `from` replaced by `to`.
std::string with(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

TEST(ControllerFile, ShotTableSettingsHaveSaneRanges) {
  const std::string good = controller_to_json(with_shots());
  // A scale of 1e-6 made the lookup spin for ever, 1.5e-9 asked for an oversized allocation.
  for (const char* scale : {"1e-06", "1.5e-09", "0", "-0.1", "4"}) {
    expect_error(with(good, "\"angle_scale_rad\": 0.07", std::string("\"angle_scale_rad\": ") + scale),
                 "bad.json: imitation.angle_scale_rad: must be in [0.001, 3.14159] rad");
  }
  expect_error(with(good, "\"h_scale\": 0.2", "\"h_scale\": 1e-5"), "imitation.h_scale: must be in [0.001, 10]");
  expect_error(with(good, "\"speed_scale_mps\": 0.4", "\"speed_scale_mps\": 500"),
               "imitation.speed_scale_mps: must be in [0.001, 100] m/s");
  expect_error(with(good, "\"max_hold_s\": 0.8", "\"max_hold_s\": 60"), "imitation.max_hold_s: must be in [0, 10] s");
  expect_error(with(good, "\"lead_s\": 0.001", "\"lead_s\": 0.5"), "imitation.lead_s: must be in [0, 0.1] s");
  expect_error(with(good, "\"lead_s\": 0.001", "\"lead_s\": 0.001, \"lead_actuation_delay_s\": 0.2"),
               "imitation.lead_actuation_delay_s: must be in [0, 0.1] s");
}

TEST(ControllerFile, AShotTablesLeadRoundTripsAndATableWithoutOneLoadsWithout) {
  ControllerSpec s = with_shots();
  const std::string plain = controller_to_json(s);
  EXPECT_EQ(plain.find("lead_actuation_delay_s"), std::string::npos) << "no lead, no key: older tables load as before";
  EXPECT_FALSE(controller_from_json(plain, "old.json").shot_table->config().lead_actuation_delay_s.has_value());
  ImitationConfig c = s.shot_table->config();
  c.lead_actuation_delay_s = 0.004;
  s.shot_table = std::make_shared<const ShotTable>(s.shot_table->examples(), c);
  const ControllerSpec r = controller_from_json(controller_to_json(s), "led.json");
  EXPECT_EQ(r.shot_table->config().lead_actuation_delay_s, 0.004);
}

TEST(ControllerFile, ShotsOutOfRangeAreRefusedBeforeAnyCast) {
  const std::string good = controller_to_json(with_shots());
  const std::string row = "[0,0,-0.3333333333333333,0.5,2.25,1,0.0512345678901234,0.03]";
  ASSERT_NE(good.find(row), std::string::npos) << good;
  auto shot = [&](const std::string& r) { return with(good, row, r); };
  // Integers written as huge numbers: refused, not cast (UBSan float-cast-overflow stays silent).
  expect_error(shot("[1e300,0,0.1,0.5,2.0,1,0.05,0.03]"), "imitation.shots[0]: flipper must be 0 (left) or 1 (right)");
  expect_error(shot("[0,0,0.1,0.5,2.0,-1e300,0.05,0.03]"), "imitation.shots[0]: fired_flipper must be -1 (pass), 0 or 1");
  expect_error(shot("[0,2,0.1,0.5,2.0,1,0.05,0.03]"), "imitation.shots[0]: rolling must be 0 or 1");
  expect_error(shot("[0,0,7,0.5,2.0,1,0.05,0.03]"), "imitation.shots[0]: angle_rad must be in [-3.14159, 3.14159] rad");
  expect_error(shot("[0,0,0.1,1e200,2.0,1,0.05,0.03]"), "imitation.shots[0]: h must be in [-100, 100]");
  expect_error(shot("[0,0,0.1,0.5,-2,1,0.05,0.03]"), "imitation.shots[0]: speed_mps must be in [0, 100] m/s");
  expect_error(shot("[0,0,0.1,0.5,2.0,1,50,0.03]"), "imitation.shots[0]: d_fire_m must be in [-10, 10] m");
  expect_error(shot("[0,0,0.1,0.5,2.0,1,0.05,3600]"), "imitation.shots[0]: hold_s must be in [0, 10] s");
}

TEST(ControllerFile, GainsHoldsAndPartitionsHaveSaneRanges) {
  ControllerSpec s;
  const std::string good = controller_to_json(s);
  expect_error(with(good, "\"max_hold_s\": 1.0", "\"max_hold_s\": 11"), "bad.json: actuator.max_hold_s: must be in [0, 10] s");
  expect_error(with(good, "\"max_hold_s\": 1.0", "\"max_hold_s\": -1"), "actuator.max_hold_s: must be in [0, 10] s");
  expect_error(with(good, "\"max_hold_s\": 1.0", "\"max_hold_s\": 1.0, \"lead_actuation_delay_s\": 0.5"),
               "actuator.lead_actuation_delay_s: must be in [0, 0.1] s");
  // Without a lead the key is not written, and such a file (all before the lead) loads without one.
  EXPECT_EQ(good.find("lead_actuation_delay_s"), std::string::npos);
  EXPECT_FALSE(controller_from_json(good, "old.json").actuator.lead_actuation_delay_s.has_value());
  expect_error(with(good, "\"a\": [\n        0.0", "\"a\": [\n        1e6"), "minicontrollers[0].a: must each be in [-10, 10]");
  expect_error(with(good, "\"gain_range\": [\n      0.12", "\"gain_range\": [\n      50"),
               "partition.gain_range: must each be in [0, 10]");
  ActionFunctionConfig many;
  for (int i = 0; i < kMaxBins; ++i) many.h_borders.push_back(i);  // 65 bins
  const std::string borders = nlohmann::json(many.h_borders).dump();
  expect_error(with(good, "\"h_borders\": []", "\"h_borders\": " + borders),
               "partition.h_borders: must have at most 63 borders (64 bins)");
}

TEST(ControllerFile, IntegersAreNotTruncatedNorKeysRepeated) {
  const std::string good = controller_to_json(ControllerSpec{});
  expect_error(with(good, "\"version\": 1", "\"version\": 4294967297"), "bad.json: version: unsupported");
  expect_error(with(good, "\"version\": 1", "\"version\": 1, \"version\": 1"), "bad.json: version: duplicate key");
  expect_error(with(good, "\"max_hold_s\": 1.0", "\"max_hold_s\": 1e400"), "bad.json: (file): not valid JSON");
}

ControllerSpec spastic_spec(double reach_m, double max_hold_s) {
  ControllerSpec s;
  s.spastic = SpasticConfig{reach_m, max_hold_s};
  return s;
}

TEST(ControllerFile, ASpasticFileRoundTripsAndPlaysTheSpasticFlipper) {
  const ControllerSpec s = spastic_spec(0.03, 0.5);
  const ControllerSpec r = controller_from_json(controller_to_json(s), "spastic.json");
  ASSERT_TRUE(r.spastic);
  EXPECT_EQ(r.spastic->reach_m, 0.03);
  EXPECT_EQ(r.spastic->max_hold_s, 0.5);
  EXPECT_EQ(controller_to_json(r), controller_to_json(s));
  EXPECT_EQ(controller_to_json(ControllerSpec{}).find("spastic"), std::string::npos) << "no settings, no key";
  // It fires within its reach, where the default actuator's zero gains would not.
  const std::unique_ptr<FlipperController> c = make_flipper_controller(r);
  track::TrackerOutput out;
  out.projection.valid = true;
  out.projection.hittable = true;
  out.projection.flipper = track::kRightFlipper;
  out.projection.d_m = 0.02;
  std::array<bool, 2> on{false, false};
  c->update(out, 1.0, on);
  EXPECT_TRUE(on[track::kRightFlipper]);
  EXPECT_FALSE(on[track::kLeftFlipper]);
}

TEST(ControllerFile, ASpasticFileIsRefusedOutOfRangeOrBesideAnotherController) {
  const std::string good = controller_to_json(spastic_spec(0.03, 0.5));
  expect_error(with(good, "\"reach_m\": 0.03", "\"reach_m\": -1"), "bad.json: spastic.reach_m: must be in (0, 1] m");
  expect_error(with(good, "\"max_hold_s\": 0.5", "\"max_hold_s\": 0"), "bad.json: spastic.max_hold_s: must be in (0, 10] s");
  // Which would play? Neither: the file is refused.
  ControllerSpec both = with_shots();
  both.spastic = SpasticConfig{};
  expect_error(controller_to_json(both), "bad.json: spastic: a spastic controller file holds no imitation or planner object");
  both.shot_table.reset();
  both.planner = PlannerSettings{};
  expect_error(controller_to_json(both), "bad.json: spastic: a spastic controller file holds no imitation or planner object");
  EXPECT_THROW(make_flipper_controller(both), std::invalid_argument);
}

TEST(ControllerFile, ACradleFileRoundTripsAndIsRefusedBesideAnotherPlayer) {
  ControllerSpec s;
  s.cradle = CradleConfig{0.092, 0.4, 0.002, 3.0};
  const ControllerSpec r = controller_from_json(controller_to_json(s), "cradle.json");
  ASSERT_TRUE(r.cradle);
  EXPECT_EQ(r.cradle->drop_s, 0.092);
  EXPECT_EQ(r.cradle->rest_s, 0.4);
  EXPECT_EQ(r.cradle->still_band_m, 0.002);
  EXPECT_EQ(r.cradle->max_hold_s, 3.0);
  EXPECT_EQ(controller_to_json(r), controller_to_json(s));
  EXPECT_NE(dynamic_cast<CradleController*>(make_flipper_controller(r).get()), nullptr);
  const std::string good = controller_to_json(s);
  expect_error(with(good, "\"drop_s\": 0.092", "\"drop_s\": 2"), "bad.json: cradle.drop_s: must be in (0, 1] s");
  ControllerSpec both = s;
  both.spastic = SpasticConfig{};
  expect_error(controller_to_json(both),
               "bad.json: cradle: a cradle controller file holds no imitation, planner or spastic object");
  EXPECT_THROW(make_flipper_controller(both), std::invalid_argument);
  EXPECT_TRUE(load_controller(PINBALL_SOURCE_DIR "/controllers/cradle.json").cradle);
}

// docs/results.md quotes every file under controllers/: each must load as shipped.
TEST(ControllerFile, EveryShippedControllerLoads) {
  int loaded = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(PINBALL_SOURCE_DIR "/controllers")) {
    if (entry.path().extension() != ".json") continue;
    EXPECT_NO_THROW(load_controller(entry.path().string())) << entry.path();
    ++loaded;
  }
  EXPECT_GE(loaded, 13);
  EXPECT_TRUE(load_controller(PINBALL_SOURCE_DIR "/controllers/spastic.json").spastic);
}

TEST(ControllerFile, AShotValueTableThatIsNoFileIsRefusedAtLoadNamingTheKey) {
  const std::string dir = pinball::testing::temp_path("controller_file", "shot_values");
  std::filesystem::create_directories(dir);
  nlohmann::json j = nlohmann::json::parse(controller_to_json([] {
    ControllerSpec s;
    s.planner = PlannerSettings{};
    return s;
  }()));
  auto load_with = [&](const nlohmann::json& table) {
    j["planner"]["shot_values"] = table;
    const std::string path = dir + "/planner.json";
    std::ofstream(path) << j.dump();
    return pinball::testing::error_text([&] { load_controller(path); });
  };
  EXPECT_NE(load_with("").find("planner.json: planner.shot_values: names no file"), std::string::npos);
  EXPECT_NE(load_with("absent.json").find("planner.shot_values: " + dir + "/absent.json does not exist"),
            std::string::npos);
  EXPECT_NE(load_with(dir).find("planner.shot_values: " + dir + " is not a file"), std::string::npos);
  std::ofstream(dir + "/values.json") << "{}";
  EXPECT_EQ(load_with("values.json"), "no error") << "relative to the controller file's folder";
  EXPECT_NE(pinball::testing::error_text([&] { load_controller(dir); }).find("is a folder, not a file"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(ControllerFile, ALaunchTooWeakForTheBoardIsRefusedNamingTheFileAndKey) {
  const table::Board& board = pinball::testing::thesis_board();
  ControllerSpec s;
  EXPECT_EQ(pinball::testing::error_text([&] { check_controller_launch(s, board, "c.json"); }), "no error")
      << "a negative pull is the board's own";
  s.launcher_pull = 0.0;  // within the file's range, yet no launch leaves the plunger
  const std::string weak = pinball::testing::error_text([&] { check_controller_launch(s, board, "c.json"); });
  EXPECT_EQ(weak.rfind("c.json: launcher.pull: launch pull 0 ", 0), 0u) << weak;
  s.launcher_pull = 0.5;
  EXPECT_EQ(pinball::testing::error_text([&] { check_controller_launch(s, board, "c.json"); }), "no error");
  s.randomise_launch = true;  // then the range's low end is the pull that matters
  s.launch_pull_min = 0.01;
  const std::string range = pinball::testing::error_text([&] { check_controller_launch(s, board, "c.json"); });
  EXPECT_EQ(range.rfind("c.json: launcher.pull_min: ", 0), 0u) << range;
}

}  // namespace
}  // namespace pinball::control
