#pragma once
// The learning curve of a search: a CSV (one row per generation) and a PNG
// plot of the best-so-far and generation means against balls played.

#include <string>
#include <vector>

#include "pinball/learn/search.h"

namespace pinball::learn {

/// Writes the curve as CSV (header method,generation,balls,population_mean,
/// generation_best,best_so_far,wall_s). Throws std::runtime_error when it cannot write.
void write_curve_csv(const SearchResult& result, const std::string& path);

/// Draws the curve (mean score per ball against balls played) to a PNG.
/// Throws std::runtime_error when it cannot write.
void plot_curve_png(const SearchResult& result, const std::string& path);

}  // namespace pinball::learn
