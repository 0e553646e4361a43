#include "pinball/plot/png_file.h"

#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

namespace pinball::plot {

void write_png(const cv::Mat& image, const std::string& path) {
  bool ok = false;
  try {
    ok = !image.empty() && cv::imwrite(path, image);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("write_png: cannot write '" + path + "': " + e.what());
  }
  if (!ok) throw std::runtime_error("write_png: cannot write '" + path + "'");
}

cv::Mat read_gray_image(const std::string& path) {
  cv::Mat image;
  try {
    image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(path + ": cannot be read as an image (" + e.what() + ")");
  }
  if (image.empty()) throw std::runtime_error(path + ": cannot be read as an image");
  return image;
}

}  // namespace pinball::plot
