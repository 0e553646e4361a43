#include "pinball/plot/png_file.h"

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "common/temp_path.h"

namespace pinball::plot {
namespace {

namespace fs = std::filesystem;

TEST(WritePngTest, RoundTrips) {
  cv::Mat image(40, 50, CV_8UC3, cv::Scalar(10, 200, 30));
  image.at<cv::Vec3b>(3, 4) = cv::Vec3b(1, 2, 3);
  const std::string path = pinball::testing::temp_path("plot_png_file_test", "round.png");
  write_png(image, path);
  const cv::Mat back = cv::imread(path, cv::IMREAD_COLOR);
  ASSERT_EQ(back.size(), image.size());
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0.0);  // PNG is lossless
  fs::remove(path);
}

TEST(WritePngTest, UnwritablePathThrowsNamingThePath) {
  const std::string path = pinball::testing::temp_path("plot_png_file_test", "no_such_dir") + "/figure.png";
  try {
    write_png(cv::Mat(10, 10, CV_8UC3, cv::Scalar::all(0)), path);
    FAIL() << "write_png did not throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path));
}

TEST(WritePngTest, EmptyImageThrows) {
  EXPECT_THROW(write_png(cv::Mat(), pinball::testing::temp_path("plot_png_file_test", "empty.png")), std::runtime_error);
}

TEST(ReadGrayImageTest, ReadsWhatWritePngWroteAsGray) {
  cv::Mat image(30, 20, CV_8UC1, cv::Scalar(0));
  image.at<unsigned char>(5, 7) = 255;
  const std::string path = pinball::testing::temp_path("plot_png_file_test", "gray.png");
  write_png(image, path);
  const cv::Mat back = read_gray_image(path);
  ASSERT_EQ(back.type(), CV_8UC1);
  ASSERT_EQ(back.size(), image.size());
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0.0);
  fs::remove(path);
}

TEST(ReadGrayImageTest, AFileThatIsNoImageIsNamed) {
  const std::string path = pinball::testing::temp_path("plot_png_file_test", "text.png");
  { std::ofstream(path) << "not a picture\n"; }
  try {
    read_gray_image(path);
    FAIL() << "read_gray_image did not throw";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ": cannot be read as an image", 0), 0u) << e.what();
  }
  fs::remove(path);
  EXPECT_THROW(read_gray_image(path), std::runtime_error);  // gone: the same error
}

}  // namespace
}  // namespace pinball::plot
