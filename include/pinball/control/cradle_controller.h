#pragma once
// A ball kept alive by a cycle from the cradle (issue 20's last target). A
// ball at rest in the crook of a raised bat (the cradle) is the one state a
// camera knows exactly, and each cradle forgets how the ball got there. Both
// bats are held up; once the tracker has seen the ball lie still on a raised
// bat for rest_s, that bat drops for drop_s and rises again. Most drops only
// rock the ball, which comes to rest in the crook again; the others shoot it
// up the table, from where it falls back onto a raised bat. `pinball bench
// cradle` finds the drop a table cycles at (the twin: 90 to 94 ms), on the
// true ball; this plays it from the camera (docs/results.md, "A cradle cycle
// in the twin").

#include <array>

#include "pinball/control/flipper_controller.h"
#include "pinball/core/check.h"
#include "pinball/core/name_value.h"
#include "pinball/track/tracker.h"

namespace pinball::control {

/// Settings of the cradle cycle.
struct CradleConfig {
  /// How long the cradling bat is down (s). Commands leave on camera frames,
  /// so the drop lasts this to one frame longer (90 to 95 ms at 200 fps).
  double drop_s = 0.090;
  double rest_s = 0.3;          ///< still this long on a raised bat: cradled (s)
  /// Still: within this of where the ball came to rest (m). Three pixels of
  /// the fast loop's 2 mm camera, whose grid alone moves a resting ball by
  /// one pixel either way: 0.3 s inside it is under 0.02 m/s.
  double still_band_m = 0.006;
  /// A bat up this long is dropped for one update and raised again (s): under
  /// the driver board's hold cap (coils.max_hold_ms, 5 s by default), which
  /// would otherwise drop it at a moment of its own choosing.
  double max_hold_s = 4.0;

  /// The keys of a controller file's `cradle` object (docs/learning.md).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(drop_s));
    a->Visit(PINBALL_NVP(rest_s));
    a->Visit(PINBALL_NVP(still_band_m));
    a->Visit(PINBALL_NVP(max_hold_s));
  }
};

/// A setting outside its range: drop_s in (0, 1] s, rest_s in (0, 10] s,
/// still_band_m in (0, 0.05] m, max_hold_s in (0, kMaxHold_s] and above drop_s + rest_s.
RangeViolation check_cradle_config(const CradleConfig& config);

/// Flipper commands for the cradle cycle, from tracker output.
class CradleController final : public FlipperController {
 public:
  /// Throws std::invalid_argument for a setting out of range (check_cradle_config).
  explicit CradleController(const CradleConfig& config = {});

  void update(const track::TrackerOutput& output, double now_s, std::array<bool, 2>& energized) override;
  void reset(std::array<bool, 2>& energized) override;

  /// Drops begun since construction (each a rock back into the crook or a shot).
  long drops() const { return drops_; }

 private:
  void raise(int bat, double now_s, std::array<bool, 2>& energized);

  CradleConfig config_;
  int dropped_ = -1;                   // the bat that is down for a drop, or -1
  double raise_at_s_ = 0.0;            // when it rises again
  int resting_on_ = -1;                // the raised bat the ball lies still on, or -1
  Vec2 rest_anchor_m_ = Vec2::Zero();  // where it came to rest
  double resting_since_s_ = 0.0;
  std::array<double, 2> raised_at_s_{};  // when each bat went up (the hold cap counts from there)
  long drops_ = 0;
};

}  // namespace pinball::control
