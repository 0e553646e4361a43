#include "pinball/learn/learning_curve.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include <opencv2/imgcodecs.hpp>

namespace pinball::learn {
namespace {

TEST(LearningCurve, WritesCsvAndPng) {
  SearchResult r;
  r.method = "toy";
  for (int g = 1; g <= 5; ++g) r.curve.push_back({g, static_cast<std::uint64_t>(10 * g), 1.0 * g, 2.0 * g, 2.0 * g, 0.1 * g});
  const std::string csv = ::testing::TempDir() + "/curve.csv";
  const std::string png = ::testing::TempDir() + "/curve.png";
  write_curve_csv(r, csv);
  plot_curve_png(r, png);
  std::ifstream f(csv);
  std::string header, row;
  std::getline(f, header);
  std::getline(f, row);
  EXPECT_EQ(header, "method,generation,balls,population_mean,generation_best,best_so_far,wall_s");
  EXPECT_EQ(row, "toy,1,10,1,2,2,0.1");
  const cv::Mat img = cv::imread(png);
  EXPECT_EQ(img.cols, 800);
  EXPECT_EQ(img.rows, 500);
  EXPECT_THROW(write_curve_csv(r, "/nonexistent/dir/curve.csv"), std::runtime_error);
  std::remove(csv.c_str());
  std::remove(png.c_str());
}

}  // namespace
}  // namespace pinball::learn
