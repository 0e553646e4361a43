#include <filesystem>
#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "common/figure_check.h"
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
  // Two families: two panels side by side, a title, a note and the legend above them.
  pinball::testing::expect_figure(path, cv::Size(2 * 420, 320 + 60), 1);
  const cv::Mat img = pinball::testing::read_figure(path);
  ASSERT_FALSE(img.empty());
  EXPECT_GE(img.cols, 2 * 420) << "one panel per family";
  EXPECT_LT(img.cols, 3 * 420) << "one panel per family";
  // The learned controller's curve (the palette's first colour) and the baseline are on the picture.
  EXPECT_GT(pinball::testing::count_colour(img, plot::palette_colour(0)), 100);
  EXPECT_GT(pinball::testing::count_colour(img, plot::muted_colour()), 100);
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
