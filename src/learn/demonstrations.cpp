#include "pinball/learn/demonstrations.h"

#include <array>
#include <chrono>
#include <optional>
#include <stdexcept>

#include "pinball/core/progress.h"
#include "pinball/simlab/simulated_player.h"
#include "pinball/learn/evaluator.h"
#include "pinball/learn/parallel_runner.h"
#include "pinball/learn/team.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/sim/model_world.h"

namespace pinball::learn {

namespace {

// Watches the tracker and books one example per approach; never moves a flipper itself.
class ShotRecorder final : public control::FlipperController {
 public:
  // `lead_actuation_delay_s`: the examples hold the projection a table with this lead looks up.
  ShotRecorder(std::vector<control::ShotExample>& out, std::optional<double> lead_actuation_delay_s)
      : out_(out), lead_actuation_delay_s_(lead_actuation_delay_s) {}

  void update(const track::TrackerOutput& o, double now_s, std::array<bool, 2>&) override {
    if (o.launch.launched || o.launch.lost) {
      close();
      return;
    }
    const track::TrajectoryProjection p = control::projection_to_act_on(o, lead_actuation_delay_s_);
    if (p.valid && p.hittable) {
      open_ = true;
      last_ = p;
      last_time_s_ = now_s;
    }
  }
  void reset(std::array<bool, 2>&) override { close(); }

  // The approach is open, not yet labelled, and the tracker projected a
  // hittable impact in this very frame (a controller can act on it now).
  bool can_label(double now_s) const { return open_ && !fired_ && last_time_s_ == now_s; }
  // The latest projection.
  const track::TrajectoryProjection& projection() const { return last_; }

  // The teacher fires `flipper` (tracker index) now, or would once the ball
  // has come `lead_m` closer: an example if a controller could act in this
  // frame. Returns false when it could not (nothing is recorded).
  bool teacher_fired(int flipper, double hold_s, double now_s, double lead_m = 0.0) {
    if (open_ && fired_ && last_time_s_ == now_s) return true;  // a second flip in one approach: the first is the shot
    if (!can_label(now_s)) return false;
    out_.push_back(example(flipper, last_.d_m - lead_m, hold_s));
    fired_ = true;
    return true;
  }
  // The teacher would let the ball pass: the approach's example is a pass.
  void teacher_passes(double now_s) {
    if (!can_label(now_s)) return;
    out_.push_back(example(-1, 0.0, 0.0));
    fired_ = true;
  }
  // Label this approach no more (the learner acted where the teacher cannot judge).
  void give_up() { fired_ = true; }
  void close() {
    if (open_ && !fired_) out_.push_back(example(-1, 0.0, 0.0));
    open_ = false;
    fired_ = false;
  }

 private:
  control::ShotExample example(int fired_flipper, double d_m, double hold_s) const {
    return {last_.flipper, last_.rolling, last_.angle_rad, last_.h, last_.speed_mps, fired_flipper, d_m, hold_s};
  }

  std::vector<control::ShotExample>& out_;
  std::optional<double> lead_actuation_delay_s_;
  bool open_ = false;
  bool fired_ = false;  // labelled (fired or passed) in this approach
  track::TrajectoryProjection last_;
  double last_time_s_ = -1.0;
};

// Passes tracker updates to the learner, which acts, and to the recorder, which watches.
class Tee final : public control::FlipperController {
 public:
  Tee(control::FlipperController& acts, control::FlipperController& watches) : acts_(acts), watches_(watches) {}
  void update(const track::TrackerOutput& o, double now_s, std::array<bool, 2>& energized) override {
    watches_.update(o, now_s, energized);
    acts_.update(o, now_s, energized);
  }
  void reset(std::array<bool, 2>& energized) override {
    watches_.reset(energized);
    acts_.reset(energized);
  }

 private:
  control::FlipperController& acts_;
  control::FlipperController& watches_;
};

// Board flipper index -> tracker flipper index.
std::array<int, 2> tracker_index_of(const simlab::SimulatedPlayer& watcher) {
  std::array<int, 2> index{};
  index[static_cast<std::size_t>(watcher.board_index(track::kRightFlipper))] = track::kRightFlipper;
  index[static_cast<std::size_t>(watcher.board_index(track::kLeftFlipper))] = track::kLeftFlipper;
  return index;
}

// The ball is over: book the open approach and the ball's figures.
void finish(DemonstrationBall& ball, ShotRecorder& recorder, const sim::BallResult& r) {
  recorder.close();
  ball.score = r.score;
  ball.duration_s = r.duration_s;
  ball.cut = r.cut;
}

// The camera model and tracker that watch a ball: the world's camera, the
// belief's table and believed camera; the same seeds as the evaluator's, so
// the examples see what a controller would.
simlab::SimulatedPlayer make_watcher(const table::Board& belief, const DemonstrationConfig& config,
                                     control::FlipperController& controller, std::uint64_t seed) {
  return simlab::SimulatedPlayer(belief, config.world_camera.value_or(config.camera),
                                 track::default_tracker_config(belief, config.camera), controller, camera_seed(seed));
}

sim::BallLimits limits_of(const DemonstrationConfig& config) {
  sim::BallLimits limits;
  limits.max_ball_time_s = config.max_ball_time_s;
  limits.pull = config.pull;
  return limits;
}

// The learner plays; at each camera frame of an unlabelled approach the
// teacher judges the true state: "fire now" labels the approach with this
// frame's d; if the learner fires first, the teacher's best plan from that
// frame labels it (fire k frames later: d less the ball's travel; no fire: a pass).
DemonstrationBall record_correction(const table::Board& belief, sim::World& world, const sim::ThesisStepper& model,
                                    const DemonstrationConfig& config,
                                    const std::shared_ptr<const control::ShotTable>& learner_table,
                                    std::uint64_t seed) {
  DemonstrationBall ball;
  ShotRecorder recorder(ball.shots, config.lead_actuation_delay_s);
  control::ImitationController learner(learner_table);
  Tee tee(learner, recorder);
  simlab::SimulatedPlayer watcher = make_watcher(belief, config, tee, seed);
  LookaheadPlanner teacher(model, config.teacher);
  const double frame_s = model.dt_s() * config.teacher.frame_steps;
  simlab::DelayLine delay(belief.flippers.size(), config.actuation_delay_s);
  const std::array<int, 2> track_index = tracker_index_of(watcher);
  sim::GameState state = sim::make_game_state(world.board(), seed);
  bool held = false;  // a learner's flipper was commanded up before this step
  const sim::BallResult r = sim::play_ball(
      world, state, limits_of(config),
      [&](sim::GameState& s) {
        const std::uint64_t before = watcher.observations();
        const long fires_before = learner.fires();
        watcher.act(s);
        const bool learner_fired = learner.fires() != fires_before;
        if (learner_fired) ++ball.teacher_fires;
        if (watcher.observations() != before && !held && recorder.can_label(s.time_s)) {
          const int f = teacher.decision_flipper(s);
          if (f >= 0) {
            const std::vector<LookaheadCandidate>& c = teacher.evaluate(s, delay, f);
            const LookaheadCandidate& best = c[teacher.best()];
            const int tf = track_index[static_cast<std::size_t>(f)];
            if (best.fire_frame == 0) {
              recorder.teacher_fired(tf, best.hold_frames * frame_s, s.time_s);
            } else if (learner_fired && best.fire_frame > 0) {
              const double lead_m = recorder.projection().speed_mps * best.fire_frame * frame_s;
              recorder.teacher_fired(tf, best.hold_frames * frame_s, s.time_s, lead_m);
            } else if (learner_fired) {
              recorder.teacher_passes(s.time_s);
            }
          } else if (learner_fired) {
            ++ball.unmatched_fires;  // fired outside the teacher's zone: no judgement
            recorder.give_up();
          }
        }
        held = s.flippers[0].energized || s.flippers[1].energized;
        delay.apply(s);
      },
      [](const sim::GameState&, const sim::StepEvents&) {});
  finish(ball, recorder, r);
  return ball;
}

}  // namespace

DemonstrationBall record_demonstration(const table::Board& belief, sim::World& world, const sim::ThesisStepper& model,
                                       const DemonstrationConfig& config, std::uint64_t seed) {
  DemonstrationBall ball;
  ShotRecorder recorder(ball.shots, config.lead_actuation_delay_s);
  simlab::SimulatedPlayer watcher = make_watcher(belief, config, recorder, seed);
  LookaheadPlayer teacher(model, config.teacher, config.actuation_delay_s);
  const std::array<int, 2> track_index = tracker_index_of(watcher);
  sim::GameState state = sim::make_game_state(world.board(), seed);
  const sim::BallResult r = sim::play_ball(
      world, state, limits_of(config),
      [&](sim::GameState& s) {
        const std::uint64_t before = watcher.observations();
        watcher.act(s);
        // The teacher decides at the camera's frames, when a controller can.
        teacher.act(s, watcher.observations() != before);
        const int f = teacher.fired_flipper();
        if (f < 0) return;
        ++ball.teacher_fires;
        if (!recorder.teacher_fired(track_index[static_cast<std::size_t>(f)], teacher.fired_hold_s(), s.time_s)) {
          ++ball.unmatched_fires;
        }
      },
      [](const sim::GameState&, const sim::StepEvents&) {});
  finish(ball, recorder, r);
  return ball;
}

TeacherWorlds::TeacherWorlds(const table::Board& belief, const sim::World* world) : belief_(belief) {
  Place home;
  home.world = world != nullptr ? world->fork() : sim::make_model_world(belief);
  sim::check_same_flippers(home.world->board(), belief);
  home.teacher_model = std::make_unique<sim::ThesisStepper>(belief);
  places_.push_back(std::move(home));
}

TeacherWorlds::TeacherWorlds(const table::Board& belief, std::vector<DrawnWorld> drawn, double dt_s)
    : belief_(belief), drawn_(std::move(drawn)) {
  if (drawn_.empty()) throw std::invalid_argument("teacher worlds: no drawn world");
  for (const DrawnWorld& w : drawn_) {
    Place p;
    sim::ModelWorldOptions options;
    options.stepper = w.stepper;
    options.dt_s = dt_s;
    p.world = sim::make_model_world(w.settings.board, options);
    sim::check_same_flippers(p.world->board(), belief);
    sim::ThesisStepperOptions model_options;
    model_options.dt_s = dt_s;
    p.teacher_model = std::make_unique<sim::ThesisStepper>(w.settings.board, model_options);
    p.actuation_delay_s = w.settings.actuation_delay_s;
    p.camera = w.settings.camera;
    places_.push_back(std::move(p));
  }
}

const TeacherWorlds::Place& TeacherWorlds::place_of(std::uint64_t ball_seed) const {
  return drawn_.empty() ? places_.front() : places_[drawn_world_index(ball_seed, places_.size())];
}

Blob to_blob(const DemonstrationBall& b) {
  BlobWriter w;
  // A shot field by field: the struct's padding is no part of it.
  w.put<std::uint64_t>(b.shots.size());
  for (const control::ShotExample& e : b.shots) {
    w.put(e.flipper).put(e.rolling).put(e.angle_rad).put(e.h).put(e.speed_mps).put(e.fired_flipper).put(e.d_fire_m)
        .put(e.hold_s);
  }
  w.put(b.score).put(b.duration_s).put(b.cut).put(b.teacher_fires).put(b.unmatched_fires);
  return w.take();
}

DemonstrationBall demonstration_ball_from_blob(const Blob& blob) {
  BlobReader r(blob);
  DemonstrationBall b;
  const auto shots = r.get<std::uint64_t>();
  if (shots > blob.size()) throw std::runtime_error("blob: more shots than bytes");
  b.shots.resize(static_cast<std::size_t>(shots));
  for (control::ShotExample& e : b.shots) {
    e.flipper = r.get<int>();
    e.rolling = r.get<bool>();
    e.angle_rad = r.get<double>();
    e.h = r.get<double>();
    e.speed_mps = r.get<double>();
    e.fired_flipper = r.get<int>();
    e.d_fire_m = r.get<double>();
    e.hold_s = r.get<double>();
  }
  b.score = r.get<double>();
  b.duration_s = r.get<double>();
  b.cut = r.get<bool>();
  b.teacher_fires = r.get<int>();
  b.unmatched_fires = r.get<int>();
  r.expect_end();
  return b;
}

Demonstrations record_demonstrations(const table::Board& board, const DemonstrationConfig& config, int balls,
                                     std::uint64_t seed, int threads,
                                     const std::function<void(const std::string&)>& progress,
                                     const std::shared_ptr<const control::ShotTable>& learner,
                                     const TeacherWorlds* worlds) {
  if (balls < 1) throw std::invalid_argument("demonstrations: balls must be >= 1");
  if (board.flippers.size() != 2) throw std::invalid_argument("demonstrations: the board needs exactly two flippers");
  if (worlds != nullptr && &worlds->belief() != &board)
    throw std::invalid_argument("demonstrations: the worlds must watch with the board given");
  if (learner != nullptr && learner->config().lead_actuation_delay_s != config.lead_actuation_delay_s)
    throw std::invalid_argument("demonstrations: the learner's lead must be the one the shots are keyed with");
  std::optional<TeacherWorlds> home;  // the belief's own model
  if (worlds == nullptr) worlds = &home.emplace(board, nullptr);
  const auto n = static_cast<std::size_t>(balls);
  const auto start = std::chrono::steady_clock::now();
  // Across the job: each rank plays its share (progress counts this rank's balls).
  const int share = std::max<int>(1, balls / team_size());
  // "teacher: 30/300 balls (10 %), 41 s elapsed, ETA 6 min 09 s" (the round's ETA).
  SharedProgress balls_done(share, share / 10, [&](long d, double elapsed_s) {
    if (!progress) return;
    progress(format_progress(learner != nullptr ? "learner, teacher judging" : "teacher", static_cast<double>(d),
                             static_cast<double>(share), "balls", elapsed_s,
                             team_size() > 1 ? "this rank's share" : ""));
  });
  Demonstrations out;
  out.balls = balls;
  double score = 0.0;
  double time = 0.0;
  auto take = [&](std::size_t, std::vector<Blob>& blobs) {
    for (const Blob& blob : blobs) {
      const DemonstrationBall b = demonstration_ball_from_blob(blob);
      out.shots.insert(out.shots.end(), b.shots.begin(), b.shots.end());
      score += b.score;
      time += b.duration_s;
      out.cut += b.cut ? 1 : 0;
      if (b.cut) out.best_cut_score = std::max(out.best_cut_score, b.score);
      out.teacher_fires += b.teacher_fires;
      out.unmatched_fires += b.unmatched_fires;
    }
  };
  // Batches of kDemonstrationBatchBalls: memory for one batch, however large the round.
  distributed_batches(n, kDemonstrationBatchBalls, threads, [&](std::size_t i) {
    const std::uint64_t b = ball_seed(seed, i);
    const TeacherWorlds::Place& place = worlds->place_of(b);
    DemonstrationConfig c = config;  // the world's own delay and camera, when it has them
    if (place.actuation_delay_s) c.actuation_delay_s = *place.actuation_delay_s;
    if (place.camera) c.world_camera = place.camera;
    const std::unique_ptr<sim::World> ball_world = place.world->fork();
    const DemonstrationBall ball = learner != nullptr
                                       ? record_correction(board, *ball_world, *place.teacher_model, c, learner, b)
                                       : record_demonstration(board, *ball_world, *place.teacher_model, c, b);
    balls_done.one_done();
    return to_blob(ball);
  }, take);
  out.mean_teacher_score = score / balls;
  out.mean_ball_time_s = time / balls;
  out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

ImitationResult learn_by_imitation(const table::Board& board, const ImitationLearningConfig& config,
                                   std::uint64_t budget_balls, std::uint64_t seed, int threads,
                                   const std::function<void(const std::string&)>& progress,
                                   const ImitationCycleHandler& on_cycle, const TeacherWorlds* worlds) {
  if (config.rounds < 1) throw std::invalid_argument("imitation: rounds must be >= 1");
  if (config.table.lead_actuation_delay_s != config.demonstration.lead_actuation_delay_s)
    throw std::invalid_argument("imitation: the table's lead must be the one its demonstrations are keyed with");
  if (budget_balls < static_cast<std::uint64_t>(config.rounds)) {
    throw std::invalid_argument("imitation: a budget of " + std::to_string(budget_balls) + " balls (--budget-balls) "
                                "cannot give each of " + std::to_string(config.rounds) + " rounds (--rounds) a ball");
  }
  ImitationResult result;
  std::vector<control::ShotExample> shots;
  const std::uint64_t per_round = budget_balls / static_cast<std::uint64_t>(config.rounds);
  for (int r = 0; r < config.rounds; ++r) {
    const std::uint64_t balls = r + 1 == config.rounds ? budget_balls - per_round * static_cast<std::uint64_t>(r)
                                                       : per_round;
    const Demonstrations d =
        record_demonstrations(board, config.demonstration, static_cast<int>(balls),
                              ball_seed(seed, static_cast<std::uint64_t>(r)), threads,
                              [&](const std::string& line) {
                                if (progress) progress("round " + std::to_string(r + 1) + "/" +
                                                       std::to_string(config.rounds) + ": " + line);
                              },
                              r == 0 ? nullptr : result.table, worlds);
    if (r > 0 && d.cut > 0 && on_cycle) on_cycle(*result.table, d.best_cut_score);  // the table that played it
    shots.insert(shots.end(), d.shots.begin(), d.shots.end());
    result.table = std::make_shared<const control::ShotTable>(shots, config.table);
    result.rounds.push_back({r, d.balls, shots.size(), d.mean_teacher_score, d.mean_ball_time_s, d.cut,
                             d.teacher_fires, d.unmatched_fires, d.wall_s});
    if (progress) {
      progress("round " + std::to_string(r + 1) + ": " + (r == 0 ? "teacher " : "learner ") +
               std::to_string(d.mean_teacher_score) + " per ball over " + std::to_string(d.balls) + " balls; " +
               std::to_string(shots.size()) + " examples");
    }
  }
  // A table of no shots never flips, and no controller file holds one (controller_file.cpp).
  if (shots.empty()) {
    throw std::runtime_error("imitation: the teacher fired no shot in " + std::to_string(budget_balls) +
                             (budget_balls == 1 ? " ball" : " balls") +
                             " (did every ball end before it reached a flipper? see --max-ball-time); "
                             "no controller written");
  }
  return result;
}

SearchResult imitation_curve(const ImitationResult& result) {
  SearchResult s;
  s.method = "imitate";
  double wall = 0.0;
  double best = 0.0;
  for (const ImitationRound& r : result.rounds) {
    s.balls_used += static_cast<std::uint64_t>(r.balls);
    wall += r.wall_s;
    if (r.round > 0) best = std::max(best, r.mean_score);  // learners only: the teacher is no controller
    s.curve.push_back({r.round + 1, s.balls_used, r.mean_score, r.mean_score, best, wall});
    s.cycle_found = s.cycle_found || (r.round > 0 && r.cut > 0);
  }
  s.generations = static_cast<int>(result.rounds.size());
  s.best_mean = best;
  s.wall_s = wall;
  return s;
}

}  // namespace pinball::learn
