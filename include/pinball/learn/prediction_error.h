#pragma once
// How well a belief predicts recorded play (issue 20): from a moment of a
// recording, the ball's state as the tracker would estimate it from the last
// frames (a parabola under the belief's g, unless the ball was pushed: see
// below), the belief's model plays on for a horizon with the flippers down,
// and the predicted ball is compared with where the camera saw it. The moments are chosen from the recording alone
// (never from the belief), so two beliefs are judged on the same moments:
// the ball was seen in every frame of the history and at the horizon and
// was one ball all along, the history fits one parabola, and no coil
// command falls near the window. A ball the model loses in the window flies
// on under g from where it was lost (the model takes it off the table; the
// camera still sees it).
// The moments are also told apart by what moved the ball in the history,
// again from the recording alone: g alone, when the history's acceleration
// is the recording's usual one (the median over every moment's history), or
// something more (pushed), when an acceleration of its own fits the history
// better by more than the 99.9 % point of χ²(2). What pushes a ball is a
// wall or a resting flipper it rolls along, or, on a real table, sliding
// friction: a ball skids after a bounce until the playfield has made it
// roll again, which a model without ball spin cannot know. A pushed
// moment starts from the history's own acceleration fit (the same for every
// belief): forcing g on it would get the velocity wrong by the push times
// half the history.

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "pinball/bus/recorded_play.h"
#include "pinball/core/name_value.h"
#include "pinball/table/board.h"

namespace pinball::learn {

/// How moments are chosen and predicted.
struct PredictionOptions {
  double horizon_s = 0.1;         ///< how far ahead (s)
  int history_frames = 24;        ///< frames the start state is fitted to (the tracker's least window)
  double sigma_m = 0.001;         ///< detector noise, for the history's χ² test (m)
  double command_margin_s = 0.3;  ///< no coil command this long before the moment, nor before the horizon (s)
  int stride_frames = 5;          ///< frames between moments (they overlap less)
  /// A faster move between two frames is another ball (the next one launched
  /// after a drain): no moment's window spans it (m/s).
  double max_speed_mps = 10.0;
};

/// One moment to predict from.
struct PredictionStart {
  std::size_t recording = 0;  ///< index into the recordings
  std::size_t frame = 0;      ///< the history's last frame: the moment
  bool pushed = false;        ///< the history's acceleration is not the recording's usual one (see the file comment)
};

/// The error of the moments whose window held a collision, by what the
/// model's ball hit first in it: where the model, not the start, is wrong.
struct CollisionError {
  std::string model_hit;    ///< "obstacles <first> and N more" (a material group), "flipper <name>", "nothing" or "lost"
  std::size_t moments = 0;  ///< moments
  double mean_m = 0.0;      ///< mean error (m)

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(model_hit));
    a->Visit(PINBALL_NVP(moments));
    a->Visit(PINBALL_NVP(mean_m));
  }
};

/// Prediction errors over moments.
struct PredictionError {
  std::size_t moments = 0;    ///< moments predicted
  double mean_m = 0.0;        ///< mean distance between predicted and seen ball (m)
  double median_m = 0.0;      ///< median (m)
  double p90_m = 0.0;         ///< 90th percentile (m)
  double mean_ci95_m = 0.0;   ///< half-width of the mean's 95 % interval (Student's t, m)
  /// The moments whose seen window (moment to horizon) fits one parabola:
  /// the ball flew free, and only g and the start's noise matter there.
  std::size_t free_moments = 0;
  double free_mean_m = 0.0;       ///< mean error over them (m); NaN with none
  double collision_mean_m = 0.0;  ///< mean error over the others, something hit in the window (m); NaN: none
  std::size_t under_g_moments = 0;  ///< moments whose history g alone moved (PredictionStart::pushed false)
  double under_g_mean_m = 0.0;       ///< mean error over them (m); NaN with none
  std::size_t pushed_moments = 0;   ///< moments whose history something more pushed (skid, a wall, a flipper)
  double pushed_mean_m = 0.0;       ///< mean error over them (m); NaN with none
  /// The collision moments by what the model hit first, most moments first.
  std::vector<CollisionError> collisions_by_model_hit;
  /// Each start's error (m), in the order of the starts; NaN where the
  /// moment could not be predicted. Not in --json: the pairing is its use.
  std::vector<double> errors_m;

  /// Every figure, for --json (core/json_write_archive.h).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(moments));
    a->Visit(PINBALL_NVP(mean_m));
    a->Visit(PINBALL_NVP(mean_ci95_m));
    a->Visit(PINBALL_NVP(median_m));
    a->Visit(PINBALL_NVP(p90_m));
    a->Visit(PINBALL_NVP(free_moments));
    a->Visit(PINBALL_NVP(free_mean_m));
    a->Visit(PINBALL_NVP(collision_mean_m));
    a->Visit(PINBALL_NVP(under_g_moments));
    a->Visit(PINBALL_NVP(under_g_mean_m));
    a->Visit(PINBALL_NVP(pushed_moments));
    a->Visit(PINBALL_NVP(pushed_mean_m));
    a->Visit(PINBALL_NVP(collisions_by_model_hit));
  }
};

/// One model's mean error over another's on the moments both predicted.
struct ErrorRatio {
  double ratio = 0.0;      ///< Σ errors of the first / Σ errors of the second
  double ci95 = 0.0;       ///< half-width of its 95 % interval (delta method over the paired moments)
  std::size_t moments = 0; ///< moments both predicted
};

/// The ratio of `model`'s mean error to `baseline`'s, paired moment by
/// moment (both from prediction_error over the same starts). Throws
/// std::invalid_argument when their starts differ in number.
ErrorRatio paired_error_ratio(const PredictionError& model, const PredictionError& baseline);

/// The moments of `recordings` to predict from (see the file comment).
std::vector<PredictionStart> prediction_starts(std::span<const bus::RecordedPlay> recordings,
                                               const PredictionOptions& options = {});

/// How far the model of `belief` (thesis stepper) lands from the seen ball
/// `options.horizon_s` after each moment.
PredictionError prediction_error(const table::Board& belief, std::span<const bus::RecordedPlay> recordings,
                                 std::span<const PredictionStart> starts, const PredictionOptions& options = {});

}  // namespace pinball::learn
