#pragma once
// A transfer report made by hand, with known numbers, for the report, the
// sensitivities and the figure: every controller scores `base − loss·|v|`
// (± 100 per ball) in each world of the sweep.

#include <cmath>
#include <string>

#include "transfer_bench.h"

namespace pinball::testing {

/// A cell whose balls score mean − 100 and mean + 100, `balls` of them.
inline bench::TransferCell made_cell(const std::string& controller, double mean, int balls) {
  bench::TransferCell c;
  c.controller = controller;
  for (int i = 0; i < balls; ++i) {
    c.score.add(mean + (i % 2 == 0 ? -100.0 : 100.0));
    c.duration_s.add(10.0);
    c.flips.add(3.0);
  }
  c.drains.add(bench::DrainCause::kLeftOutlane, false);
  c.outlane_after_flipper_s.add(2.5);  // the outlane drain, 2.5 s after the last flipper touch
  c.drains.add(bench::DrainCause::kCentre, false);
  c.cut = balls - 2;
  c.wall_s = 0.01 * balls;
  return c;
}

/// spastic (1000 − 10·|v|) and "learned" (2000 − 50·|v|) over model, event, a
/// skipped twin, pivots ±1 and ±3 mm and g +5 %, 4 balls per cell.
inline bench::TransferReport made_report() {
  bench::TransferReport r;
  r.board = "boards/mit1993.board";
  r.options.balls = 4;
  r.options.sweep = {{bench::Perturbation::kPivotY_mm, {-3, -1, 1, 3}}, {bench::Perturbation::kGravity_pct, {5}}};
  static const control::ControllerSpec spec;
  r.options.controllers = {{"learned", "controllers/learned.json", &spec}};
  const auto world = [&](const std::string& name, const std::string& family, double v) {
    bench::TransferWorld w;
    w.name = name;
    w.family = family;
    w.value = v;
    w.world = name == "event" ? "event" : "thesis";
    w.played = true;
    w.cells = {made_cell("spastic", 1000.0 - 10.0 * std::fabs(v), 4), made_cell("learned", 2000.0 - 50.0 * std::fabs(v), 4)};
    bench::set_ratios_to_spastic(w.cells);
    return w;
  };
  r.worlds.push_back(world("model", "nominal", 0.0));
  r.worlds.push_back(world("event", "nominal", 0.0));
  bench::TransferWorld twin;
  twin.name = "twin";
  twin.family = "nominal";
  twin.world = "twin";
  twin.skipped_reason = "this build has no MuJoCo twin, so no \"twin\" row is played";
  r.worlds.push_back(twin);
  for (const double v : {-3.0, -1.0, 1.0, 3.0}) {
    r.worlds.push_back(world(std::string("pivot_y_mm=") + (v > 0 ? "+" : "") + std::to_string(static_cast<int>(v)),
                             "pivot_y_mm", v));
  }
  r.worlds.push_back(world("gravity_pct=+5", "gravity_pct", 5.0));
  r.sensitivities = bench::transfer_sensitivities(r.worlds, r.options);
  r.summaries = bench::transfer_summaries(r.worlds, r.options.target_ratio);
  r.wall_s = 1.5;
  return r;
}

}  // namespace pinball::testing
