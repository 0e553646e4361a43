#pragma once
// Where a lost ball went, for the benches that say how their players lose
// balls (`bench ceiling`, `bench transfer`): one classifier. A ball is lost
// below the flippers, so what tells an outlane from the gap between the
// flippers is where it last went down past the flippers' pivot line: outside
// the leftmost pivot (the left outlane), outside the rightmost (the right
// outlane), or between them (the centre). Its position when lost says less:
// a ball leaving the left outlane drifts right under the flipper before the
// drain takes it (up to 70 mm from the wall on the thesis table), and one
// through the gap spreads across the bottom. A ball that went through the gap
// and bounced back up past the line beside the flippers (rare: under 1 % of
// the drains on the thesis table) counts where it came down last.

#include <cmath>
#include <limits>
#include <string_view>

#include "pinball/learn/blob.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/step_events.h"
#include "pinball/table/board.h"

namespace pinball::bench {

/// The way a ball left play.
enum class DrainCause : unsigned char {
  kLeftOutlane,   ///< went down outside the leftmost flipper's pivot
  kRightOutlane,  ///< went down outside the rightmost flipper's pivot
  kCentre,        ///< went down between the flippers' pivots
  kOther,         ///< never went down past the pivot line (lost above it, e.g. off the table)
};

/// "left_outlane", "right_outlane", "centre" or "other": the reports' keys.
std::string_view drain_cause_name(DrainCause cause);

/// The pivot line and the centre band of a board (board frame, m).
struct DrainZones {
  double line_y_m = -std::numeric_limits<double>::infinity();  ///< the flippers' pivot line (the highest pivot)
  double centre_min_x_m = 1.0;  ///< the leftmost pivot
  double centre_max_x_m = 0.0;  ///< the rightmost pivot
};

/// The zones of `board` (a board with fewer than two flippers has none:
/// every drain is kOther).
DrainZones drain_zones(const table::Board& board);

/// The cause of a ball lost after last going down past the pivot line at
/// `crossing_x_m` (NaN: it never did).
DrainCause classify_drain(const DrainZones& zones, double crossing_x_m);

/// Counts of lost balls by cause; a ball cut at the time limit is none of them.
struct DrainCounts {
  int left_outlane = 0;   ///< DrainCause::kLeftOutlane
  int right_outlane = 0;  ///< DrainCause::kRightOutlane
  int centre = 0;         ///< DrainCause::kCentre
  int other = 0;          ///< DrainCause::kOther
  int left_table = 0;     ///< of all of them, lost by leaving the table's bounds rather than by a drain

  /// Counts one lost ball.
  void add(DrainCause cause, bool left_table_bounds);
  /// Every lost ball.
  int total() const { return left_outlane + right_outlane + centre + other; }
};

/// A ball runner's observer (sim::play_ball) that keeps the x at which the
/// ball last went down past the pivot line since its launch, and how long
/// before that a flipper last touched it: an outlane drain decided seconds
/// and many bounces after the last shot is one no flipper could prevent.
class DrainWatch {
 public:
  /// Watches the ball of `start` against `zones`' pivot line.
  DrainWatch(const sim::GameState& start, const DrainZones& zones)
      : line_y_m_(zones.line_y_m), last_(start.ball.position_m) {}
  void operator()(const sim::GameState& s, const sim::StepEvents& e) {
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    const Vec2& p = s.ball.position_m;
    if (e.has(sim::StepEvents::kLaunch)) {
      crossing_x_m_ = kNaN;  // the chute lies below the line too
      crossing_after_flipper_s_ = kNaN;
      flipper_touch_s_ = kNaN;
    } else if (e.has(sim::StepEvents::kBallLost)) {
      return;  // a lost ball is moved back to the launcher: keep what was seen before
    } else {
      if (e.has(sim::StepEvents::kHitFlipper) || e.has(sim::StepEvents::kFlipperPush)) flipper_touch_s_ = s.time_s;
      if (last_.y() >= line_y_m_ && p.y() < line_y_m_) {
        const double f = (last_.y() - line_y_m_) / (last_.y() - p.y());
        crossing_x_m_ = last_.x() + f * (p.x() - last_.x());
        crossing_after_flipper_s_ = s.time_s - flipper_touch_s_;  // NaN when no flipper has touched it
      }
    }
    last_ = p;
  }
  /// Where the ball last went down past the line (NaN: it has not).
  double crossing_x_m() const { return crossing_x_m_; }
  /// Seconds from the last flipper touch before that crossing to the
  /// crossing (NaN: no crossing, or no flipper touched the ball before it).
  double crossing_after_flipper_s() const { return crossing_after_flipper_s_; }

 private:
  double line_y_m_;
  Vec2 last_;
  double crossing_x_m_ = std::numeric_limits<double>::quiet_NaN();
  double flipper_touch_s_ = std::numeric_limits<double>::quiet_NaN();
  double crossing_after_flipper_s_ = std::numeric_limits<double>::quiet_NaN();
};

/// What a bench keeps of one played ball: the ball runner's result and where
/// the ball was lost (plain bytes, so it crosses threads and MPI ranks as a blob).
struct PlayedBall {
  double score = 0.0;        ///< points scored
  double duration_s = 0.0;   ///< simulated time of the ball
  int flips = 0;             ///< flipper activations
  bool cut = false;          ///< alive at the time limit
  bool left_table = false;   ///< lost by leaving the table's bounds
  double drain_x_m = 0.0;    ///< where it last went down past the flippers' pivot line (DrainWatch; NaN: never)
  /// Seconds from the last flipper touch to that crossing (DrainWatch; NaN: none).
  double drain_after_flipper_s = 0.0;
};

/// A played ball as blob bytes, field by field (a struct's padding is no part
/// of it), and back: what crosses between the benches' threads and ranks.
inline void put_played_ball(learn::BlobWriter& w, const PlayedBall& b) {
  w.put(b.score).put(b.duration_s).put(b.flips).put(b.cut).put(b.left_table);
  w.put(b.drain_x_m).put(b.drain_after_flipper_s);
}
inline void get_played_ball(learn::BlobReader& r, PlayedBall& b) {
  b.score = r.get<double>();
  b.duration_s = r.get<double>();
  b.flips = r.get<int>();
  b.cut = r.get<bool>();
  b.left_table = r.get<bool>();
  b.drain_x_m = r.get<double>();
  b.drain_after_flipper_s = r.get<double>();
}

/// The ball `r` that `watch` saw.
inline PlayedBall played_ball(const sim::BallResult& r, const DrainWatch& watch) {
  return {r.score, r.duration_s, r.flips, r.cut, r.left_table, watch.crossing_x_m(), watch.crossing_after_flipper_s()};
}

}  // namespace pinball::bench
