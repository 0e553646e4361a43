#pragma once
// The project's one straight-line fit: ordinary least squares of y on x, used
// for the precision bench's power laws (on logs), the transfer bench's cost
// of a calibration error (score against the size of the error) and the
// camera latency calibration (the flipper's motion against the frame stamp),
// and, with standard errors and one robust trim, identification's rebound
// ratios and flipper strokes (learn/identification.h).

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

/// A line fitted with the standard error of each coefficient (from the
/// residuals), after one pass that leaves out points beyond `trim_sigmas`
/// robust σ (1.4826 × the median absolute residual) of the first fit.
struct TrimmedLineFit {
  LineFit line;                   ///< the fit on the points kept
  double intercept_stderr = 0.0;  ///< 0 when the line goes through the origin
  double slope_stderr = 0.0;
  int used = 0;                   ///< points kept
  int outliers = 0;               ///< points left out
};

/// y ≈ intercept + slope·x (or slope·x alone with `through_origin`), trimmed
/// once. The trim is skipped when it would leave too few points to fit.
/// Throws std::invalid_argument for fewer than two points (three with an
/// intercept) or when every x is the same (0 with `through_origin`).
TrimmedLineFit fit_line_trimmed(const std::vector<std::pair<double, double>>& xy, bool through_origin,
                                double trim_sigmas = 3.5);

/// Root mean square of y − (intercept + slope·x) over `xy` (0 for none).
double rms_residual(const std::vector<std::pair<double, double>>& xy, const LineFit& line);

}  // namespace pinball
