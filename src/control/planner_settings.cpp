#include "pinball/control/planner_settings.h"

#include <cmath>

namespace pinball::control {

RangeViolation check_planner_settings(const PlannerSettings& s) {
  if (!(s.fire_frames >= 0 && s.fire_frames <= 40)) return {"fire_frames", "must be in [0, 40] frames"};
  if (!(s.short_hold_s >= 0.005 && s.short_hold_s <= 1.0)) return {"short_hold_s", "must be in [0.005, 1] s"};
  if (!(s.long_hold_s >= 0.005 && s.long_hold_s <= 1.0)) return {"long_hold_s", "must be in [0.005, 1] s"};
  if (!(s.zone_factor > 0.0 && s.zone_factor <= 50.0)) return {"zone_factor", "must be in (0, 50] ball radii"};
  if (!(s.horizon_s > 0.0 && s.horizon_s <= 10.0)) return {"horizon_s", "must be in (0, 10] s"};
  if (!(std::isfinite(s.drain_penalty) && s.drain_penalty >= 0.0)) return {"drain_penalty", "must be finite and >= 0"};
  if (!(s.actuation_delay_s >= 0.0 && s.actuation_delay_s <= 0.1)) return {"actuation_delay_s", "must be in [0, 0.1] s"};
  if (!(s.step_budget >= 1000 && s.step_budget <= 10'000'000)) return {"step_budget", "must be in [1000, 10^7] steps"};
  return {};
}

}  // namespace pinball::control
