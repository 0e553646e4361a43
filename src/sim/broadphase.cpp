#include "pinball/sim/broadphase.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pinball::sim {
namespace {

// Grids larger than this fall back to bigger cells: memory stays bounded for
// huge or sparse boards at the price of longer candidate lists.
constexpr double kMaxCells = 4.0e6;

void shape_bounds(const table::Shape& s, Vec2& lo, Vec2& hi) {
  if (s.kind == table::ShapeKind::kLine) {
    lo = s.p0.cwiseMin(s.p1);
    hi = s.p0.cwiseMax(s.p1);
  } else {
    lo = s.p0.array() - s.radius_m;
    hi = s.p0.array() + s.radius_m;
  }
}

double distance_shape_box(const table::Shape& s, const Vec2& lo, const Vec2& hi) {
  if (s.kind == table::ShapeKind::kLine) return distance_segment_box(s.p0, s.p1, lo, hi);
  return std::max(0.0, distance_point_box(s.p0, lo, hi) - s.radius_m);
}

}  // namespace

UniformGrid::UniformGrid(std::span<const table::Shape> shapes, double reach_m, double cell_m) {
  if (!(reach_m >= 0.0) || !(cell_m > 0.0)) throw std::invalid_argument("UniformGrid: reach must be >= 0, cell > 0");
  if (shapes.empty()) {
    cell_start_.assign(1, 0);
    return;
  }
  Vec2 lo = Vec2::Constant(INFINITY);
  Vec2 hi = Vec2::Constant(-INFINITY);
  for (const table::Shape& s : shapes) {
    Vec2 slo, shi;
    shape_bounds(s, slo, shi);
    lo = lo.cwiseMin(slo);
    hi = hi.cwiseMax(shi);
  }
  lo.array() -= reach_m;
  hi.array() += reach_m;
  const Vec2 extent = hi - lo;
  while ((std::ceil(extent.x() / cell_m) + 1.0) * (std::ceil(extent.y() / cell_m) + 1.0) > kMaxCells) cell_m *= 2.0;
  origin_ = lo;
  inv_cell_ = 1.0 / cell_m;
  nx_ = static_cast<int>(std::ceil(extent.x() / cell_m)) + 1;
  ny_ = static_cast<int>(std::ceil(extent.y() / cell_m)) + 1;

  // Pass 1 counts, pass 2 fills: shapes visit only the cells their bounds
  // (grown by reach) overlap, and keep those they are truly within reach of.
  std::vector<std::int32_t> count(static_cast<std::size_t>(nx_) * ny_ + 1, 0);
  auto for_each_cell_in_reach = [&](const table::Shape& s, auto&& fn) {
    Vec2 slo, shi;
    shape_bounds(s, slo, shi);
    const int x0 = std::max(0, static_cast<int>(std::floor((slo.x() - reach_m - origin_.x()) * inv_cell_)));
    const int y0 = std::max(0, static_cast<int>(std::floor((slo.y() - reach_m - origin_.y()) * inv_cell_)));
    const int x1 = std::min(nx_ - 1, static_cast<int>(std::floor((shi.x() + reach_m - origin_.x()) * inv_cell_)));
    const int y1 = std::min(ny_ - 1, static_cast<int>(std::floor((shi.y() + reach_m - origin_.y()) * inv_cell_)));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const Vec2 clo = origin_ + Vec2{x * cell_m, y * cell_m};
        const Vec2 chi = clo + Vec2{cell_m, cell_m};
        if (distance_shape_box(s, clo, chi) <= reach_m) fn(y * nx_ + x);
      }
    }
  };
  for (const table::Shape& s : shapes) for_each_cell_in_reach(s, [&](int cell) { ++count[cell + 1]; });
  for (std::size_t i = 1; i < count.size(); ++i) count[i] += count[i - 1];
  cell_start_ = count;
  entries_.resize(static_cast<std::size_t>(count.back()));
  std::vector<std::int32_t> fill(count.begin(), count.end() - 1);
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    for_each_cell_in_reach(shapes[i], [&](int cell) { entries_[fill[cell]++] = static_cast<std::int32_t>(i); });
  }
}

int UniformGrid::candidates_in_box(const Vec2& lo, const Vec2& hi, std::span<const std::int32_t>* lists,
                                   int max_lists) const {
  if (nx_ == 0 || ny_ == 0) return 0;
  const double fx0 = std::max(0.0, (lo.x() - origin_.x()) * inv_cell_);
  const double fy0 = std::max(0.0, (lo.y() - origin_.y()) * inv_cell_);
  const double fx1 = std::min(nx_ - 1.0, (hi.x() - origin_.x()) * inv_cell_);
  const double fy1 = std::min(ny_ - 1.0, (hi.y() - origin_.y()) * inv_cell_);
  if (!(fx0 <= fx1 && fy0 <= fy1)) return 0;  // outside the grid (or NaN)
  const int x0 = static_cast<int>(fx0), x1 = static_cast<int>(fx1);
  const int y0 = static_cast<int>(fy0), y1 = static_cast<int>(fy1);
  int n = 0;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const int cell = y * nx_ + x;
      if (cell_start_[cell + 1] == cell_start_[cell]) continue;
      if (n < max_lists) {
        lists[n] = {entries_.data() + cell_start_[cell],
                    static_cast<std::size_t>(cell_start_[cell + 1] - cell_start_[cell])};
      }
      ++n;
    }
  }
  return n;
}

std::size_t UniformGrid::max_candidates() const {
  std::size_t best = 0;
  for (std::size_t c = 0; c + 1 < cell_start_.size(); ++c) {
    best = std::max(best, static_cast<std::size_t>(cell_start_[c + 1] - cell_start_[c]));
  }
  return best;
}

}  // namespace pinball::sim
