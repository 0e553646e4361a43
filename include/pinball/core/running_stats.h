#pragma once
// Incremental mean and variance (Welford's update, thesis App. A done stably).

#include <cstdint>
#include <optional>

namespace pinball {

/// Running sample statistics in O(1) memory.
class RunningStats {
 public:
  /// Adds one sample.
  void add(double x);
  /// Adds every sample of `other` (Chan et al.'s pairwise combination of
  /// Welford states): the result equals adding the samples one by one, up to rounding.
  void merge(const RunningStats& other);

  /// Number of samples added.
  std::int64_t count() const { return n_; }
  /// Sample mean (0 with no samples).
  double mean() const { return mean_; }
  /// Unbiased sample variance (0 with fewer than two samples).
  double variance() const { return n_ > 1 ? m2_ / static_cast<double>(n_ - 1) : 0.0; }
  /// Sample standard deviation.
  double stddev() const;
  /// Half-width of the 95 % confidence interval of the mean (Student's t with n − 1 degrees of freedom);
  /// infinite with fewer than two samples (JSON writes it as null).
  double ci95_half_width() const;
  /// Smallest and largest sample (0 with no samples).
  double min() const { return min_; }
  double max() const { return max_; }

 private:
  std::int64_t n_ = 0;
  double mean_ = 0.0;
  double m2_ = 0.0;
  double min_ = 0.0;
  double max_ = 0.0;
};

/// A ratio of two means and its 95 % interval.
struct RatioInterval {
  double ratio = 0.0;  ///< mean of the numerator / mean of the denominator
  double low = 0.0;    ///< lower end of the 95 % interval
  double high = 0.0;   ///< upper end
};

/// The ratio of the means of two independent samples (a controller's scores
/// over the spastic flipper's, each from its own games) with a 95 % interval
/// from the delta method on log(ratio): var ≈ var(a)/(n_a·ā²) + var(b)/(n_b·b̄²),
/// Student's t with Welch–Satterthwaite's degrees of freedom. The interval is
/// R·exp(±t·σ), so it stays positive and is as wide each way in log terms,
/// as a ratio's noise is. None unless both have two or more samples and
/// positive means (no log, no interval).
std::optional<RatioInterval> ratio_of_means_ci95(const RunningStats& numerator, const RunningStats& denominator);

}  // namespace pinball
