#pragma once
// Checks that a figure is written and not trivial: read back from its PNG,
// enough ink, the palette's colours present (the series and their legend
// swatches), shared by every figure's test.

#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "pinball/plot/draw.h"

namespace pinball::testing {

/// Pixels within `tolerance` (each channel) of `colour`.
inline int count_colour(const cv::Mat& bgr, const cv::Scalar& colour, int tolerance = 12) {
  cv::Mat mask;
  cv::inRange(bgr, colour - cv::Scalar::all(tolerance), colour + cv::Scalar::all(tolerance), mask);
  return cv::countNonZero(mask);
}

/// Pixels that are not (near) white.
inline int count_ink(const cv::Mat& bgr) {
  return bgr.rows * bgr.cols - count_colour(bgr, cv::Scalar(255, 255, 255), 10);
}

/// How many of palette colours 0..n-1 cover at least `min_pixels` pixels each.
inline int palette_colours_present(const cv::Mat& bgr, int n, int min_pixels = 20) {
  int present = 0;
  for (int i = 0; i < n; ++i) present += count_colour(bgr, plot::palette_colour(i)) >= min_pixels ? 1 : 0;
  return present;
}

/// Reads a PNG back (BGR); fails the test when it is missing or empty.
inline cv::Mat read_figure(const std::string& path) {
  const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  EXPECT_FALSE(image.empty()) << path << " was not written or is not an image";
  return image;
}

/// A figure (`name` in messages) that is at least `min_size`, with ink on
/// more than 2 % of it (not blank) and at least `palette_colours` of the
/// palette's first `palette_n` colours.
inline void expect_figure_image(const cv::Mat& image, const std::string& name, cv::Size min_size, int palette_colours,
                                int palette_n = 8) {
  ASSERT_FALSE(image.empty()) << name << " is empty";
  EXPECT_GE(image.cols, min_size.width) << name;
  EXPECT_GE(image.rows, min_size.height) << name;
  EXPECT_GT(count_ink(image), image.rows * image.cols / 50) << name << " is (nearly) blank";
  EXPECT_GE(palette_colours_present(image, palette_n), palette_colours) << name << ": too few palette colours";
}

/// expect_figure_image of the figure read back from `path`.
inline void expect_figure(const std::string& path, cv::Size min_size, int palette_colours, int palette_n = 8) {
  const cv::Mat image = read_figure(path);
  if (image.empty()) return;
  expect_figure_image(image, path, min_size, palette_colours, palette_n);
}

}  // namespace pinball::testing
