#pragma once
// Writes a figure or picture to a PNG file. Apart from draw.h because OpenCV's
// imgcodecs loads about 120 shared libraries (codecs, GDAL) that only the
// programs writing files need, not every library that draws.

#include <string>

#include <opencv2/core.hpp>

namespace pinball::plot {

/// Writes an image as PNG. Throws std::runtime_error naming the path on failure.
void write_png(const cv::Mat& image, const std::string& path);

}  // namespace pinball::plot
