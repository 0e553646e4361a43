#pragma once
// A flipper controller that copies a teacher's shots (docs/learning.md,
// "Learning from a teacher"): it holds the teacher's recorded shots, each the
// tracker's projection (flipper, θ, h, s, rolling) at the moment the teacher
// fired, with the projected distance d left at that moment, or a pass when the
// teacher let the ball go by. For each new projection it takes the k recorded
// shots nearest in (θ, h, s) on the same flipper line; if most of them fired,
// d_critical is the median of their d, and it fires once d <= d_critical, as
// the thesis's actuator does (5.2.3), for the median of their holds. The
// action function's d_critical (5.2.4) is linear per angle bin; this one is a
// nearest-neighbour table, so it can follow the sharp, many-valued choices of
// a teacher that aims. θ is compared modulo π: a ball falling straight down
// is at −π/2 or +π/2 depending on the sign of a tiny vx.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "pinball/control/flipper_controller.h"
#include "pinball/core/check.h"
#include "pinball/core/name_value.h"
#include "pinball/track/projection.h"

namespace pinball::control {

/// One recorded approach: what the tracker projected and what the teacher did.
struct ShotExample {
  int flipper = track::kLeftFlipper;  ///< the projection's flipper line (f_impact)
  bool rolling = false;               ///< the rolling-ball projection (4.1.2)
  double angle_rad = 0.0;             ///< θ_impact
  double h = 0.0;                     ///< h_impact (flipper lengths)
  double speed_mps = 0.0;             ///< s_impact
  int fired_flipper = -1;             ///< flipper the teacher fired; -1: it let the ball pass
  double d_fire_m = 0.0;              ///< d_impact when the teacher fired (m)
  double hold_s = 0.0;                ///< how long the teacher held the flipper up (s)
};

/// Settings of the nearest-neighbour lookup (ranges: check_imitation_config).
struct ImitationConfig {
  int neighbours = 7;             ///< k (1..kMaxNeighbours)
  double angle_scale_rad = 0.10;  ///< θ distance worth one unit, 0.001..π rad
  double h_scale = 0.10;          ///< h distance worth one unit, 0.001..10 flipper lengths
  double speed_scale_mps = 0.30;  ///< s distance worth one unit, 0.001..100 m/s
  double max_hold_s = 1.0;        ///< release a flipper held this long with no launch seen, 0..10 s (0: never)
  /// Fire when d − s·lead_s <= d_critical: the teacher fired at the frame whose d
  /// was nearest its choice, so firing at the first frame with d <= d_critical
  /// would be half a frame late on average. Half a 200 fps frame by default; 0..0.1 s.
  double lead_s = 0.0025;
  /// Lead (issue 20): the shots are keyed, and looked up, on the projection
  /// advanced by the newest frame's camera latency plus this actuation delay
  /// (s; projection_to_act_on), so d_critical means the same whatever the
  /// latency. θ, h and s do not move; d does. A table recorded with a lead is
  /// only right with the same lead. Absent: the projection from the newest
  /// frame, as every table before the lead. 0..0.1 s.
  std::optional<double> lead_actuation_delay_s;

  /// The keys of a controller file (docs/learning.md).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(neighbours));
    a->Visit(PINBALL_NVP(angle_scale_rad));
    a->Visit(PINBALL_NVP(h_scale));
    a->Visit(PINBALL_NVP(speed_scale_mps));
    a->Visit(PINBALL_NVP(max_hold_s));
    a->Visit(PINBALL_NVP(lead_s));
    a->Visit(PINBALL_NVP(lead_actuation_delay_s));
  }
};

/// Largest k the controller supports (it keeps the neighbours in a fixed array).
inline constexpr int kMaxNeighbours = 32;

/// Most shots a table holds, about five times the shipped one (44273): a
/// lookup costs at most about two scans of one line's shots (ShotTable::decide),
/// a few milliseconds at this size.
inline constexpr std::size_t kMaxShots = 250'000;

/// The first setting outside its range. The scales are the widths of the
/// lookup grid's cells: below 0.001 nothing the tracker measures is that fine,
/// and the grid and its search grow without bound (an angle scale of 1e-6 once
/// made a lookup spin for ever, 1.5e-9 asked for an oversized allocation).
RangeViolation check_imitation_config(const ImitationConfig& config);

/// The first field of a shot outside its range (keys: ShotTable's `shot_fields`):
/// flipper 0 or 1, fired flipper −1, 0 or 1, |θ| <= π, |h| <= 100 flipper
/// lengths, 0 <= s <= 100 m/s, |d| <= 10 m, 0 <= hold <= 10 s, all finite.
RangeViolation check_shot_example(const ShotExample& example);

/// What the table says for one projection.
struct ImitationDecision {
  bool fire = false;         ///< most neighbours fired
  int flipper = track::kLeftFlipper;  ///< the flipper most firing neighbours fired
  double d_critical_m = 0.0; ///< median d of the firing neighbours (m)
  double hold_s = 0.0;       ///< median hold of the firing neighbours (s)
  int neighbours = 0;        ///< neighbours found (fewer than k when the table is small)
};

/// The shot table and its lookup. Allocates nothing after construction. The
/// examples of each line are bucketed in a grid over (θ, h, s) with cells at
/// least one scale wide and not many more cells than examples, searched in
/// growing shells around the query's cell, so a lookup visits a few cells
/// rather than every example; the answer is the exact k nearest (ties: the
/// lower example index), the same as a full scan. A lookup's cost is bounded:
/// once the shell search has done as much work as a scan of the line would,
/// it scans the line instead, so a lookup costs at most about two scans.
class ShotTable {
 public:
  /// Throws std::invalid_argument for a setting out of range
  /// (check_imitation_config), a shot out of range (check_shot_example) or
  /// more than kMaxShots shots.
  ShotTable(std::vector<ShotExample> examples, const ImitationConfig& config);

  /// The decision for a projection (valid or not: the caller checks validity).
  ImitationDecision decide(const track::TrajectoryProjection& p) const;

  /// The same answer by scanning every example of the line (for tests and the bench).
  ImitationDecision decide_by_scan(const track::TrajectoryProjection& p) const;

  const std::vector<ShotExample>& examples() const { return examples_; }
  const ImitationConfig& config() const { return config_; }

 private:
  // One flipper line's (flipper, rolling) examples in grid cells (compressed rows).
  struct Line {
    int n_theta = 1, n_h = 1, n_s = 1;  // cells per axis
    double h0 = 0.0, s0 = 0.0;          // lower edges of the h and s axes
    double cell_theta_rad = 0.0;        // θ cell width: π / n_theta, at least one scale
    double cell_h = 0.0, cell_s = 0.0;  // h and s cell widths, at least one scale
    std::vector<std::uint32_t> start;   // first item of each cell; size cells + 1
    std::vector<std::uint32_t> items;   // example indices, cell by cell
  };
  struct Neighbours;
  void build_line(Line& line, const std::vector<std::uint32_t>& members);
  int cell_of(const Line& line, int it, int ih, int is) const;
  void consider(std::uint32_t i, const track::TrajectoryProjection& p, Neighbours& n) const;
  ImitationDecision vote(const Neighbours& n) const;

  std::vector<ShotExample> examples_;
  ImitationConfig config_;
  std::array<Line, 4> lines_;  // by (flipper, rolling)
};

/// The table driving the flippers: fires once d <= d_critical, holds for the
/// table's hold, then releases and may fire again in the same approach; releases
/// everything on a detected launch or a lost ball.
class ImitationController final : public FlipperController {
 public:
  /// Shares the table: many controllers (one per ball in the evaluator) use one copy.
  explicit ImitationController(std::shared_ptr<const ShotTable> table);
  explicit ImitationController(ShotTable table)
      : ImitationController(std::make_shared<const ShotTable>(std::move(table))) {}

  void update(const track::TrackerOutput& output, double now_s, std::array<bool, 2>& energized) override;
  void reset(std::array<bool, 2>& energized) override;

  /// Flips fired since construction.
  long fires() const { return fires_; }
  const ShotTable& table() const { return *table_; }

 private:
  std::shared_ptr<const ShotTable> table_;
  int held_ = -1;          // flipper up, or -1
  double release_at_s_ = 0.0;
  double held_since_s_ = 0.0;
  long fires_ = 0;
};

}  // namespace pinball::control
