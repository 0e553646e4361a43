#include "pinball/learn/shot_values.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace pinball::learn {
namespace {

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("shot_values_test_" + name)).string();
}

TEST(ShotValues, LooksUpTheMeanOfTheShotsNearAndNothingWhereTooFewAre) {
  ShotValueTable t = make_shot_value_table(2);
  t.min_weight = 5.0;
  for (int i = 0; i < 10; ++i) add_shot(t, 0, 90.5, 2.1, i % 2 == 0 ? 1000.0 : 3000.0);
  for (int i = 0; i < 10; ++i) add_shot(t, 1, 90.5, 2.1, -20000.0);
  smooth(t);
  EXPECT_EQ(shots_in(t), 20.0);
  // Every shot sits in one bin: the kernel mean there is their plain mean, for each bat apart.
  ASSERT_TRUE(shot_value(t, 0, 91.0, 2.2));
  EXPECT_NEAR(*shot_value(t, 0, 91.0, 2.2), 2000.0, 1e-9);
  EXPECT_NEAR(*shot_value(t, 1, 91.0, 2.2), -20000.0, 1e-9);
  // Two degrees off, the same shots still carry the lookup, with weight exp(-1/8) each.
  ASSERT_TRUE(shot_value(t, 0, 93.0, 2.2));
  EXPECT_NEAR(*shot_value(t, 0, 93.0, 2.2), 2000.0, 1e-9);
  // Far off, their kernel weight is below min_weight: no value.
  EXPECT_FALSE(shot_value(t, 0, 120.0, 2.2));
  EXPECT_FALSE(shot_value(t, 0, 91.0, 5.0));
  // Outside the table: a downward shot, a bat the table lacks, a NaN.
  EXPECT_FALSE(shot_value(t, 0, -10.0, 2.2));
  EXPECT_FALSE(shot_value(t, 2, 91.0, 2.2));
  EXPECT_FALSE(shot_value(t, 0, std::nan(""), 2.2));
}

TEST(ShotValues, WeighsNeighbouringBinsByTheKernel) {
  ShotValueTable t = make_shot_value_table(1);
  t.min_weight = 1.0;
  add_shot(t, 0, 91.0, 2.1, 0.0);      // bin 45
  add_shot(t, 0, 95.0, 2.1, 1000.0);   // bin 47: two bins, 4 degrees, away
  smooth(t);
  // At bin 46 both are 2 degrees away: equal weights.
  EXPECT_NEAR(*shot_value(t, 0, 93.0, 2.1), 500.0, 1e-9);
  // At bin 45: weights 1 and exp(-0.5) (4 degrees at a 4 degree kernel).
  const double w = std::exp(-0.5);
  EXPECT_NEAR(*shot_value(t, 0, 91.0, 2.1), 1000.0 * w / (1.0 + w), 1e-9);
}

TEST(ShotValues, WritesAndReadsBackTheSameTable) {
  ShotValueTable t = make_shot_value_table(2);
  for (int i = 0; i < 50; ++i) add_shot(t, i % 2, 60.0 + i, 1.0 + 0.05 * i, 100.0 * i);
  smooth(t);
  const std::string path = temp_path("roundtrip.json");
  write_shot_value_table(t, path);
  const ShotValueTable back = read_shot_value_table(path);
  EXPECT_EQ(back.sum, t.sum);
  EXPECT_EQ(back.count, t.count);
  ASSERT_EQ(back.smoothed.size(), t.smoothed.size());
  for (std::size_t i = 0; i < t.smoothed.size(); ++i) {
    if (std::isnan(t.smoothed[i])) {
      EXPECT_TRUE(std::isnan(back.smoothed[i]));
    } else {
      EXPECT_DOUBLE_EQ(back.smoothed[i], t.smoothed[i]);
    }
  }
  std::filesystem::remove(path);
}

TEST(ShotValues, RefusesAMissingFileAnotherFormatAndBinsThatDoNotAgree) {
  const auto refused = [](const std::string& path, const std::string& says) {
    try {
      read_shot_value_table(path);
      ADD_FAILURE() << path << " was read";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  };
  refused(temp_path("absent.json"), "cannot open");
  const std::string folder = temp_path("a_folder");
  std::filesystem::create_directories(folder);
  refused(folder, "is a folder, not a file");  // it had said only "basic_filebuf::underflow error"
  std::filesystem::remove(folder);
  const std::string other = temp_path("other.json");
  std::ofstream(other) << R"({"format": "pinball-controller"})";
  refused(other, "not a shot-value table");
  const std::string broken = temp_path("broken.json");
  write_shot_value_table(make_shot_value_table(2), broken);
  {
    std::ifstream in(broken);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    text.replace(text.find("\"speed_bins\":24"), 15, "\"speed_bins\":25");
    std::ofstream(broken) << text;
  }
  refused(broken, "bins");
  const std::string truncated = temp_path("truncated.json");
  std::ofstream(truncated) << R"({"format": "pinball-shot-values", "flippers": 2)";
  refused(truncated, "not valid JSON");
  for (const std::string& p : {other, broken, truncated}) std::filesystem::remove(p);
}

}  // namespace
}  // namespace pinball::learn
