#pragma once
// One-dimensional minimisation on an interval, for fits whose objective is
// cheap enough to sample but not smooth everywhere (a replayed flipper shot,
// a capped friction loss): a grid first, so a kink or a second dip cannot
// trap it, then golden sections around the grid's best point.

#include <functional>

namespace pinball {

/// The x in [lo, hi] where f is least: f at grid_steps + 1 evenly spaced
/// points, then golden_steps golden sections between the best point's two
/// neighbours; the sections' midpoint when f there is no worse than at the
/// grid's best point, otherwise that point. Needs lo < hi, grid_steps >= 1.
double minimize_on_interval(const std::function<double(double)>& f, double lo, double hi, int grid_steps,
                            int golden_steps);

}  // namespace pinball
