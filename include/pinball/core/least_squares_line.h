#pragma once
// The project's one straight-line fit: ordinary least squares of y on x, used
// for the precision bench's power laws (on logs), the transfer bench's cost
// of a calibration error (score against the size of the error) and the
// camera latency calibration (the flipper's motion against the frame stamp).

#include <utility>
#include <vector>

namespace pinball {

/// y ≈ intercept + slope·x.
struct LineFit {
  double intercept = 0.0;  ///< y at x = 0
  double slope = 0.0;      ///< dy/dx
};

/// The least-squares line through `xy`; the slope is 0 when every x is the
/// same. Throws std::invalid_argument for fewer than two points.
LineFit fit_line(const std::vector<std::pair<double, double>>& xy);

/// The weight of each point's y in fit_line's slope (slope = Σ wᵢ·yᵢ), so a
/// caller can carry each y's uncertainty into the slope's. Same preconditions.
std::vector<double> slope_weights(const std::vector<std::pair<double, double>>& xy);

}  // namespace pinball
