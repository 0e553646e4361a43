#include "drain_cause.h"

#include <algorithm>

namespace pinball::bench {

std::string_view drain_cause_name(DrainCause cause) {
  switch (cause) {
    case DrainCause::kLeftOutlane: return "left_outlane";
    case DrainCause::kRightOutlane: return "right_outlane";
    case DrainCause::kCentre: return "centre";
    case DrainCause::kOther: return "other";
  }
  return "other";
}

DrainZones drain_zones(const table::Board& board) {
  DrainZones z;
  if (board.flippers.size() < 2) return z;
  z.centre_min_x_m = std::numeric_limits<double>::infinity();
  z.centre_max_x_m = -std::numeric_limits<double>::infinity();
  for (const table::Flipper& f : board.flippers) {
    z.line_y_m = std::max(z.line_y_m, f.pivot.y());
    z.centre_min_x_m = std::min(z.centre_min_x_m, f.pivot.x());
    z.centre_max_x_m = std::max(z.centre_max_x_m, f.pivot.x());
  }
  return z;
}

DrainCause classify_drain(const DrainZones& zones, double crossing_x_m) {
  if (std::isnan(crossing_x_m) || zones.centre_min_x_m > zones.centre_max_x_m) return DrainCause::kOther;
  if (crossing_x_m < zones.centre_min_x_m) return DrainCause::kLeftOutlane;
  if (crossing_x_m > zones.centre_max_x_m) return DrainCause::kRightOutlane;
  return DrainCause::kCentre;
}

void DrainCounts::add(DrainCause cause, bool left_table_bounds) {
  switch (cause) {
    case DrainCause::kLeftOutlane: ++left_outlane; break;
    case DrainCause::kRightOutlane: ++right_outlane; break;
    case DrainCause::kCentre: ++centre; break;
    case DrainCause::kOther: ++other; break;
  }
  if (left_table_bounds) ++left_table;
}

}  // namespace pinball::bench
