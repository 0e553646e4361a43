#pragma once
// Writes a figure or picture to a PNG file, and reads a gray picture back
// (a calibration frame, an occluder mask). Apart from draw.h because OpenCV's
// imgcodecs loads about 120 shared libraries (codecs, GDAL) that only the
// programs reading or writing files need, not every library that draws.

#include <string>

#include <opencv2/core.hpp>

namespace pinball::plot {

/// Throws std::runtime_error "PATH: a PNG is written; give the file name a
/// .png extension" unless `path` ends in .png (any case): what write_png
/// writes, so that a command can check its outputs before its work.
void check_png_name(const std::string& path);

/// Writes an image as PNG, whole (a temporary renamed over the file). Throws
/// std::runtime_error naming the path when it does not end in .png or the
/// write fails.
void write_png(const cv::Mat& image, const std::string& path);

/// Reads an image file (PNG, or any format OpenCV decodes) as 8-bit gray.
/// Throws std::runtime_error "PATH: cannot be read as an image" when it cannot.
cv::Mat read_gray_image(const std::string& path);

}  // namespace pinball::plot
