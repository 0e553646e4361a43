#pragma once
// Shared pieces of the stiff and extreme suite (label `numerics`): every case
// runs on both steppers as a typed test, and checks after every step that the
// state is finite, the ball overlaps nothing, its energy has not grown without
// a kicker or flipper to supply it, and the event stepper's event count stays
// bounded. Measured figures are printed as "[numerics] ..." lines; the table
// in docs/physics.md quotes them.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <string>

#include "pinball/table/board.h"
#include "pinball/sim/event_stepper.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/thesis_stepper.h"
#include "sim/invariants.h"
#include "sim/test_boards.h"

namespace pinball::sim::testing {

/// Ball radius of empty_board() (m).
constexpr double kBallR = 0.0135;

/// How to build and judge each stepper.
template <class Stepper>
struct StepperTraits;

template <>
struct StepperTraits<ThesisStepper> {
  static constexpr const char* kName = "thesis";
  /// Fixed steps: hits and misses near a tangent depend on its own O(dt) path error.
  static constexpr bool kExact = false;
  /// It stops 1 µm (its separation) short of every contact.
  static constexpr double kMaxDepth_m = 1e-6;
  static ThesisStepper make(const table::Board& b, double dt_s) {
    ThesisStepperOptions o;
    o.dt_s = dt_s;
    return ThesisStepper(b, o);
  }
  /// Semi-implicit Euler does not conserve ½v² + g·y: it conserves a shadow
  /// energy ½v² + g·y + ½g·dt·v_y, so the energy read at a step end is off by
  /// up to ½g·|v|·dt. A contact flips v_y and with it that offset, and the
  /// part of the step flown before it counts at the old v_y: every contact may
  /// leave the energy up to 2·g·|v|·dt higher (measured: 0.0055 J/kg against
  /// g·|v|·dt = 0.0028 in a ρ = 1 box; a random walk, bounded linearly by the
  /// number of contacts): Euler's known drift, not a source.
  static double energy_slack(double g, double speed_mps, double dt_s, double e0, long contacts) {
    return g * (speed_mps + g * dt_s) * dt_s * (2.0 + 2.0 * static_cast<double>(contacts)) +
           1e-12 * (1.0 + std::abs(e0));
  }
};

template <>
struct StepperTraits<EventStepper> {
  static constexpr const char* kName = "event";
  static constexpr bool kExact = true;
  /// Roots are found to 1e-12 of the board's size; 1 nm leaves a thousandfold margin.
  static constexpr double kMaxDepth_m = 1e-9;
  static EventStepper make(const table::Board& b, double dt_s) {
    EventStepperOptions o;
    o.dt_s = dt_s;
    return EventStepper(b, o);
  }
  /// Exact parabolas and reflections with ρ ≤ 1: only rounding and the root
  /// tolerance (a position error of ~1e-12 m, worth g·1e-12) may show.
  static double energy_slack(double g, double, double, double e0, long) {
    return 1e-9 * (1.0 + std::abs(e0)) + g * 1e-9;
  }
};

/// The steppers every case runs on.
using Steppers = ::testing::Types<ThesisStepper, EventStepper>;

/// Names the typed tests by stepper.
struct StepperNames {
  template <class T>
  static std::string GetName(int) {
    return StepperTraits<T>::kName;
  }
};

/// Mechanical energy per unit mass: ½|v|² + g·y.
inline double energy(const table::Board& b, const GameState& s) {
  return 0.5 * s.ball.velocity_mps.squaredNorm() + b.gravity_mps2 * s.ball.position_m.y();
}

/// Prints one measured figure for docs/physics.md.
inline void note(const char* fmt, ...) {
  std::va_list args;
  va_start(args, fmt);
  std::printf("[numerics] ");
  std::vprintf(fmt, args);
  std::printf("\n");
  va_end(args);
}

/// The per-step checks of one run. Construct it before the first step.
template <class Stepper>
class Checker {
 public:
  using Traits = StepperTraits<Stepper>;

  /// energy_supplied: a kicker or a moving flipper may add energy, so its
  /// growth is not checked; max_events: the event count may not pass it (0: no bound).
  Checker(const Stepper& stepper, const GameState& s, bool energy_supplied = false, std::uint64_t max_events = 0)
      : stepper_(stepper),
        e0_(energy(stepper.board(), s)),
        events0_(s.events),
        last_v_(s.ball.velocity_mps),
        energy_supplied_(energy_supplied),
        max_events_(max_events) {}

  /// Checks the state after step `step`; records a failure and returns false on the first violation.
  bool operator()(const GameState& s, long step) {
    const table::Board& b = stepper_.board();
    if (!invariants_hold(b, s, step, Traits::kMaxDepth_m)) return false;
    max_speed_ = std::max(max_speed_, s.ball.velocity_mps.norm());
    // A velocity change beyond what gravity does in one step is a contact.
    const double dv = (s.ball.velocity_mps - last_v_).norm();
    if (dv > 2.0 * b.gravity_mps2 * stepper_.dt_s() + 1e-12) ++contacts_;
    last_v_ = s.ball.velocity_mps;
    if (s.ball_in_play) {
      const double gain = energy(b, s) - e0_;
      max_gain_ = std::max(max_gain_, gain);
      const double slack = Traits::energy_slack(b.gravity_mps2, max_speed_, stepper_.dt_s(), e0_, contacts_);
      if (!energy_supplied_ && gain > slack) {
        ADD_FAILURE() << Traits::kName << ": energy grew by " << gain << " J/kg (slack " << slack << ") at step "
                      << step;
        return false;
      }
    }
    if (max_events_ > 0 && s.events - events0_ > max_events_) {
      ADD_FAILURE() << Traits::kName << ": " << s.events - events0_ << " events by step " << step << " (bound "
                    << max_events_ << ")";
      return false;
    }
    return true;
  }

  /// Largest energy gain seen so far (J/kg; negative when it only fell).
  double max_energy_gain() const { return max_gain_; }

 private:
  const Stepper& stepper_;
  double e0_;
  std::uint64_t events0_;
  Vec2 last_v_;
  bool energy_supplied_;
  std::uint64_t max_events_;
  double max_gain_ = -INFINITY;
  double max_speed_ = 0.0;
  long contacts_ = 0;
};

/// Steps n times under a Checker; `policy(state, i)` runs before each step and
/// `observe(state, i)` after the checks (it may ASSERT). Returns false after the first failure.
template <class Stepper, class Policy, class Observe>
bool run_checked(const Stepper& stepper, GameState& s, long n, Checker<Stepper>& check, Policy&& policy,
                 Observe&& observe) {
  for (long i = 0; i < n; ++i) {
    policy(s, i);
    stepper.step(s);
    if (!check(s, i)) return false;
    observe(static_cast<const GameState&>(s), i);
    if (::testing::Test::HasFatalFailure()) return false;  // an ASSERT inside observe
  }
  return true;
}

/// The same without a policy or an observer.
template <class Stepper>
bool run_checked(const Stepper& stepper, GameState& s, long n, Checker<Stepper>& check) {
  return run_checked(stepper, s, n, check, [](GameState&, long) {}, [](const GameState&, long) {});
}

}  // namespace pinball::sim::testing
