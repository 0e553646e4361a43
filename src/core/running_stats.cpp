#include "pinball/core/running_stats.h"

#include "pinball/core/statistics.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pinball {

void RunningStats::add(double x) {
  ++n_;
  if (n_ == 1) {
    min_ = max_ = x;
  } else {
    min_ = std::min(min_, x);
    max_ = std::max(max_, x);
  }
  const double delta = x - mean_;
  mean_ += delta / static_cast<double>(n_);
  m2_ += delta * (x - mean_);
}

void RunningStats::merge(const RunningStats& o) {
  if (o.n_ == 0) return;
  if (n_ == 0) {
    *this = o;
    return;
  }
  const double na = static_cast<double>(n_);
  const double nb = static_cast<double>(o.n_);
  const double n = na + nb;
  const double delta = o.mean_ - mean_;
  mean_ += delta * (nb / n);
  m2_ += o.m2_ + delta * delta * (na * nb / n);
  n_ += o.n_;
  min_ = std::min(min_, o.min_);
  max_ = std::max(max_, o.max_);
}

double RunningStats::stddev() const { return std::sqrt(variance()); }

double RunningStats::ci95_half_width() const {
  // One sample says nothing of the spread: its interval is unbounded, not zero.
  if (n_ < 2) return std::numeric_limits<double>::infinity();
  return student_t95(n_ - 1) * stddev() / std::sqrt(static_cast<double>(n_));
}

std::optional<RatioInterval> ratio_of_means_ci95(const RunningStats& a, const RunningStats& b) {
  if (a.count() < 2 || b.count() < 2 || !(a.mean() > 0.0) || !(b.mean() > 0.0)) return std::nullopt;
  // Squared relative standard errors of each mean: the variances of log(ā) and log(b̄) to first order.
  const auto relative_variance = [](const RunningStats& s) {
    return s.variance() / (static_cast<double>(s.count()) * s.mean() * s.mean());
  };
  const double ua = relative_variance(a);
  const double ub = relative_variance(b);
  const double u = ua + ub;
  RatioInterval out;
  out.ratio = a.mean() / b.mean();
  if (u == 0.0) {
    out.low = out.high = out.ratio;
    return out;
  }
  const double dof = u * u / (ua * ua / static_cast<double>(a.count() - 1) + ub * ub / static_cast<double>(b.count() - 1));
  const double half_width_log = student_t95(static_cast<std::int64_t>(std::floor(dof))) * std::sqrt(u);
  out.low = out.ratio * std::exp(-half_width_log);
  out.high = out.ratio * std::exp(half_width_log);
  return out;
}

}  // namespace pinball
