// The twin's parameter file: every key required, with its unit and source,
// in range, or refused naming file:key.

#include "pinball/simlab/twin_params.h"

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "common/temp_path.h"

namespace pinball::simlab {
namespace {

std::string shipped_text() {
  std::ifstream in(PINBALL_SOURCE_DIR "/config/twin.yaml");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Loads `text` from a file and returns the error's message ("" when it loads).
std::string load_error(const std::string& text) {
  const std::string path = testing::temp_path("twin", "twin_params.yaml");
  std::ofstream(path) << text;
  try {
    load_twin_params(path);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

// The shipped text with key's line replaced.
std::string with_line(const std::string& key, const std::string& line) {
  std::regex re("\n" + key + ":[^\n]*");
  return std::regex_replace(shipped_text(), re, "\n" + line);
}

TEST(TwinParams, TheShippedFileLoadsWithASourceForEveryNumber) {
  const TwinParams p = load_twin_params(PINBALL_SOURCE_DIR "/config/twin.yaml");
  EXPECT_DOUBLE_EQ(p.ball_mass_kg.value, 0.0809);
  EXPECT_EQ(p.ball_mass_kg.unit, "kg");
  EXPECT_FALSE(p.ball_mass_kg.source.empty());
  EXPECT_NO_THROW(check_twin_params(p));
}

TEST(TwinParams, RefusesAMissingKeyNamingIt) {
  const std::string e = load_error(with_line("ball_mass_kg", ""));
  EXPECT_NE(e.find("twin_params.yaml:ball_mass_kg: missing"), std::string::npos) << e;
}

TEST(TwinParams, RefusesAnUnknownKeyNamingIt) {
  const std::string e = load_error(shipped_text() + "ball_colour: {value: 1, unit: \"1\", source: x}\n");
  EXPECT_NE(e.find("ball_colour: unknown key"), std::string::npos) << e;
}

TEST(TwinParams, RefusesAWrongUnit) {
  const std::string e = load_error(with_line("ball_mass_kg", "ball_mass_kg: {value: 80.9, unit: g, source: x}"));
  EXPECT_NE(e.find("ball_mass_kg: must be given in kg, not 'g'"), std::string::npos) << e;
}

TEST(TwinParams, RefusesAValueOutOfRangeSayingTheRange) {
  const std::string e = load_error(with_line("timestep_s", "timestep_s: {value: 0.01, unit: s, source: x}"));
  EXPECT_NE(e.find("timestep_s: is 0.01 s, must be in [0.00001, 0.002] s"), std::string::npos) << e;
  // A ratio's unit "1" is not written after the number ("is 1.5 1").
  const std::string ratio =
      load_error(with_line("rubber_restitution", "rubber_restitution: {value: 1.5, unit: \"1\", source: x}"));
  EXPECT_NE(ratio.find("rubber_restitution: is 1.5, must be in [0, 0.95]"), std::string::npos) << ratio;
}

TEST(TwinParams, RefusesANumberWithoutASource) {
  const std::string e = load_error(with_line("ball_mass_kg", "ball_mass_kg: {value: 0.08, unit: kg, source: \"\"}"));
  EXPECT_NE(e.find("ball_mass_kg: needs a source"), std::string::npos) << e;
}

TEST(TwinParams, RefusesSettingsThatContradictEachOther) {
  const std::string e =
      load_error(with_line("coil_hold_torque_nm", "coil_hold_torque_nm: {value: 2.0, unit: N*m, source: x}"));
  EXPECT_NE(e.find("coil_hold_torque_nm: must not exceed coil_pulse_torque_nm"), std::string::npos) << e;
}

TEST(TwinParams, RefusesAFileThatIsNotThere) {
  EXPECT_THROW(load_twin_params("/nonexistent/twin.yaml"), std::runtime_error);
}

}  // namespace
}  // namespace pinball::simlab
