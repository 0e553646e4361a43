#pragma once
// `pinball bench cradle`: can a ball be kept alive by a cycle from the cradle?
//
// The last target asks for a ball alive 10 minutes in at least 1 % of
// balls, by a path the controller repeats. The one state a controller can
// repeat exactly is a ball at rest in the crook of a raised bat (the cradle):
// no velocity, and a place fixed by the bat and the guide. So the cycle
// sought is: hold both bats up; once the ball has lain still on a raised bat
// for `rest_s`, drop that bat for `drop_s` (the ball rolls down it) and raise
// it again, which shoots the ball up the table; hold both up again until the
// ball comes back to a cradle. Each cradle resets the ball, so a cycle is as
// long-lived as the chance p that a shot returns to a cradle: a ball lives
// about p^n for n cycles, and 10 minutes at a period T needs
// p >= 0.01^(T / 600 s) for 1 % of balls.
//
// The player here sees the world's true ball and acts on the world's own
// step: exact timing, no camera, no delay line (a delay moves the drop and
// the raise alike). It is a ceiling on what a cradle cycle can do, not a
// controller; the report says so.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pinball/core/statistics.h"
#include "pinball/sim/world.h"
#include "pinball/table/board.h"

#include "drain_cause.h"

namespace pinball::bench {

/// What to measure.
struct CradleBenchOptions {
  int balls = 8;                  ///< balls per drop duration; ball i launches with ball_seed(seed, i)
  std::uint64_t seed = 1;
  double max_ball_time_s = 600.0; ///< a ball alive after this is cut
  double drop_from_s = 0.230;     ///< the drop durations tried: from, to (inclusive) and step (s)
  double drop_to_s = 0.250;
  double drop_step_s = 0.001;
  double rest_s = 0.3;            ///< still this long on a raised bat: cradled
  double still_speed_mps = 0.02;  ///< slower than this is still
  double left_height_m = 0.25;    ///< a shot has left the bats once the ball rises this far above the highest pivot
  double cycling_gap_s = 60.0;    ///< a ball cut at the cap with no return in this long is stuck, not cycling
  int threads = 1;                ///< results do not depend on it
};

/// One ball's play.
struct CradleBall {
  bool cradled = false;        ///< reached a cradle at all
  int shots = 0;               ///< drops whose outcome is known: returns, and the drop the ball was lost after
  int returns = 0;             ///< drops after which the ball left the bats and came back to a cradle
  int duds = 0;                ///< drops after which the ball settled again without leaving the bats (no cycle, no loss)
  int passes = 0;              ///< duds after which it settled on the other bat (rolled or hopped across)
  double cycle_time_s = 0.0;   ///< cradle to cradle, summed over the returns
  double cycle_points = 0.0;   ///< points scored over the returns
  bool lost_after_drop = false; ///< the cycle broke: lost after a drop, whether it left the bats or not
  DrainCause drain = DrainCause::kOther;  ///< when lost_after_drop
  bool cut = false;            ///< alive at the cap
  bool cycling_at_cut = false; ///< cut, with a return within cycling_gap_s of the cap
  bool passing_at_cut = false; ///< cut, with a pass within cycling_gap_s of the cap
  double ball_time_s = 0.0;
  double score = 0.0;
};

/// The balls of one drop duration.
struct CradleDropResult {
  double drop_s = 0.0;
  int balls = 0;
  int cradled = 0;             ///< balls that reached a first cradle
  int shots = 0;               ///< returns + losses after a drop
  int returns = 0;
  int duds = 0;
  int passes = 0;
  DrainCounts drains;          ///< balls lost after a drop, by route
  Interval return_interval;  ///< Wilson 95 % of returns / shots
  double mean_period_s = 0.0;  ///< cradle to cradle over the returns (NaN without a return)
  double points_per_cycle = 0.0;  ///< NaN without a return
  double mean_ball_time_s = 0.0;
  int cut = 0;
  int cut_cycling = 0;
  int cut_passing = 0;
  double mean_score = 0.0;
  double score_ci95 = 0.0;     ///< half-width of mean_score's 95 % interval (Student's t)

  /// returns / shots (NaN, null in JSON, without a shot).
  double return_share() const;
  /// The return share a cycle of this period needs for 1 % of balls to live
  /// 10 minutes: 0.01^(period / 600 s) (1 without a period).
  double return_share_needed() const;
  /// Of the balls that reached a cradle, the share alive at 10 minutes if
  /// every cycle returned independently at this share and period.
  double projected_share_at_10_min() const;
};

struct CradleReport {
  CradleBenchOptions options;
  std::string world;           ///< the world's name: "twin", "thesis", "event"
  std::vector<CradleDropResult> drops;
  /// The drop with the highest return share (the lower end of its interval breaks ties);
  /// none when no drop had a shot.
  std::optional<std::size_t> best;
  double wall_s = 0.0;
};

/// Plays one ball in `world` (a fresh fork) from its launch. Throws
/// std::invalid_argument for a board without two flippers.
CradleBall play_cradle_ball(const sim::World& world, std::uint64_t ball_seed, double drop_s,
                            const CradleBenchOptions& options);

/// Every drop duration from drop_from_s to drop_to_s, options.balls balls
/// each. Throws std::invalid_argument for balls < 1, a drop range that is
/// empty, not positive or over 1000 durations, or a rest, cap or height <= 0.
CradleReport run_cradle_bench(const sim::World& world, const CradleBenchOptions& options,
                              const std::function<void(const std::string&)>& progress = {});

nlohmann::json to_json(const CradleReport& report);
std::string to_text(const CradleReport& report);

}  // namespace pinball::bench
