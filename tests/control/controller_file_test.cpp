#include "pinball/control/controller_file.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

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
  s.launcher_pull = 0.95;
  s.randomise_launch = true;
  s.launch_pull_min = 0.6;
  s.note = "test";
  const std::string path = testing::TempDir() + "/controller_roundtrip.json";
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
  expect_error(bad_flipper, "imitation: shot table: example 0: flipper");
  std::string half = good;
  half.replace(half.find("[0,0,"), 5, "[0.5,0,");
  expect_error(half, "imitation.shots[0]: flipper numbers must be integers");
  std::string k = good;
  k.replace(k.find("\"neighbours\": 5"), 15, "\"neighbours\": 0");
  expect_error(k, "imitation: shot table: neighbours");
}

}  // namespace
}  // namespace pinball::control
