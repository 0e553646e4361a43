#include "pinball/control/cradle_controller.h"

#include <string>

namespace pinball::control {

RangeViolation check_cradle_config(const CradleConfig& c) {
  if (!(c.drop_s > 0.0 && c.drop_s <= 1.0)) return {"drop_s", "must be in (0, 1] s"};
  if (!(c.rest_s > 0.0 && c.rest_s <= 10.0)) return {"rest_s", "must be in (0, 10] s"};
  if (!(c.still_band_m > 0.0 && c.still_band_m <= 0.05)) return {"still_band_m", "must be in (0, 0.05] m"};
  if (!(c.max_hold_s > 0.0 && c.max_hold_s <= kMaxHold_s)) {
    return {"max_hold_s", "must be in (0, " + std::to_string(firmware::kAbsMaxHoldMs / 1000) +
                              "] s (the driver board's hold cap)"};
  }
  // A bat that must be re-raised before the ball can rest on it and be dropped would never cradle.
  if (!(c.max_hold_s > c.rest_s + c.drop_s)) return {"max_hold_s", "must exceed rest_s + drop_s"};
  return {};
}

CradleController::CradleController(const CradleConfig& config) : config_(config) {
  check_input(check_cradle_config(config_), "cradle controller");
}

void CradleController::reset(std::array<bool, 2>& energized) {
  energized = {false, false};
  dropped_ = -1;
  resting_on_ = -1;
}

void CradleController::raise(int bat, double now_s, std::array<bool, 2>& energized) {
  if (!energized[bat]) raised_at_s_[bat] = now_s;
  energized[bat] = true;
}

void CradleController::update(const track::TrackerOutput& out, double now_s, std::array<bool, 2>& energized) {
  if (out.launch.lost) {  // the ball is gone: nothing to hold
    reset(energized);
    return;
  }
  if (dropped_ >= 0) {  // a drop runs its time, whatever the ball does meanwhile
    if (now_s < raise_at_s_) return;
    raise(dropped_, now_s, energized);
    dropped_ = -1;
  }
  for (int bat = 0; bat < 2; ++bat) {
    if (!energized[bat]) {
      raise(bat, now_s, energized);
    } else if (now_s - raised_at_s_[bat] > config_.max_hold_s) {
      energized[bat] = false;  // down for this update, up at the next: the board's hold cap never cuts in
      if (resting_on_ == bat) resting_on_ = -1;
    }
  }
  // On a bat (its contact switch closed), the tracker's projection is the rolling one, aimed at the other bat.
  const bool on_a_bat = out.projection.valid && out.projection.rolling;
  const int bat = on_a_bat ? 1 - out.projection.flipper : -1;
  if (bat < 0 || !energized[bat]) {
    resting_on_ = -1;
    return;
  }
  if (resting_on_ != bat || (out.ball_m - rest_anchor_m_).norm() > config_.still_band_m) {
    resting_on_ = bat;
    rest_anchor_m_ = out.ball_m;
    resting_since_s_ = now_s;
    return;
  }
  if (now_s - resting_since_s_ < config_.rest_s) return;
  // Cradled: drop that bat.
  energized[bat] = false;
  dropped_ = bat;
  raise_at_s_ = now_s + config_.drop_s;
  resting_on_ = -1;
  ++drops_;
}

}  // namespace pinball::control
