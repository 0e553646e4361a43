#pragma once
// Fits a circle to points on an arc (a flipper tip's path): Taubin's
// algebraic fit for a start, then geometric least squares (Gauss-Newton on
// the distances to the circle) with outliers trimmed by a median/MAD rule.
// The algebraic fit alone is biased on a short, noisy arc; the geometric
// refinement is not (to first order).
// Also the point nearest to a set of lines in the least-squares sense (where
// the centre lines of a turning flipper blade meet: its pivot), trimmed the
// same way.

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

/// A line through `point` along the unit vector `direction`.
struct Line2 {
  Vec2 point = Vec2::Zero();          ///< a point on the line
  Vec2 direction = Vec2::UnitX();     ///< unit direction
};

/// Where lines meet.
struct LinesMeet {
  Vec2 point = Vec2::Zero();  ///< the point nearest to the lines kept (least squares)
  double rms = 0.0;           ///< RMS distance of the lines kept to the point
  int lines = 0;              ///< lines kept
  int rejected = 0;           ///< lines trimmed as outliers
};

/// The point nearest to `lines` (sum of squared perpendicular distances),
/// then trimmed like fit_circle (options.trim_rounds, options.trim_mad) and
/// solved again. Throws std::invalid_argument for fewer than 2 lines or
/// (nearly) parallel ones.
LinesMeet meet_lines(std::span<const Line2> lines, const CircleFitOptions& options = {});

}  // namespace pinball::calibration
