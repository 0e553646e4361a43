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

}  // namespace
}  // namespace pinball::control
