#pragma once
// A toy objective with a known optimum for the search tests: each partition's
// minicontroller earns, per flip opportunity, 100 − 100·‖a/range − target‖²
// (+ a bonus when its flipper is the target flipper) plus noise; the ball's
// score is the sum over a fixed number of opportunities per partition.

#include <cmath>

#include "pinball/learn/evaluator.h"

namespace pinball::learn::testing_support {

class ToyObjective final : public BallObjective {
 public:
  explicit ToyObjective(int k = 2, double noise = 5.0) : k_(k), noise_(noise) {}

  static double target(int partition, int i) { return 0.6 * std::sin(1.0 + partition + 2.0 * i); }
  static int target_flipper(int partition) { return partition % 2; }

  double value(const control::Minicontroller& m, int p, const control::ActionFunction& af) const {
    double d2 = 0.0;
    for (int i = 0; i < 4; ++i) {
      const double x = m.a[static_cast<std::size_t>(i)] / af.config().gain_range[static_cast<std::size_t>(i)];
      d2 += (x - target(p, i)) * (x - target(p, i));
    }
    return 100.0 - 100.0 * d2 + (m.flipper == target_flipper(p) ? 20.0 : 0.0);
  }
  /// The expected score per ball of a controller.
  double expected(const control::ControllerSpec& s) const {
    double sum = 0.0;
    for (int p = 0; p < s.action_function.partitions(); ++p) sum += 2.0 * value(s.action_function.minicontroller(p), p, s.action_function);
    return sum;
  }
  /// The best score per ball.
  double optimum() const { return 2.0 * 120.0 * 2 * k_; }

  BallOutcome play(const control::ControllerSpec& s, std::uint64_t seed) const override {
    Rng rng(seed);
    BallOutcome o;
    for (int p = 0; p < s.action_function.partitions(); ++p) {
      for (int r = 0; r < 2; ++r) {
        const double v = value(s.action_function.minicontroller(p), p, s.action_function) + noise_ * rng.normal();
        o.opportunities.push_back({p, v});
        o.score += v;
      }
    }
    o.flips = 2 * s.action_function.partitions();
    return o;
  }
  control::ControllerSpec prototype() const override {
    control::ControllerSpec s;
    s.action_function = control::ActionFunction(control::uniform_partition(k_));
    return s;
  }

 private:
  int k_;
  double noise_;
};

}  // namespace pinball::learn::testing_support
