#pragma once
// Learning from a teacher (docs/learning.md): the looking-ahead player plays
// on the simulator's true state while the camera model and the tracker watch,
// exactly as they would for a real controller; every approach of the ball to
// the flippers becomes one control::ShotExample: the tracker's projection at
// the frame the teacher fired, with d then, or the approach's last projection
// when the teacher let the ball pass. The table of these examples is the
// imitation controller (control/imitation_controller.h). The teacher cheats;
// the controller learned from it does not: it sees only the tracker's output.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pinball/control/imitation_controller.h"
#include "pinball/firmware/flipper_actuation.h"
#include "pinball/learn/blob.h"
#include "pinball/learn/lookahead_player.h"
#include "pinball/learn/randomized_evaluator.h"
#include "pinball/learn/search.h"
#include "pinball/sim/thesis_stepper.h"
#include "pinball/sim/world.h"
#include "pinball/track/camera_model.h"

namespace pinball::learn {

/// How the teacher plays and what watches it.
struct DemonstrationConfig {
  LookaheadConfig teacher;           ///< the teacher's planner
  track::CameraModelConfig camera;   ///< the camera the tracker believes it sees through
  /// The camera the world really has (latency, noise) when it is not the
  /// believed one (a drawn world of `learn --randomize`); empty: `camera`.
  std::optional<track::CameraModelConfig> world_camera;
  double actuation_delay_s = firmware::kDefaultActuationDelay_s;  ///< command to flipper motion (s), as in the evaluator
  /// The lead the shots are keyed with (control::ImitationConfig::lead_actuation_delay_s):
  /// each example holds the projection a table with this lead will look up. Empty: none.
  std::optional<double> lead_actuation_delay_s;
  double max_ball_time_s = 60.0;     ///< a teacher's ball alive after this is cut
  double pull = -1.0;                ///< launcher pull; negative: the board's
};

/// One teacher ball's examples and figures.
struct DemonstrationBall {
  std::vector<control::ShotExample> shots;  ///< one per approach, in order
  double score = 0.0;        ///< the teacher's score
  double duration_s = 0.0;   ///< simulated time of the ball
  bool cut = false;          ///< alive at the time limit
  int teacher_fires = 0;     ///< flips fired by whoever played (the teacher, or the learner)
  int unmatched_fires = 0;   ///< of them, fired where no example could be recorded (no hittable
                             ///< projection in that frame; a learner firing outside the teacher's zone)
};

/// A demonstration ball as bytes and back (for the MPI ranks and the checkpoint).
Blob to_blob(const DemonstrationBall& ball);
DemonstrationBall demonstration_ball_from_blob(const Blob& blob);

/// Plays ball `ball_seed` in `world` with the teacher, which plans on
/// `teacher_model`, while the tracker watches through the configured world
/// camera believing `belief` and the configured camera; records the shots.
DemonstrationBall record_demonstration(const table::Board& belief, sim::World& world,
                                       const sim::ThesisStepper& teacher_model, const DemonstrationConfig& config,
                                       std::uint64_t ball_seed);

/// Where a teacher's balls are played, and on what the teacher plans. The
/// teacher never looks into a world a controller is judged in: it plans on
/// the belief's model, or on a world drawn from the belief's ranges.
class TeacherWorlds {
 public:
  /// Every ball in a fork of `world` (null: the model of `belief`), the teacher
  /// planning on the belief's model. Borrows `belief`. Throws
  /// std::invalid_argument when the world's flippers are not the belief's.
  TeacherWorlds(const table::Board& belief, const sim::World* world);
  /// `learn --randomize`: each ball in the drawn world its seed picks
  /// (drawn_world_index), with that world's stepper, delay and camera. The
  /// teacher plans on that world's own table and delay: a drawn world is a
  /// sample of the belief, so its labels say what is best in each world the
  /// belief allows, and the learner, which cannot tell the worlds apart,
  /// learns what does well across them. `dt_s`: the worlds' step (0: the
  /// board's). Throws std::invalid_argument for no worlds.
  TeacherWorlds(const table::Board& belief, std::vector<DrawnWorld> drawn, double dt_s = 0.0);

  /// One place a ball can be played.
  struct Place {
    std::unique_ptr<sim::World> world;                   ///< forked for each ball
    std::unique_ptr<sim::ThesisStepper> teacher_model;   ///< what the teacher plans on
    std::optional<double> actuation_delay_s;             ///< the world's, when not the configured one
    std::optional<track::CameraModelConfig> camera;      ///< the world's, when not the configured one
  };
  /// The place ball `ball_seed` plays in.
  const Place& place_of(std::uint64_t ball_seed) const;
  /// The belief the tracker watches with.
  const table::Board& belief() const { return belief_; }
  /// The drawn worlds (empty for one world).
  const std::vector<DrawnWorld>& drawn() const { return drawn_; }

 private:
  const table::Board& belief_;
  std::vector<DrawnWorld> drawn_;  // their boards outlive the places' worlds and models
  std::vector<Place> places_;
};

/// Everything recorded over many balls.
struct Demonstrations {
  std::vector<control::ShotExample> shots;  ///< ball by ball, in ball order
  int balls = 0;
  double mean_teacher_score = 0.0;  ///< mean score per ball of whoever played
  double mean_ball_time_s = 0.0;
  int cut = 0;
  double best_cut_score = 0.0;  ///< highest score of a ball cut at the time limit (0: none cut)
  long teacher_fires = 0;
  long unmatched_fires = 0;
  double wall_s = 0.0;
};

/// Balls gathered (and checkpointed) at a time by record_demonstrations: a
/// round of more is several batches, so memory holds one batch's balls and a
/// long round is kept in parts. Fixed, not per rank, so that a checkpoint
/// resumes on any count of ranks; rounds up to this size are one batch, as before.
inline constexpr std::size_t kDemonstrationBatchBalls = 500;

/// Records `balls` balls (ball i plays ball_seed(seed, i)) on `threads`
/// threads; the result depends only on the seed. With `learner` null the
/// teacher plays (record_demonstration); otherwise the imitation controller of
/// that table plays and the teacher labels the approaches it reaches (DAgger:
/// the learner's own mistakes get the teacher's answer; record_correction in
/// the source). `progress` (may be empty) gets a line every tenth of the
/// balls, never from two threads at once. The balls are played in `worlds`
/// (null: every ball in the model of `board`, the belief). Throws
/// std::invalid_argument when the learner's lead is not `config`'s.
Demonstrations record_demonstrations(const table::Board& board, const DemonstrationConfig& config, int balls,
                                     std::uint64_t seed, int threads,
                                     const std::function<void(const std::string&)>& progress,
                                     const std::shared_ptr<const control::ShotTable>& learner = nullptr,
                                     const TeacherWorlds* worlds = nullptr);

/// Settings of learning by imitation.
struct ImitationLearningConfig {
  DemonstrationConfig demonstration;  ///< teacher, camera, delay, time limit
  control::ImitationConfig table;     ///< the learned table's lookup settings
  int rounds = 4;                     ///< round 0: the teacher plays; rounds 1..: the learner plays, the teacher labels
};

/// One round's figures (the player's own balls: the teacher's in round 0, the learner's after).
struct ImitationRound {
  int round = 0;
  int balls = 0;                 ///< balls played in the round
  std::size_t shots = 0;         ///< examples in the table after the round
  double mean_score = 0.0;       ///< the round's player, per ball
  double mean_ball_time_s = 0.0;
  int cut = 0;                   ///< balls alive at the time limit
  long fires = 0;
  long unmatched_fires = 0;
  double wall_s = 0.0;
};

/// The learned table and the rounds that made it.
struct ImitationResult {
  std::shared_ptr<const control::ShotTable> table;  ///< after the last round
  std::vector<ImitationRound> rounds;
};

/// Called when a learner's ball was alive at the time limit (a possible
/// cycle): the table that played it and that ball's score.
using ImitationCycleHandler = std::function<void(const control::ShotTable& table, double score)>;

/// Learns a shot table from the teacher in `config.rounds` rounds that share
/// `budget_balls` (the last round takes the remainder): the table after each
/// round is trained on every example so far (DAgger). Round r's balls are
/// ball_seed(ball_seed(seed, r), i). `on_cycle` (may be empty) hears of the
/// highest-scoring cut ball of each learner round that had one, at the end of
/// that round. `board` is the belief; balls play in `worlds` (null: the
/// model of `board`). Throws std::invalid_argument for fewer balls than
/// rounds, rounds < 1, or a table lead that is not the demonstrations'.
ImitationResult learn_by_imitation(const table::Board& board, const ImitationLearningConfig& config,
                                   std::uint64_t budget_balls, std::uint64_t seed, int threads,
                                   const std::function<void(const std::string&)>& progress,
                                   const ImitationCycleHandler& on_cycle = {}, const TeacherWorlds* worlds = nullptr);

/// The rounds as a learning curve (one row per round; see docs/learning.md)
/// for learn::write_curve_csv and plot_curve_png.
SearchResult imitation_curve(const ImitationResult& result);

}  // namespace pinball::learn
