#include "pinball/plot/png_file.h"

#include <stdexcept>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "pinball/core/file_name.h"
#include "pinball/core/text_file.h"

namespace pinball::plot {

void check_png_name(const std::string& path) {
  if (lowercase_extension(path) != ".png") {
    throw std::runtime_error(path + ": a PNG is written; give the file name a .png extension");
  }
}

void write_png(const cv::Mat& image, const std::string& path) {
  // PNG whatever the name would tell imwrite (r.jpg wrote a JPEG, a name
  // without an extension OpenCV's raw error), and whole (core/text_file.h).
  check_png_name(path);
  std::vector<unsigned char> bytes;
  bool ok = false;
  try {
    ok = !image.empty() && cv::imencode(".png", image, bytes);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(path + ": cannot encode the PNG: " + e.what());
  }
  if (!ok) throw std::runtime_error(path + ": cannot encode the PNG");
  write_text_file(path, std::string(bytes.begin(), bytes.end()));
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
