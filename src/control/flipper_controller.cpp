#include "pinball/control/flipper_controller.h"

#include <string>

namespace pinball::control {

track::TrajectoryProjection projection_to_act_on(const track::TrackerOutput& output,
                                                 const std::optional<double>& lead_actuation_delay_s) {
  if (!lead_actuation_delay_s) return output.projection;
  return track::lead_projection(output.projection, output.fit, output.projection.latency_s + *lead_actuation_delay_s);
}

RangeViolation check_lead_actuation_delay(const std::optional<double>& lead_actuation_delay_s, const char* key) {
  if (!lead_actuation_delay_s || (*lead_actuation_delay_s >= 0.0 && *lead_actuation_delay_s <= kMaxLeadActuationDelay_s))
    return {};
  return {key, "must be in [0, 0.1] s"};
}

}  // namespace pinball::control
