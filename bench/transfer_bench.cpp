#include "transfer_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include "pinball/learn/planning_controller.h"
#include "pinball/control/spastic_controller.h"
#include "pinball/core/progress.h"
#include "pinball/core/rng.h"
#include "pinball/core/statistics.h"
#include "pinball/learn/evaluator.h"
#include "pinball/learn/parallel_runner.h"
#include "pinball/learn/team.h"
#include "pinball/sim/model_world.h"

namespace pinball::bench {

TransferBenchOptions quick_transfer_bench_options() {
  TransferBenchOptions o;
  o.balls = 5;
  o.twin_balls = 2;
  o.sweep = quick_transfer_sweep();
  return o;
}

TransferBall play_transfer_ball(sim::World& world, const WorldSettings& settings, const table::Board& belief,
                                const track::CameraModelConfig& belief_camera, const control::ControllerSpec* spec,
                                double max_ball_time_s, std::uint64_t ball_seed) {
  const std::unique_ptr<control::FlipperController> controller =
      spec != nullptr ? learn::make_controller(*spec, belief) : std::make_unique<control::SpasticController>();
  sim::GameState state = sim::make_game_state(world.board(), ball_seed);
  sim::BallLimits limits;
  limits.max_ball_time_s = max_ball_time_s;
  limits.pull = spec != nullptr ? spec->launcher_pull : -1.0;  // the spastic flipper: the board's, as learn plays it
  DrainWatch watch(state, drain_zones(belief));
  // The tracker believes the nominal camera: its σ is the calibrated one, whatever the real camera does.
  const sim::BallResult r =
      learn::play_through_tracker(world, belief, state, settings.camera,
                                  track::default_tracker_config(belief, belief_camera), *controller,
                                  settings.actuation_delay_s, limits, ball_seed, watch);
  TransferBall b;
  static_cast<PlayedBall&>(b) = played_ball(r, watch);
  return b;
}

std::string value_text(double v, bool sign) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), sign ? "%+g" : "%g", v);
  return buf;
}

void set_ratios_to_spastic(std::vector<TransferCell>& cells) {
  if (cells.empty()) return;
  const RunningStats spastic = cells.front().score;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    TransferCell& cell = cells[i];
    cell.ratio_to_spastic = spastic.mean() != 0.0 ? cell.score.mean() / spastic.mean() : 0.0;
    // The spastic flipper against its own games is 1 exactly: no interval.
    cell.ratio_interval = i == 0 ? std::nullopt : ratio_of_means_ci95(cell.score, spastic);
  }
}

std::vector<TransferSummary> transfer_summaries(const std::vector<TransferWorld>& worlds, double target_ratio) {
  std::vector<TransferSummary> out;
  std::vector<std::vector<double>> ratios;
  for (const TransferWorld& w : worlds) {
    if (!w.played) continue;
    for (std::size_t i = 1; i < w.cells.size(); ++i) {
      const TransferCell& c = w.cells[i];
      if (out.size() < i) {
        out.resize(i);
        ratios.resize(i);
        out[i - 1].controller = c.controller;
      }
      TransferSummary& s = out[i - 1];
      if (s.worlds == 0 || c.ratio_to_spastic < s.lowest_ratio) {
        s.lowest_ratio = c.ratio_to_spastic;
        s.lowest_world = w.name;
        s.lowest_interval = c.ratio_interval;
      }
      ++s.worlds;
      if (c.ratio_to_spastic >= target_ratio) ++s.worlds_at_target;
      if (c.ratio_interval && c.ratio_interval->high < target_ratio) ++s.worlds_below_target;
      ratios[i - 1].push_back(c.ratio_to_spastic);
    }
  }
  for (std::size_t i = 0; i < out.size(); ++i) out[i].median_ratio = median(ratios[i]);
  return out;
}

namespace {

// A world to play, with the board it borrows and its world-side settings.
struct PlannedWorld {
  TransferWorld row;
  WorldSettings settings;
  simlab::OwnedWorld world;  // empty when skipped
};

// Makes `w` a model world of its own settings' board on `stepper`, played with `balls` balls.
void play_model_world(PlannedWorld& w, sim::StepperKind stepper, int balls) {
  w.row.world = std::string(sim::stepper_kind_name(stepper));
  w.row.balls = balls;
  w.row.played = true;
  w.world.board = std::make_unique<const table::Board>(w.settings.board);
  sim::ModelWorldOptions options;
  options.stepper = stepper;
  w.world.world = sim::make_model_world(*w.world.board, options);
}

// The nominal worlds, then the sweep in order; a value equal to the nominal
// setting is the `model` world and is not played twice.
std::vector<PlannedWorld> plan_worlds(const table::Board& belief, const TransferBenchOptions& o) {
  WorldSettings nominal{belief, o.actuation_delay_s, o.camera};
  std::vector<PlannedWorld> out;
  const auto add_factory_world = [&](const std::string& name, const simlab::WorldSpec& spec) {
    PlannedWorld w{{}, nominal, {}};
    if (spec.kind == simlab::WorldKind::kTwin) w.settings.actuation_delay_s = o.twin_actuation_delay_s;
    w.row.name = name;
    w.row.family = "nominal";
    w.row.world = std::string(simlab::world_name(spec));
    w.row.balls = spec.kind == simlab::WorldKind::kTwin ? std::min(o.balls, o.twin_balls) : o.balls;
    try {
      w.world = simlab::make_world(spec, belief);
      w.row.played = true;
    } catch (const std::exception& e) {
      // The twin in a build without it, or one that refuses this board: a row that says why, never a stand-in.
      if (spec.kind != simlab::WorldKind::kTwin) throw;
      w.row.skipped_reason = e.what();
    }
    out.push_back(std::move(w));
  };
  add_factory_world("model", simlab::WorldSpec{});
  simlab::WorldSpec event;
  event.stepper = sim::StepperKind::kEvent;
  add_factory_world("event", event);
  simlab::WorldSpec twin;
  twin.kind = simlab::WorldKind::kTwin;
  twin.twin_params_path = o.twin_params_path;
  add_factory_world("twin", simlab::world_for_belief(twin, belief.source, o.identified));
  for (const SweepFamily& family : o.sweep) {
    for (const double v : family.values) {
      if (std::fabs(v - nominal_value(family.kind, o)) < 1e-9) continue;  // the model world
      PlannedWorld w{{}, perturb(nominal, family.kind, v), {}};
      w.row.family = std::string(perturbation_name(family.kind));
      w.row.name = w.row.family + "=" + value_text(v, is_offset(family.kind));
      w.row.value = v;
      play_model_world(w, sim::StepperKind::kThesis, o.balls);
      out.push_back(std::move(w));
    }
  }
  for (const CombinedWorld& c : o.combined) {
    PlannedWorld w{{}, nominal, {}};
    for (const auto& [kind, change] : c.changes) w.settings = perturb(w.settings, kind, nominal_value(kind, o) + change);
    w.row.family = "combined";
    w.row.name = c.name;
    play_model_world(w, c.stepper, o.balls);
    out.push_back(std::move(w));
  }
  return out;
}

// Shares one count of balls over every cell for the progress line, which
// names the world being played. The ETA goes world kind by world kind
// (thesis, event, twin): a twin ball costs many model balls, and one rate
// over every ball had the ETA far too short while the twin played and far
// too long after it.
class ProgressCount {
 public:
  // `balls_by_kind`: this rank's balls of each world to play, with the world's kind.
  ProgressCount(const std::function<void(const std::string&)>& progress,
                const std::vector<std::pair<std::string, long>>& balls_by_kind)
      : total_(std::max(1L, total_of(balls_by_kind))),
        count_(total_, total_ / 100, [this, &progress](long d, double elapsed_s) { report(progress, d, elapsed_s); }) {
    for (const auto& world : balls_by_kind) kind(world.first).total += static_cast<double>(world.second);
  }
  /// Before a world's balls (no ball in flight): the name the lines carry, and its kind's clock.
  void start_world(const std::string& world, const std::string& kind) {
    close_world();
    world_ = world;
    kind_ = kind;
    world_start_done_ = count_.done();
    world_start_s_ = elapsed_s();
  }
  void ball_done() { count_.one_done(); }

 private:
  static long total_of(const std::vector<std::pair<std::string, long>>& balls_by_kind) {
    long total = 0;
    for (const auto& entry : balls_by_kind) total += entry.second;
    return total;
  }
  double elapsed_s() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  // The world just played, into its kind's figures.
  void close_world() {
    if (kind_.empty()) return;
    KindProgress& k = kind(kind_);
    k.done += static_cast<double>(count_.done() - world_start_done_);
    k.wall_s += elapsed_s() - world_start_s_;
  }
  // The kind's figures, made on first use (the constructor's) in the order the worlds come.
  KindProgress& kind(const std::string& name) {
    auto it = std::find_if(kinds_.begin(), kinds_.end(), [&](const auto& k) { return k.first == name; });
    if (it == kinds_.end()) it = kinds_.insert(kinds_.end(), {name, KindProgress{}});
    return it->second;
  }
  // Under the count's lock; kinds_ changes only between worlds, with no ball in flight.
  void report(const std::function<void(const std::string&)>& progress, long done, double elapsed) {
    if (!progress) return;
    std::vector<KindProgress> now;
    now.reserve(kinds_.size());
    for (const auto& [name, k] : kinds_) {
      KindProgress p = k;
      if (name == kind_) {
        p.done += static_cast<double>(done - world_start_done_);
        p.wall_s += elapsed - world_start_s_;
      }
      now.push_back(p);
    }
    const double eta_s = eta_by_kind_s(now, done > 0 ? elapsed / static_cast<double>(done) : 0.0);
    // "transfer: 4000/116000 balls (3 %), 40 s elapsed, ETA 19 min 10 s; gravity_pct=+10"
    progress(format_progress("transfer", static_cast<double>(done), static_cast<double>(total_), "balls", elapsed,
                             world_, 0.0, eta_s));
  }

  long total_;
  std::vector<std::pair<std::string, KindProgress>> kinds_;
  std::string world_;
  std::string kind_;
  long world_start_done_ = 0;
  double world_start_s_ = 0.0;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  SharedProgress count_;
};

// Plays every controller's balls in one world, across the job.
void play_world(PlannedWorld& w, const table::Board& belief, const TransferBenchOptions& o,
                const std::vector<TransferController>& players, ProgressCount& progress) {
  const auto balls = static_cast<std::size_t>(w.row.balls);
  const auto start = std::chrono::steady_clock::now();
  progress.start_world(w.row.name, w.row.world);
  const std::vector<learn::Blob> blobs = learn::distributed_map(players.size() * balls, o.threads, [&](std::size_t i) {
    const auto ball_start = std::chrono::steady_clock::now();
    const std::unique_ptr<sim::World> ball_world = w.world->fork();
    TransferBall b = play_transfer_ball(*ball_world, w.settings, belief, o.camera, players[i / balls].spec,
                                        o.max_ball_time_s, ball_seed(o.seed, i % balls));
    b.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - ball_start).count();
    progress.ball_done();
    learn::BlobWriter out;
    put_played_ball(out, b);
    out.put(b.wall_s);
    return out.take();
  });
  w.row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const DrainZones zones = drain_zones(belief);
  for (std::size_t c = 0; c < players.size(); ++c) {
    TransferCell cell;
    cell.controller = players[c].name;
    for (std::size_t i = 0; i < balls; ++i) {
      learn::BlobReader r(blobs[c * balls + i]);
      TransferBall b;
      get_played_ball(r, b);
      b.wall_s = r.get<double>();
      r.expect_end();
      cell.score.add(b.score);
      cell.duration_s.add(b.duration_s);
      cell.flips.add(b.flips);
      cell.wall_s += b.wall_s;
      if (b.cut) {
        ++cell.cut;
      } else {
        const DrainCause cause = classify_drain(zones, b.drain_x_m);
        cell.drains.add(cause, b.left_table);
        const bool outlane = cause == DrainCause::kLeftOutlane || cause == DrainCause::kRightOutlane;
        if (outlane && !std::isnan(b.drain_after_flipper_s)) cell.outlane_after_flipper_s.add(b.drain_after_flipper_s);
      }
    }
    w.row.cells.push_back(cell);
  }
  set_ratios_to_spastic(w.row.cells);
  w.row.world_warnings = w.world->warnings();
}

void check_options(const TransferBenchOptions& o) {
  if (o.balls < 1) throw std::invalid_argument("transfer bench: balls must be >= 1");
  if (o.twin_balls < 1) throw std::invalid_argument("transfer bench: twin balls must be >= 1");
  if (o.threads < 1) throw std::invalid_argument("transfer bench: threads must be >= 1");
  if (!(o.max_ball_time_s > 0.0)) throw std::invalid_argument("transfer bench: max ball time must be > 0");
  if (!(o.target_ratio > 0.0) || !std::isfinite(o.target_ratio))
    throw std::invalid_argument("transfer bench: target ratio must be finite and > 0");
  for (const TransferController& c : o.controllers) {
    if (c.spec == nullptr) throw std::invalid_argument("transfer bench: controller " + c.name + " has no spec");
    if (c.name == "spastic") throw std::invalid_argument("transfer bench: 'spastic' names the baseline; rename " + c.file);
    // A per-ball random pull is the evaluator's (PinballEvaluator::play); this bench plays a fixed pull.
    if (c.spec->randomise_launch) {
      throw std::invalid_argument("transfer bench: " + c.file + " draws its launch pull at random; the bench plays "
                                  "every controller at a fixed pull");
    }
    for (const TransferController& d : o.controllers) {
      if (&c != &d && c.name == d.name) throw std::invalid_argument("transfer bench: two controllers named " + c.name);
    }
  }
}

}  // namespace

TransferReport run_transfer_bench(const table::Board& belief, const TransferBenchOptions& options,
                                  const std::function<void(const std::string&)>& progress) {
  check_options(options);
  const auto start = std::chrono::steady_clock::now();
  std::vector<TransferController> players{{"spastic", "", nullptr}};
  players.insert(players.end(), options.controllers.begin(), options.controllers.end());
  std::vector<PlannedWorld> worlds = plan_worlds(belief, options);
  // Progress counts this rank's share of the job (learn::distributed_map deals balls to the ranks).
  std::vector<std::pair<std::string, long>> balls_by_kind;
  for (const PlannedWorld& w : worlds) {
    if (w.row.played) {
      balls_by_kind.emplace_back(w.row.world, w.row.balls * static_cast<long>(players.size()) / learn::team_size());
    }
  }
  ProgressCount count(progress, balls_by_kind);
  TransferReport report;
  report.board = belief.source;
  report.options = options;
  for (PlannedWorld& w : worlds) {
    if (w.row.played) play_world(w, belief, options, players, count);
    report.worlds.push_back(std::move(w.row));
  }
  report.sensitivities = transfer_sensitivities(report.worlds, options);
  report.summaries = transfer_summaries(report.worlds, options.target_ratio);
  report.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace pinball::bench
