#pragma once
// The piecewise-linear action function (thesis 5.2.2, 5.2.4): the input space
// (flipper × impact-angle bin, optionally × h bin, optionally a rolling
// partition per flipper, thesis 7.1) is split into partitions, each with a
// minicontroller (a1..a4, f) giving d_critical = a1·θ + a2·h + a3·s + a4 (5.1)
// and the flipper to fire.

#include <array>
#include <cstdint>
#include <vector>

#include "pinball/core/check.h"
#include "pinball/core/name_value.h"
#include "pinball/core/rng.h"
#include "pinball/track/projection.h"

namespace pinball::control {

/// Largest |gain| of a minicontroller and largest gain range: fifty times the
/// widest range the learner draws from; beyond it d_critical lies metres past any table.
inline constexpr double kMaxGain = 10.0;
/// Most angle bins, and most h bins, of a partition: sixteen times the shipped
/// 4 (each partition needs balls to learn); it bounds the minicontroller count.
inline constexpr int kMaxBins = 64;

/// One local linear controller (thesis 5.2.4): d_critical = a1·θ + a2·h + a3·s + a4 (m).
struct Minicontroller {
  std::array<double, 4> a{};      ///< a1 (m/rad), a2 (m per flipper length), a3 (s), a4 (m); each within ±kMaxGain
  int flipper = track::kLeftFlipper;  ///< which flipper this partition fires
};

/// How the input space is partitioned, and the gain ranges of random minicontrollers.
struct ActionFunctionConfig {
  /// Interior impact-angle borders γ (rad), strictly increasing inside (−π/2, π/2);
  /// k − 1 of them make k bins. A θ equal to a border belongs to the bin above it.
  std::vector<double> angle_borders_rad;
  /// Interior h borders (flipper lengths), strictly increasing inside (−100, 100); empty: no h partition (the thesis).
  std::vector<double> h_borders;
  /// A separate minicontroller for a ball rolling on each flipper (thesis 7.1).
  bool rolling_minicontrollers = false;
  /// Random gains are uniform in [−gain_range[i], +gain_range[i]] (thesis 6.1.3: symmetric about 0);
  /// each in [0, kMaxGain].
  std::array<double, 4> gain_range{0.12, 0.2, 0.08, 0.2};

  /// The keys of a controller file (docs/learning.md).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(angle_borders_rad));
    a->Visit(PINBALL_NVP(h_borders));
    a->Visit(PINBALL_NVP(rolling_minicontrollers));
    a->Visit(PINBALL_NVP(gain_range));
  }
};

/// k uniform angle bins over [−π/2, π/2] (the thesis's choice, 6.1.1). Throws for k < 1.
ActionFunctionConfig uniform_partition(int k);

/// The first setting outside its range: borders finite, strictly increasing
/// and inside their interval, at most kMaxBins − 1 of each kind, gain ranges
/// in [0, kMaxGain].
RangeViolation check_action_function_config(const ActionFunctionConfig& config);

/// Gains outside ±kMaxGain (key "a") or a flipper that is neither (key "flipper").
RangeViolation check_minicontroller(const Minicontroller& minicontroller);

/// The action: fire `flipper` once d <= d_critical_m.
struct Action {
  int partition = -1;        ///< index of the responsible minicontroller
  double d_critical_m = 0.0; ///< d_critical (m); may be negative (never fires)
  int flipper = track::kLeftFlipper;  ///< flipper to fire
};

/// A set of minicontrollers over a fixed partition.
class ActionFunction {
 public:
  /// Throws std::invalid_argument for a setting out of range
  /// (check_action_function_config).
  explicit ActionFunction(ActionFunctionConfig config);

  /// Number of angle bins k, h bins, and partitions in all.
  int angle_bins() const { return static_cast<int>(config_.angle_borders_rad.size()) + 1; }
  int h_bins() const { return static_cast<int>(config_.h_borders.size()) + 1; }
  int partitions() const { return static_cast<int>(minis_.size()); }

  /// Angle bin of θ: the number of borders <= θ (so a border belongs to the bin above).
  int angle_bin(double angle_rad) const;
  /// h bin of h: the number of h borders <= h.
  int h_bin(double h) const;
  /// Partition of a projection (flipper, angle bin, h bin; or the rolling partition of its flipper).
  int partition_of(const track::TrajectoryProjection& p) const;
  /// d_critical of minicontroller `partition` for this input (eq. 5.1).
  double d_critical(int partition, const track::TrajectoryProjection& p) const;
  /// The action for a projection (valid or not: the caller checks validity).
  Action action(const track::TrajectoryProjection& p) const;

  /// Minicontrollers, by partition index.
  const Minicontroller& minicontroller(int i) const { return minis_.at(static_cast<std::size_t>(i)); }
  Minicontroller& minicontroller(int i) { return minis_.at(static_cast<std::size_t>(i)); }
  const std::vector<Minicontroller>& minicontrollers() const { return minis_; }

  /// A random minicontroller (thesis 6.2.1): gains uniform over the gain range, a random flipper.
  Minicontroller random_minicontroller(Rng& rng) const;
  /// Replaces every minicontroller with a random one.
  void randomise(Rng& rng);

  /// The partition settings.
  const ActionFunctionConfig& config() const { return config_; }
  /// A readable name of a partition ("L angle 2", "R rolling", ...).
  std::string partition_name(int i) const;

 private:
  ActionFunctionConfig config_;
  std::vector<Minicontroller> minis_;
};

}  // namespace pinball::control
