#pragma once
// Uniform grid over static shapes (thesis 3.3.2, footnote 2). Each cell stores,
// once at build time, every shape within `reach` of any point of the cell, so
// a query is one cell lookup and never touches obstacles out of the ball's
// reach. Storage is two flat arrays (offsets and indices): nothing per cell.

#include <cstdint>
#include <span>
#include <vector>

#include "pinball/core/geometry.h"
#include "pinball/table/board.h"

namespace pinball::sim {

/// Cell -> nearby shape indices, in ascending index order.
class UniformGrid {
 public:
  UniformGrid() = default;

  /// Builds the grid. reach_m: the largest distance from a ball centre in a
  /// cell to a shape it may touch before the next query; cell_m: cell edge.
  UniformGrid(std::span<const table::Shape> shapes, double reach_m, double cell_m);

  /// Indices of every shape within reach of `p` (ascending). Empty far from
  /// all shapes, including outside the grid.
  std::span<const std::int32_t> candidates(const Vec2& p) const {
    const double fx = (p.x() - origin_.x()) * inv_cell_;
    const double fy = (p.y() - origin_.y()) * inv_cell_;
    if (!(fx >= 0.0 && fy >= 0.0 && fx < nx_ && fy < ny_)) return {};
    const int cell = static_cast<int>(fy) * nx_ + static_cast<int>(fx);
    return {entries_.data() + cell_start_[cell],
            static_cast<std::size_t>(cell_start_[cell + 1] - cell_start_[cell])};
  }

  /// Candidate lists of the cells that the box [lo, hi] overlaps (cells
  /// outside the grid hold nothing and are skipped). Writes at most max_lists
  /// spans and returns how many cells overlap; a return above max_lists means
  /// the box is too big for the caller's buffer (only max_lists were written).
  int candidates_in_box(const Vec2& lo, const Vec2& hi, std::span<const std::int32_t>* lists, int max_lists) const;

  /// Cell edge (m); 0 for an empty grid.
  double cell_m() const { return inv_cell_ > 0.0 ? 1.0 / inv_cell_ : 0.0; }

  /// Number of cells.
  int cell_count() const { return nx_ * ny_; }
  /// Total stored (cell, shape) pairs.
  std::size_t entry_count() const { return entries_.size(); }
  /// Largest candidate list of any cell.
  std::size_t max_candidates() const;

 private:
  Vec2 origin_ = Vec2::Zero();
  double inv_cell_ = 0.0;
  int nx_ = 0;
  int ny_ = 0;
  std::vector<std::int32_t> cell_start_;  // nx*ny + 1 offsets into entries_
  std::vector<std::int32_t> entries_;
};

}  // namespace pinball::sim
