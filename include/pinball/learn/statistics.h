#pragma once
// Statistics of the searches (thesis App. A, B): the Hoeffding confidence
// interval with the thesis's range bound B = mean + 2σ, and the thesis's own
// incremental variance recurrence (A.11–A.16), kept only to show why we use
// Welford's update (pinball::RunningStats) instead.

#include <cstdint>

#include "pinball/core/running_stats.h"
#include "pinball/core/statistics.h"

namespace pinball::learn {

/// Half-width t of the two-sided Hoeffding interval (eq. B.8):
/// t = sqrt(B² / (2n) · ln(2 / (1 − c))). Infinite for n < 1 or B not finite;
/// 0 for B = 0. `confidence` c in (0, 1).
double hoeffding_half_width(std::int64_t n, double range_b, double confidence);

/// The thesis's range bound (App. B): B = mean + 2σ, taken as |mean| + 2σ so
/// that a mean made negative by the loss penalty still gives a positive range.
double thesis_range_bound(const RunningStats& stats);

using pinball::Interval;  // core/statistics.h

/// The Hoeffding interval of the relay race: mean ± t with B from
/// thesis_range_bound; infinite (±inf) with fewer than 2 samples.
Interval hoeffding_interval(const RunningStats& stats, double confidence = 0.90);

/// The thesis's recurrence for the mean and (n − 1)-variance (App. A,
/// A.5, A.11, A.16), as printed. Numerically fragile: α_n is a mean of
/// squares, so for large values the variance is a difference of huge numbers.
class ThesisIncrementalStats {
 public:
  /// Adds one sample.
  void add(double x);
  /// Samples so far.
  std::int64_t count() const { return n_; }
  /// m_n (A.5).
  double mean() const { return m_; }
  /// σ_n² (A.16); 0 for n < 2.
  double variance() const { return var_; }

 private:
  std::int64_t n_ = 0;
  double m_ = 0.0;
  double alpha_ = 0.0;
  double x1_ = 0.0;
  double var_ = 0.0;
};

}  // namespace pinball::learn
