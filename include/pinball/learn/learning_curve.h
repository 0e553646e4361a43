#pragma once
// The learning curve of a search: a CSV (one row per generation) and a
// figure of the best-so-far and generation means against balls played.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pinball/learn/search.h"

namespace pinball::learn {

/// Writes the curve as CSV (header method,generation,balls,population_mean,
/// generation_best,best_so_far,wall_s). Throws std::runtime_error when it cannot write.
void write_curve_csv(const SearchResult& result, const std::string& path);

/// Draws the curve (mean score per ball against balls played) as a figure
/// (BGR); `pinball learn --plot` writes it with plot::write_png.
cv::Mat draw_curve(const SearchResult& result);

}  // namespace pinball::learn
