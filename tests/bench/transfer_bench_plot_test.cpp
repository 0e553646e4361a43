#include <filesystem>
#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "common/temp_path.h"
#include "transfer_bench.h"
#include "transfer_report_fixture.h"

namespace pinball::bench {
namespace {

using pinball::testing::made_report;
using pinball::testing::temp_path;

TEST(TransferPlot, OnePanelPerFamilyWithTheControllersDrawn) {
  const std::string path = temp_path("transfer", "plot.png");
  plot_transfer_png(made_report(), path);
  ASSERT_GT(std::filesystem::file_size(path), 1000u);
  const cv::Mat img = cv::imread(path);
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.cols, 4 * 400) << "four panels across";
  EXPECT_EQ(img.rows, 56 + 300) << "two families: one row";
  // The learned controller's curve (the first colour, BGR 200, 90, 0) is on the picture.
  int curve = 0;
  for (int y = 0; y < img.rows; ++y) {
    for (int x = 0; x < img.cols; ++x) curve += img.at<cv::Vec3b>(y, x) == cv::Vec3b(200, 90, 0) ? 1 : 0;
  }
  EXPECT_GT(curve, 100);
  std::filesystem::remove(path);
}

TEST(TransferPlot, RefusesAReportWithoutAModelWorldAndAPathItCannotWrite) {
  TransferReport r = made_report();
  EXPECT_THROW(plot_transfer_png(r, "/no/such/folder/x.png"), std::runtime_error);
  r.worlds.erase(r.worlds.begin());
  EXPECT_THROW(plot_transfer_png(r, temp_path("transfer", "none.png")), std::runtime_error);
}

}  // namespace
}  // namespace pinball::bench
