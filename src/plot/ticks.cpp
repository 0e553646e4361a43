#include "pinball/plot/ticks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace pinball::plot {
namespace {

void check_finite(double v, const char* what) {
  if (!std::isfinite(v)) throw std::invalid_argument(std::string(what) + ": needs a finite value");
}

// Mantissas of a round step, in order.
constexpr double kMantissas[] = {1.0, 2.0, 5.0, 10.0};

}  // namespace

double nice_step(double raw) {
  if (!(raw > 0.0) || !std::isfinite(raw)) throw std::invalid_argument("nice_step: needs a finite step > 0");
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : kMantissas) {
    if (m * decade >= raw * (1.0 - 1e-12)) return m * decade;
  }
  return 10.0 * decade;
}

double round_at_most(double x) {
  if (!(x > 0.0) || !std::isfinite(x)) throw std::invalid_argument("round_at_most: needs a finite value > 0");
  const double decade = std::pow(10.0, std::floor(std::log10(x)));
  double best = decade;
  for (const double m : kMantissas) {
    if (m * decade <= x * (1.0 + 1e-12)) best = m * decade;
  }
  return best;
}

std::vector<double> nice_ticks(double lo, double hi, int max_ticks) {
  check_finite(lo, "nice_ticks");
  check_finite(hi, "nice_ticks");
  if (max_ticks < 2) throw std::invalid_argument("nice_ticks: needs max_ticks >= 2");
  if (hi < lo) std::swap(lo, hi);
  if (hi == lo) {
    const double half = lo == 0.0 ? 1.0 : 0.1 * std::abs(lo);
    lo -= half;
    hi += half;
  }
  // Halves first: hi - lo may overflow where each half does not.
  const double span = 2.0 * (0.5 * hi - 0.5 * lo);
  // A span too small to divide (subnormal) takes the smallest normal step.
  const double raw = std::isfinite(span) ? span / (max_ticks - 1) : std::numeric_limits<double>::max();
  double step = nice_step(std::max(raw, std::numeric_limits<double>::min()));
  for (;;) {
    double first = std::floor(lo / step), last = std::ceil(hi / step);
    if (first * step > lo) first -= 1.0;  // k·step rounded past the bound
    if (last * step < hi) last += 1.0;
    if (last - first + 1.0 <= max_ticks) {
      std::vector<double> ticks;
      for (double k = first; k <= last; k += 1.0) {
        const double v = k * step + 0.0;  // + 0.0 turns -0 into 0
        if (std::isfinite(v)) ticks.push_back(v);
      }
      return ticks;
    }
    const double next = nice_step(step * 1.5);
    if (!std::isfinite(next)) return {lo, hi};
    step = next;
  }
}

std::vector<double> decade_ticks(double lo, double hi, int max_ticks) {
  if (!(lo > 0.0) || !(hi > 0.0) || !std::isfinite(lo) || !std::isfinite(hi)) {
    throw std::invalid_argument("decade_ticks: needs finite bounds > 0");
  }
  if (max_ticks < 2) throw std::invalid_argument("decade_ticks: needs max_ticks >= 2");
  if (hi < lo) std::swap(lo, hi);
  const int d0 = static_cast<int>(std::floor(std::log10(lo) + 1e-9));
  int d1 = static_cast<int>(std::ceil(std::log10(hi) - 1e-9));
  if (d1 <= d0) d1 = d0 + 1;
  for (int every = 1;; ++every) {
    // Every k-th decade, on multiples of k, within the doubles' normal range.
    const int first = std::max(-307 / every * every, static_cast<int>(std::floor(double(d0) / every)) * every);
    const int last = std::min(307 / every * every, static_cast<int>(std::ceil(double(d1) / every)) * every);
    if ((last - first) / every + 1 > max_ticks) continue;
    std::vector<double> ticks;
    for (int d = first; d <= last; d += every) ticks.push_back(std::pow(10.0, d));
    return ticks;
  }
}

std::string tick_label(double value, double step) {
  char buf[48];
  if (!std::isfinite(value)) return std::snprintf(buf, sizeof buf, "%g", value), buf;
  step = std::abs(step);
  if (!(step > 0.0) || !std::isfinite(step)) step = std::abs(value) > 0.0 ? std::abs(value) : 1.0;
  if (std::abs(value) < step * 1e-9) value = 0.0;
  const double magnitude = std::max(std::abs(value), step);
  if (step < 1e-4 || magnitude >= 1e6) {
    const int digits =
        std::clamp(static_cast<int>(std::floor(std::log10(magnitude)) - std::floor(std::log10(step))) + 1, 1, 15);
    std::snprintf(buf, sizeof buf, "%.*g", digits, value);
    return buf;
  }
  const int decimals = std::clamp(static_cast<int>(-std::floor(std::log10(step) + 1e-9)), 0, 10);
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  return buf;
}

std::string decade_label(double value) {
  if (value >= 1e-3 * (1 - 1e-9) && value <= 1e3 * (1 + 1e-9)) return tick_label(value, value);
  char buf[32];
  std::snprintf(buf, sizeof buf, "1e%d", static_cast<int>(std::lround(std::log10(value))));
  return buf;
}

}  // namespace pinball::plot
