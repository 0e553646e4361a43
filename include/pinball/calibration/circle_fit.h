#pragma once
// Fits a circle to points on an arc (a flipper tip's path): Taubin's
// algebraic fit for a start, then geometric least squares (Gauss-Newton on
// the distances to the circle) with outliers trimmed by a median/MAD rule.
// The algebraic fit alone is biased on a short, noisy arc; the geometric
// refinement is not (to first order).

#include <span>

#include "pinball/core/geometry.h"

namespace pinball::calibration {

/// A fitted circle.
struct CircleFit {
  Vec2 centre = Vec2::Zero();  ///< centre (input units)
  double radius = 0.0;         ///< radius
  double rms = 0.0;            ///< RMS geometric residual over the points kept
  int points = 0;              ///< points kept
  int rejected = 0;            ///< points trimmed as outliers
  int iterations = 0;          ///< Gauss-Newton iterations, all rounds
};

/// Settings of the geometric refinement.
struct CircleFitOptions {
  int max_iterations = 50;       ///< Gauss-Newton iterations per round
  int trim_rounds = 3;           ///< rounds of outlier trimming (0: none)
  double trim_mad = 4.0;         ///< a point farther than this many robust sigmas (1.4826·MAD) is trimmed
};

/// Taubin's algebraic fit (Chernov's Newton form). Throws
/// std::invalid_argument for fewer than 3 points or (nearly) collinear ones.
CircleFit fit_circle_algebraic(std::span<const Vec2> points);

/// Taubin, then geometric Gauss-Newton with trimming. Throws like
/// fit_circle_algebraic, or when the refinement diverges.
CircleFit fit_circle(std::span<const Vec2> points, const CircleFitOptions& options = {});

}  // namespace pinball::calibration
