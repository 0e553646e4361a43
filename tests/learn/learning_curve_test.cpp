#include "pinball/learn/learning_curve.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "common/figure_check.h"

namespace pinball::learn {
namespace {

TEST(LearningCurve, WritesCsvAndDrawsTheFigure) {
  SearchResult r;
  r.method = "toy";
  for (int g = 1; g <= 5; ++g) {
    r.curve.push_back({g, static_cast<std::uint64_t>(10 * g), 1.0 * g, 2.0 * g, 2.0 * g, 0.1 * g, 0.25 * g});
  }
  const std::string csv = ::testing::TempDir() + "/curve.csv";
  write_curve_csv(r, csv);
  const cv::Mat img = draw_curve(r);
  std::ifstream f(csv);
  std::string header, row;
  std::getline(f, header);
  std::getline(f, row);
  EXPECT_EQ(header, "method,generation,balls,population_mean,generation_best,best_so_far,wall_s,population_ci95");
  EXPECT_EQ(row, "toy,1,10,1,2,2,0.1,0.25");
  // Three series (population with its band, generation best, best so far) and their legend swatches.
  pinball::testing::expect_figure_image(img, "the learning curve", cv::Size(800, 440), 3, 3);
  // The band: the population colour lightened, over a fair area.
  const cv::Scalar c = plot::palette_colour(0);
  const auto lighter = [](double v) { return 255 - 0.45 * 0.45 * (255 - v); };  // tinted 55 %, blended at 45 %
  const cv::Scalar band(lighter(c[0]), lighter(c[1]), lighter(c[2]));
  EXPECT_GT(pinball::testing::count_colour(img, band, 10), 2000);
  EXPECT_THROW(write_curve_csv(r, "/nonexistent/dir/curve.csv"), std::runtime_error);
  std::remove(csv.c_str());
}

}  // namespace
}  // namespace pinball::learn
