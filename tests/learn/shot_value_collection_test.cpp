#include "pinball/learn/shot_value_collection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "common/thesis_board.h"

namespace pinball::learn {
namespace {

using pinball::testing::thesis_board;

ShotValueCollectionConfig short_balls() {
  ShotValueCollectionConfig c;
  c.max_ball_time_s = 5.0;
  c.player.horizon_s = 1.0;
  return c;
}

TEST(ShotValueCollection, GathersTheSameShotsWhateverTheThreads) {
  int reports = 0;
  const ShotValueTable one = collect_shot_values(thesis_board(), short_balls(), 3, 5, 1,
                                                 [&](const std::string& line) {
                                                   ++reports;
                                                   EXPECT_NE(line.find("balls"), std::string::npos) << line;
                                                 });
  const ShotValueTable two = collect_shot_values(thesis_board(), short_balls(), 3, 5, 2);
  EXPECT_EQ(reports, 3) << "one line a ball when there are fewer than 20";
  EXPECT_GT(shots_in(one), 50.0) << "every decision's shooting plans add a shot";
  EXPECT_EQ(one.sum, two.sum);
  EXPECT_EQ(one.count, two.count);
  // Smoothed: some shots have a value, and every value is a finite mean.
  int valued = 0;
  for (const double v : one.smoothed) {
    if (std::isnan(v)) continue;
    ++valued;
    EXPECT_TRUE(std::isfinite(v));
  }
  EXPECT_GT(valued, 0);
}

TEST(ShotValueCollection, RefusesNoBallsAndAPlayerThatAlreadyValuesShots) {
  EXPECT_THROW(collect_shot_values(thesis_board(), short_balls(), 0, 1, 1), std::invalid_argument);
  ShotValueCollectionConfig c = short_balls();
  c.player.shot_values = std::make_shared<const ShotValueTable>(make_shot_value_table(2));
  EXPECT_THROW(collect_shot_values(thesis_board(), c, 1, 1, 1), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::learn
