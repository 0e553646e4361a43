#pragma once
// `pinball bench ceiling`: how well a player that CHEATS does on the board, as
// a ceiling reference for the learned controllers (issue #6), compared in the
// same run and on the same balls with the spastic flipper and with no flipping.
//
// The ceiling player is not a controller: it reads the world's true state
// and looks ahead in the belief's model, the thesis stepper on the board file
// (in the default model world that is the world itself: a copy of the
// GameState is a copy of the world; in the twin or another board it is not).
// Every 5 ms frame (what a 200 fps camera allows) while the ball is falling
// within `zone_factor` ball radii of a flipper's rest position and no flip is
// under way, it plays candidate plans ahead for the flipper nearest the
// ball: "don't fire", and "fire at frame k (k = 0..K), hold H frames,
// release" for each hold in `hold_frames`. A branch ends when the ball comes
// back falling into a decision zone after having left every zone (the next
// approach), when the ball is lost, or at the horizon; its value is the score
// gained in it, minus `drain_penalty` if the ball was lost. Receding horizon:
// only the best plan's first frame is acted on. If the best plan fires now,
// the player fires and holds for that plan's H frames, then releases and plans
// again; otherwise it does nothing this frame and plans again at the next.
// Ties go to the earlier candidate, so "don't fire" wins when nothing is
// better. Commands pass through the evaluator's 4 ms actuation delay
// (simlab::DelayLine), in the branches as in the real play.
//
// Baselines on the same ball seeds (ball_seed(seed, i)): the spastic
// flipper on the true state (simlab::oracle_spastic_policy, every step, same
// actuation delay), and no flipping. Balls are cut at 60 s as in the evaluator.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "drain_cause.h"
#include "pinball/core/running_stats.h"
#include "pinball/control/controller_file.h"
#include "pinball/firmware/flipper_actuation.h"
#include "pinball/learn/lookahead_player.h"
#include "pinball/track/camera_model.h"
#include "pinball/table/board.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/thesis_stepper.h"
#include "pinball/sim/world.h"

namespace pinball::bench {

/// What to measure.
struct CeilingBenchOptions {
  int balls = 200;                  ///< balls per player (same seeds for all three)
  std::uint64_t seed = 1;           ///< run seed: ball i plays ball_seed(seed, i)
  int threads = 2;                  ///< worker threads; results do not depend on it
  double max_ball_time_s = 60.0;    ///< a ball alive after this is cut (a possible cycle)
  double actuation_delay_s = firmware::kDefaultActuationDelay_s; ///< command to flipper motion, as in the evaluator
  double pull = -1.0;               ///< launcher pull; negative: the board's
  double spastic_reach_factor = 2.5;///< the spastic baseline's reach (ball radii)
  learn::LookaheadConfig planner;   ///< the ceiling player's planner
  track::CameraModelConfig camera;  ///< the tracker-side players' camera (the evaluator's)
  /// A controller to play through the camera model and tracker beside the
  /// others (`--controller FILE`); null: none.
  const control::ControllerSpec* controller = nullptr;
  std::string controller_name;      ///< its file, for the report
  /// Also play the controller fed the TRUE ball instead of the tracker's
  /// estimate (`--true-state-noise MM MPS`): every camera frame, a parabola
  /// through the ball's true position and velocity, each coordinate plus
  /// Gaussian noise of these standard deviations. How exact a start the
  /// controller's plans need (docs/results.md); null: not played.
  struct TrueStateFeed {
    double position_noise_m = 0.0;     ///< standard deviation per coordinate (m)
    double velocity_noise_mps = 0.0;   ///< standard deviation per coordinate (m/s)
  };
  std::optional<TrueStateFeed> true_state_feed;
};

/// A short run for tests and a first look: 10 balls.
CeilingBenchOptions quick_ceiling_bench_options();

/// Who presses the buttons. The first three read the true state; the last two
/// see only the tracker's output through the camera model, as the evaluator's
/// controllers do (the 3x target's spastic baseline is kTrackerSpastic).
enum class CeilingPlayerKind { kCeiling, kSpastic, kNoFlipping, kTrackerSpastic, kController, kControllerTrueState };

/// One ball's outcome, and the ceiling player's planning.
struct CeilingBall : PlayedBall {
  int decisions = 0;              ///< ceiling: frames at which candidates were evaluated
  std::uint64_t branch_steps = 0; ///< ceiling: stepper steps simulated in lookahead branches
};

/// Plays ball `ball_seed` in `world` with `kind` (the same seed gives the same
/// ball for every kind up to the first flip). `model` is the belief: the
/// tracker's board and the ceiling player's planning model; the true-state
/// players read the world's state directly.
CeilingBall play_ceiling_bench_ball(sim::World& world, const sim::ThesisStepper& model,
                                    const CeilingBenchOptions& options, CeilingPlayerKind kind,
                                    std::uint64_t ball_seed);

/// One player's figures.
struct CeilingPlayerReport {
  std::string name;               ///< ceiling | spastic | no_flipping
  RunningStats score;             ///< per ball
  RunningStats duration_s;        ///< per ball
  RunningStats flips;             ///< per ball
  int cut = 0;                    ///< balls cut at the time limit
  DrainCounts drains;             ///< lost balls by where they went (classify_drain)
  double decisions_per_ball = 0.0;     ///< ceiling: planning frames per ball
  double branch_steps_per_ball = 0.0;  ///< ceiling: lookahead steps per ball
  double wall_s = 0.0;            ///< wall time of this player's balls
};

/// The whole measurement.
struct CeilingReport {
  std::string board;              ///< board name (the belief)
  std::string world_board;        ///< the world's board
  std::string world;              ///< the world that played: thesis, event (stepper of the model world)
  CeilingBenchOptions options;    ///< what was run
  CeilingPlayerReport ceiling;    ///< the cheating lookahead player
  CeilingPlayerReport spastic;    ///< the spastic flipper on true state (baseline)
  CeilingPlayerReport no_flipping;///< flippers never move (baseline)
  CeilingPlayerReport tracker_spastic;  ///< the spastic flipper through the tracker (the learning tables' baseline)
  std::optional<CeilingPlayerReport> controller;  ///< options.controller, through the tracker
  std::optional<CeilingPlayerReport> controller_true_state;  ///< options.controller fed options.true_state_feed
  double ceiling_over_spastic = 0.0;  ///< ratio of mean scores per ball
  double ceiling_over_tracker_spastic = 0.0;     ///< the same against the spastic flipper through the tracker
  double controller_over_tracker_spastic = 0.0;  ///< the controller's, when one was played
  double controller_true_state_over_tracker_spastic = 0.0;  ///< the same fed the true state, when played
};

/// Runs the players; `progress` (may be empty) gets a line now and then, from
/// any thread but never two at once. `board` is the belief; balls play in
/// forks of `world` (null: the model of `board` on the thesis stepper).
CeilingReport run_ceiling_bench(const table::Board& board, const CeilingBenchOptions& options,
                                const std::function<void(const std::string&)>& progress,
                                const sim::World* world = nullptr);

// The report (ceiling_bench_report.cpp).

/// The report as one JSON object.
nlohmann::json to_json(const CeilingReport& report);
/// The report as text.
std::string to_text(const CeilingReport& report);

}  // namespace pinball::bench
