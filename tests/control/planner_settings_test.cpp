#include "pinball/control/planner_settings.h"

#include <gtest/gtest.h>

#include "pinball/control/controller_file.h"

namespace pinball::control {
namespace {

TEST(PlannerSettings, DefaultsAreInRangeAndEachBadSettingIsNamed) {
  EXPECT_FALSE(check_planner_settings(PlannerSettings{}));
  PlannerSettings s;
  s.fire_frames = -1;
  EXPECT_EQ(check_planner_settings(s).key, "fire_frames");
  s = {};
  s.short_hold_s = 0.0;
  EXPECT_EQ(check_planner_settings(s).key, "short_hold_s");
  s = {};
  s.horizon_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(check_planner_settings(s).key, "horizon_s");
  s = {};
  s.drain_penalty = -1.0;
  EXPECT_EQ(check_planner_settings(s).key, "drain_penalty");
  s = {};
  s.actuation_delay_s = 0.2;
  EXPECT_EQ(check_planner_settings(s).key, "actuation_delay_s");
  s = {};
  s.step_budget = 999;
  EXPECT_EQ(check_planner_settings(s).key, "step_budget");
  s.step_budget = 10'000'001;
  EXPECT_EQ(check_planner_settings(s).key, "step_budget");
}

TEST(PlannerSettings, AControllerFileKeepsThemAndRefusesABadOne) {
  ControllerSpec spec;
  spec.planner = PlannerSettings{};
  spec.planner->actuation_delay_s = 0.016;
  spec.planner->horizon_s = 2.0;
  spec.planner->step_budget = 5000;
  const ControllerSpec back = controller_from_json(controller_to_json(spec), "p.json");
  ASSERT_TRUE(back.planner.has_value());
  EXPECT_DOUBLE_EQ(back.planner->actuation_delay_s, 0.016);
  EXPECT_DOUBLE_EQ(back.planner->horizon_s, 2.0);
  EXPECT_EQ(back.planner->step_budget, 5000);
  // Without the belief board the plain factory cannot build it, and says so.
  EXPECT_THROW(make_flipper_controller(back), std::invalid_argument);

  std::string text = controller_to_json(spec);
  text.replace(text.find("\"horizon_s\": 2.0"), 16, "\"horizon_s\": -1.0");
  try {
    controller_from_json(text, "p.json");
    FAIL() << "accepted a negative horizon";
  } catch (const ControllerFileError& e) {
    EXPECT_NE(std::string(e.what()).find("planner.horizon_s"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pinball::control
