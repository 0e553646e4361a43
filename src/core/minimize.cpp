#include "pinball/core/minimize.h"

#include <algorithm>
#include <cmath>

namespace pinball {

double minimize_on_interval(const std::function<double(double)>& f, double lo, double hi, int grid_steps,
                            int golden_steps) {
  double best = lo, best_value = INFINITY;
  for (int i = 0; i <= grid_steps; ++i) {
    const double x = lo + (hi - lo) * i / grid_steps;
    const double value = f(x);
    if (value < best_value) best_value = value, best = x;
  }
  const double step = (hi - lo) / grid_steps;
  double left = std::max(lo, best - step), right = std::min(hi, best + step);
  const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  double a = right - ratio * (right - left), b = left + ratio * (right - left);
  double value_a = f(a), value_b = f(b);
  for (int i = 0; i < golden_steps; ++i) {
    if (value_a < value_b) {
      right = b, b = a, value_b = value_a;
      a = right - ratio * (right - left), value_a = f(a);
    } else {
      left = a, a = b, value_a = value_b;
      b = left + ratio * (right - left), value_b = f(b);
    }
  }
  const double refined = 0.5 * (left + right);
  return f(refined) <= best_value ? refined : best;
}

}  // namespace pinball
