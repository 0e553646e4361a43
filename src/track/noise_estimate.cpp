#include "pinball/track/noise_estimate.h"

#include <algorithm>
#include <cmath>

namespace pinball::track {

namespace {

// The estimate is refreshed every this many residuals (32 frames): a partial
// sort of 1024 takes some microseconds, too much for every frame.
constexpr std::size_t kRefreshEvery = 64;
// σ from the smaller half of the |r|: their root mean square is 0.377693 σ for
// a normal (the variance of N(0, 1) cut at its quartiles, ±0.674490, is
// 0.142652). Not the median alone: on a pixel grid the residuals take a few
// discrete values, and the median jumps between them (0.82 mm steps at 2 mm
// per pixel); a mean over half of them moves smoothly.
constexpr double kHalfRmsOverSigma = 0.377693;

}  // namespace

void ObservationNoiseEstimator::add(const Observation& o) {
  if (frames_ > 0 && !(o.t_s > last_[1].t_s)) return;
  if (frames_ > 0 && o.t_s - last_[1].t_s > kMaxGap_s) frames_ = 0;  // a gap: start a new triple
  if (frames_ == 2) {
    const double dt1 = last_[1].t_s - last_[0].t_s;
    const double dt2 = o.t_s - last_[1].t_s;
    const double w0 = 1.0 / dt1, w2 = 1.0 / dt2, w1 = -(w0 + w2);
    const double norm = std::sqrt(w0 * w0 + w1 * w1 + w2 * w2);
    const Vec2 r = (w0 * last_[0].p_board + w1 * last_[1].p_board + w2 * o.p_board) / norm;
    push(std::abs(r.x()));
    push(std::abs(r.y()));
  }
  last_[0] = last_[1];
  last_[1] = o;
  frames_ = frames_ < 2 ? frames_ + 1 : 2;
}

void ObservationNoiseEstimator::push(double residual) {
  residuals_[next_] = residual;
  next_ = (next_ + 1) % kResiduals;
  if (count_ < kResiduals) ++count_;
  if (count_ < kMinResiduals) return;
  if (estimated_ && ++since_estimate_ < kRefreshEvery) return;
  since_estimate_ = 0;
  estimated_ = true;
  std::copy_n(residuals_.begin(), count_, scratch_.begin());
  const std::size_t half = count_ / 2;
  const auto first = scratch_.begin();
  std::nth_element(first, first + static_cast<std::ptrdiff_t>(half), first + static_cast<std::ptrdiff_t>(count_));
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < half; ++i) sum_sq += scratch_[i] * scratch_[i];
  sigma_m_ = std::sqrt(sum_sq / static_cast<double>(half)) / kHalfRmsOverSigma;
}

std::optional<double> ObservationNoiseEstimator::sigma_m() const {
  if (!estimated_) return std::nullopt;
  return sigma_m_;
}

}  // namespace pinball::track
