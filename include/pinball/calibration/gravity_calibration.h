#pragma once
// Gravity along the table (thesis 4.1.1): a ball let go from rest rolls down
// the table with constant acceleration; its y(t) is a parabola. Each roll is
// trimmed to that parabola (the frames before it moved and those after it hit
// something are dropped), fitted by least squares, and the rolls are pooled:
// outlier rolls (median/MAD) left out, the mean of the rest reported with a
// Student-t confidence interval over rolls. A rolling ball measures about
// 5/7·g·sin(slope), which is what the tracker needs (docs/calibration.md).

#include <span>
#include <string>
#include <vector>

#include "pinball/calibration/calibration_file.h"
#include "pinball/track/observation.h"

namespace pinball::calibration {

/// One recording of a ball let go from rest: observations in time order
/// (from the detector's CSV, an LCM log, or the simulator).
struct GravityRoll {
  std::string source;                          ///< where it came from, for messages
  std::vector<track::Observation> observations;///< t (s), p_board (m)
};

/// Fit settings.
struct GravityOptions {
  double sigma_m = 0.001;        ///< standard deviation of one observed coordinate (m)
  double start_motion_m = 0.004; ///< the roll starts once the ball is this far from where it rested (m)
  double cut_sigmas = 6.0;       ///< a point this many σ off the parabola so far ends the roll (a collision)
  int min_points = 15;           ///< a roll needs at least this many points on its parabola
  double min_duration_s = 0.15;  ///< ... spanning at least this long (s)
  double outlier_mads = 3.5;     ///< a roll this many robust σ (1.4826·MAD) from the median is an outlier
  double confidence = 0.95;      ///< interval confidence: 0.90, 0.95 or 0.99
};

/// One roll's fit.
struct RollFit {
  std::string source;            ///< the roll's source
  bool usable = false;           ///< enough of a parabola to fit
  std::string why;               ///< why not, when not usable
  bool outlier = false;          ///< usable but left out of the estimate
  double accel_mps2 = 0.0;       ///< acceleration down the table (−y), m/s²
  double accel_stderr_mps2 = 0.0;///< its standard error from the residuals
  double lateral_mps2 = 0.0;     ///< acceleration along x (a table tilted sideways), m/s²
  double rms_m = 0.0;            ///< RMS residual of the y fit (m)
  std::size_t first = 0;         ///< index of the first observation used
  std::size_t last = 0;          ///< index of the last observation used
  double t0_s = 0.0;             ///< time the fit is centred on (s); y(t) = c0 + c1·(t − t0) + c2·(t − t0)²
  double c0 = 0.0, c1 = 0.0, c2 = 0.0;  ///< the y polynomial (m, m/s, m/s²)
};

/// Everything the gravity calibration found.
struct GravityCalibration {
  GravityEstimate estimate;      ///< the figure, its interval and the rolls behind it
  std::vector<RollFit> rolls;    ///< every roll, in input order
};

/// Fits one roll (never throws for bad data: `usable` false and `why` instead).
RollFit fit_roll(const GravityRoll& roll, const GravityOptions& options = {});

/// Fits every roll and pools them. Throws std::runtime_error when no roll is
/// usable or the options are out of range.
GravityCalibration calibrate_gravity(std::span<const GravityRoll> rolls, const GravityOptions& options = {});

/// Two-sided Student-t quantile for `confidence` (0.90, 0.95 or 0.99) with
/// `dof` >= 1 degrees of freedom (table to 30, then the Cornish-Fisher
/// expansion). Throws std::invalid_argument for other confidences.
double student_t_quantile(double confidence, int dof);

}  // namespace pinball::calibration
