// `pinball learn BOARD --method ...`: searches for a flipper controller on the
// fast learning loop (docs/learning.md), writes it, its learning curve and a
// plot; or evaluates a baseline or a controller file on fresh balls.

#include <csignal>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <iterator>
#include <sstream>
#include <memory>
#include <array>
#include <ostream>
#include <thread>
#include <stdexcept>

#include <nlohmann/json.hpp>
#include <unistd.h>

#include "camera_options.h"
#include "data_file.h"
#include "flag_uses.h"
#include "commands.h"
#include "progress_option.h"
#include "world_options.h"
#include "pinball/control/controller_file.h"
#include "pinball/control/imitation_controller.h"
#include "pinball/core/json_text.h"
#include "pinball/core/number_option.h"
#include "pinball/learn/demonstrations.h"
#include "pinball/learn/shot_value_collection.h"
#include "pinball/learn/shot_values.h"
#include <functional>
#include <optional>
#include "pinball/control/spastic_controller.h"
#include "pinball/core/format.h"
#include "pinball/core/json_write_archive.h"
#include "pinball/core/progress.h"
#include "pinball/core/running_stats.h"
#include "pinball/learn/checkpoint.h"
#include "pinball/learn/cross_entropy.h"
#include "pinball/learn/evaluator.h"
#include "pinball/learn/launcher_search.h"
#include "pinball/learn/learning_curve.h"
#include "pinball/learn/parallel_runner.h"
#include "pinball/learn/randomized_evaluator.h"
#include "pinball/learn/relay_race.h"
#include "pinball/learn/team.h"
#include "pinball/learn/tournament.h"
#include "pinball/plot/png_file.h"
#include "pinball/table/board_overlay.h"

namespace pinball::cli {

CLI::App* add_learn_command(CLI::App& app, LearnArgs& a) {
  CLI::App* cmd = app.add_subcommand("learn", "learn a flipper controller on the fast loop (or evaluate one)");
  cmd->add_option("board", a.board, "board file (docs/board-format.md)")->required()->transform(data_file());
  add_identified_option(*cmd, a.identified);
  cmd->add_option("--randomize", a.randomize,
                  "searches and imitate (teacher and learner): play each ball in a world drawn from this file's ranges (g, wall "
                  "rho, flipper mu, pivots, delay, camera latency and noise, stepper) while the controller believes "
                  "the board (docs/learning.md); the final evaluation plays the board itself")
      ->transform(data_file());
  cmd->add_option("--shot-values", a.shot_values,
                  "imitate: the teacher values each plan at its shot by this table of what shots are worth "
                  "(learn/shot_values.h, docs/learning.md) rather than by the branch played past it")
      ->transform(data_file());
  cmd->add_option("--drain-penalty", a.drain_penalty,
                  "imitate (its teacher) and shot-values (its player, and so the table's values): the points a plan "
                  "loses when the ball drains in it")
      ->check(finite_range(0.0, 1e9))
      ->default_str(format_number(learn::LookaheadConfig{}.drain_penalty));
  cmd->add_option("--method", a.method,
                  "tournament (thesis 6.2), relay (Hoeffding relay race, 6.3), cem (cross-entropy with common "
                  "random numbers and sequential halving); or no search: none, spastic, evaluate (--controller); "
                  "launcher: the launcher controller's search (20 pulls x 10 launches, thesis 5.1); shot-values: what "
                  "shots are worth in the belief, for a planner's or imitate's --shot-values (--budget-balls balls, --out)")
      ->required()
      ->check(CLI::IsMember({"tournament", "relay", "cem", "imitate", "none", "spastic", "evaluate", "launcher", "shot-values"}));
  cmd->add_option("--budget-balls", a.budget_balls, "simulated balls the search may play")
      ->check(finite_range(std::uint64_t{1}, std::uint64_t{1'000'000'000}));
  cmd->add_option("--seed", a.seed, "random seed; same seed, same result, whatever --threads")
      ->check(unsigned_64());
  cmd->add_option("--out", a.out, "controller file to write (JSON, docs/learning.md)")->check(output_file());
  cmd->add_option("--controller", a.controller, "evaluate: the controller file")->transform(data_file());
  cmd->add_option("--threads", a.threads, "worker threads")->check(finite_range(1, 256));
  cmd->add_option("--curve", a.curve, "write the learning curve to this CSV")->check(output_file());
  cmd->add_option("--plot", a.plot, "draw the learning curve to this PNG")->check(output_file());
  cmd->add_option("--eval-balls", a.eval_balls,
                  "evaluate the result on this many fresh balls (default: 0 after a search, 1000 otherwise)")
      ->check(finite_range(0, 10'000'000))
      ->default_str("");  // -1: by method
  cmd->add_option("--partitions", a.partitions, "k: impact-angle partitions per flipper (uniform)")
      ->check(finite_range(1, 64));
  cmd->add_flag("--partition-h", a.partition_by_h, "also partition by h (pivot-to-tip | tip-to-V-centre)");
  cmd->add_flag("--rolling", a.rolling, "a separate minicontroller for a ball rolling on each flipper");
  cmd->add_flag("--lead", a.lead,
                "searches and imitate: the controller acts on each projection advanced by the frame's camera latency "
                "plus --actuation-delay, to when its coil acts (docs/learning.md, \"Lead\"); written into the "
                "controller");
  cmd->add_flag("--randomise-launch", a.randomise_launch, "draw the launcher pull per ball from [0.5, 1]");
  cmd->add_option("--pull", a.pull, "launcher pull fraction (default: the board's)")
      ->check(finite_range(0.01, 1.0))
      ->default_str("");  // -1: the board's
  cmd->add_option("--balls-per-controller", a.balls_per_controller, "tournament: balls per controller (b)")
      ->check(finite_range(1, 100000));
  cmd->add_option("--population", a.population, "relay / cem: population size (default 20 / 16)")
      ->check(finite_range(2, 100000))
      ->default_str("");  // 0: the method's
  cmd->add_option("--rounds", a.rounds,
                  "imitate: rounds sharing the budget; round 1 the teacher plays, later rounds the learner plays "
                  "and the teacher labels its approaches (DAgger)")
      ->check(finite_range(1, 1000));
  cmd->add_option("--max-ball-time", a.max_ball_time_s, "seconds after which a ball is cut (a cycle)")
      ->check(finite_positive());
  cmd->add_option("--loss-penalty", a.loss_penalty,
                  "points taken from a flip opportunity that lost the ball (6.3.1)")
      ->check(finite_non_negative());
  cmd->add_option_function<double>(
         "--actuation-delay",
         [&a](const double& v) {
           a.actuation_delay_s = v;
           a.actuation_delay_given = true;
         },
         "command to flipper motion (s); default: in a model world the --identified overlay's (its flippers' rise "
         "delay) when it has one, else the firmware's 0.004")
      ->check(finite_range(0.0, 0.5));
  cmd->add_option("--gravity-scale", a.gravity_scale, "tracker's g over the board's (miscalibration)")
      ->check(finite_range(0.1, 10.0));
  add_camera_model_options(*cmd, a.camera);
  add_world_options(*cmd, a.world);
  add_progress_flag(*cmd, a.progress);
  cmd->add_option("--checkpoint", a.checkpoint,
                  "record every batch of balls in this file as the run goes, so that a run cut short resumes "
                  "(--resume) with the result of an uninterrupted one")
      ->check(output_file());
  cmd->add_flag("--resume", a.resume, "continue the run recorded in --checkpoint (the same command and seed)")
      ->needs("--checkpoint");
  cmd->add_flag("--json", a.json, "print one JSON object instead of text");
  record_flags_given(cmd, a.flags_given);
  return cmd;
}

namespace {

// No flipping.
struct IdleController final : control::FlipperController {
  void update(const track::TrackerOutput&, double, std::array<bool, 2>&) override {}
  void reset(std::array<bool, 2>& e) override { e = {false, false}; }
};

// One controller on fresh balls: the "evaluation" object of --json, written
// from Serialize() so that each key is spelled once (scripts read these keys).
struct Evaluation {
  std::int64_t balls = 0;              // balls played
  double mean_score_per_ball = 0.0;
  double score_ci95_half_width = 0.0;  // of the mean score, 95 %
  double score_stddev = 0.0;
  double mean_ball_time_s = 0.0;       // simulated (s)
  double flips_per_ball = 0.0;
  int balls_cut_at_time_limit = 0;
  double wall_s = 0.0;
  double balls_per_s = 0.0;            // over the wall clock; NaN (null) when --checkpoint held every ball

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(balls));
    a->Visit(PINBALL_NVP(mean_score_per_ball));
    a->Visit(PINBALL_NVP(score_ci95_half_width));
    a->Visit(PINBALL_NVP(score_stddev));
    a->Visit(PINBALL_NVP(mean_ball_time_s));
    a->Visit(PINBALL_NVP(flips_per_ball));
    a->Visit(PINBALL_NVP(balls_cut_at_time_limit));
    a->Visit(PINBALL_NVP(wall_s));
    a->Visit(PINBALL_NVP(balls_per_s));
  }
};

// An evaluation's balls gathered (and checkpointed) at a time; fixed, so that a checkpoint
// resumes on any count of ranks. Evaluations up to this size are one batch, as before.
constexpr std::size_t kEvaluationBatchBalls = 10000;

// Plays `balls` fresh balls (seeds apart from any search's) with one controller.
Evaluation evaluate(const learn::PinballEvaluator& ev, const LearnArgs& a, const control::ControllerSpec* spec,
                    const std::function<std::unique_ptr<control::FlipperController>()>& make_controller, int balls,
                    std::ostream& err) {
  const auto start = std::chrono::steady_clock::now();
  // Percent and ETA: a planner's thousand balls take minutes (this rank's share, under MPI).
  ProgressMeter meter(progress_wanted(a.progress) ? &err : nullptr, "learn evaluation", balls, "balls",
                      !a.progress && progress_wanted(false));
  SharedProgress balls_done(balls, 1, [&](long d, double) { meter.update(static_cast<double>(d)); });
  RunningStats score, duration_s, flips;
  Evaluation e;
  const std::uint64_t replayed_before = learn::checkpoint_status().replayed_items;
  // Batches of kEvaluationBatchBalls: memory for one batch's outcomes, however many balls.
  learn::distributed_batches(
      static_cast<std::size_t>(balls), kEvaluationBatchBalls, a.threads,
      [&](std::size_t i) {
        const std::uint64_t seed = ball_seed(a.seed ^ 0xE7A1E7A1E7A1E7A1ull, i);
        learn::Blob blob;
        if (spec != nullptr) {
          blob = learn::to_blob(ev.play(*spec, seed));
        } else {  // a controller that is no action function (a baseline, the imitation table)
          const std::unique_ptr<control::FlipperController> c = make_controller();
          blob = learn::to_blob(ev.play_with(*c, a.pull, seed));
        }
        balls_done.one_done();
        return blob;
      },
      [&](std::size_t, std::vector<learn::Blob>& blobs) {
        for (const learn::Blob& b : blobs) {
          const learn::BallOutcome o = learn::ball_outcome_from_blob(b);
          score.add(o.score);
          duration_s.add(o.duration_s);
          flips.add(o.flips);
          e.balls_cut_at_time_limit += o.cut ? 1 : 0;
        }
      });
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  e.balls = score.count();
  e.mean_score_per_ball = score.mean();
  e.score_ci95_half_width = score.ci95_half_width();
  e.score_stddev = score.stddev();
  e.mean_ball_time_s = duration_s.mean();
  e.flips_per_ball = flips.mean();
  e.wall_s = wall;
  // Balls taken from a checkpoint took no time: the rate is the job's played balls over the wall,
  // and none when the checkpoint held every ball.
  const auto played = static_cast<double>(e.balls) -
                      static_cast<double>(learn::checkpoint_status().replayed_items - replayed_before);
  e.balls_per_s = played > 0.0 && wall > 0.0 ? played / wall : std::numeric_limits<double>::quiet_NaN();
  return e;
}

// FNV-1a of a file's bytes ("missing" when it cannot be read), so that a
// checkpoint is not resumed against an edited board.
std::string file_digest(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "missing";
  std::uint64_t h = 1469598103934665603ull;
  for (std::istreambuf_iterator<char> it(in), end; it != end; ++it) h = (h ^ static_cast<unsigned char>(*it)) * 1099511628211ull;
  std::ostringstream s;
  s << std::hex << h;
  return s.str();
}

// What makes two runs the same run: every option that changes a result, and
// the bytes of every file read. Not --threads, the ranks, --out/--curve/--plot,
// --json or --progress: results do not depend on them.
std::string run_fingerprint(const LearnArgs& a) {
  nlohmann::json j = {
      {"method", a.method}, {"board", a.board}, {"board_fnv1a", file_digest(a.board)},
      {"world_board", a.world.board_path},
      {"world_board_fnv1a", a.world.board_path.empty() ? "" : file_digest(a.world.board_path)},
      {"stepper", std::string(sim::stepper_kind_name(a.world.stepper))}, {"world_dt_s", a.world.dt_s},
      {"world", std::string(simlab::world_kind_name(a.world.kind))},
      {"twin_params_fnv1a", a.world.kind != simlab::WorldKind::kTwin ? ""
                            : file_digest(a.world.twin_params_path.empty() ? simlab::default_twin_params_path()
                                                                           : a.world.twin_params_path)},
      {"controller", a.controller}, {"controller_fnv1a", a.controller.empty() ? "" : file_digest(a.controller)},
      {"budget_balls", a.budget_balls}, {"seed", a.seed}, {"eval_balls", a.eval_balls},
      {"partitions", a.partitions}, {"partition_h", a.partition_by_h}, {"rolling", a.rolling},
      {"randomise_launch", a.randomise_launch}, {"pull", a.pull}, {"balls_per_controller", a.balls_per_controller},
      {"population", a.population}, {"rounds", a.rounds}, {"max_ball_time_s", a.max_ball_time_s},
      {"loss_penalty", a.loss_penalty}, {"actuation_delay_s", a.actuation_delay_s},
      {"gravity_scale", a.gravity_scale},
      {"camera", to_json_value(a.camera)}};
  if (a.lead) j["lead"] = true;  // likewise
  if (!a.randomize.empty()) {  // likewise
    j["randomize"] = a.randomize;
    j["randomize_fnv1a"] = file_digest(a.randomize);
  }
  if (a.drain_penalty >= 0.0) j["drain_penalty"] = a.drain_penalty;  // likewise
  if (!a.shot_values.empty()) {  // likewise
    j["shot_values"] = a.shot_values;
    j["shot_values_fnv1a"] = file_digest(a.shot_values);
  }
  if (!a.identified.empty()) {  // only then: a checkpoint of a run without an overlay still resumes
    j["identified"] = a.identified;
    j["identified_fnv1a"] = file_digest(a.identified);
  }
  return "pinball learn " + json_text(j);
}

// The job's figures for the report: ranks, and what gathering cost.
nlohmann::json team_report() {
  const learn::TeamCounters c = learn::team_counters();
  const learn::CheckpointStatus k = learn::checkpoint_status();
  nlohmann::json j = {{"ranks", learn::team_size()},
                      {"mpi_wait_s", c.wait_s},
                      {"mpi_comm_s", c.comm_s},
                      {"mpi_bytes_received", c.bytes},
                      {"mpi_batches", c.batches}};
  if (k.open) {
    j["checkpoint"] = {{"batches_in_file", k.batches_in_file}, {"replayed", k.replayed}, {"recorded", k.recorded},
                       {"dropped_bytes", k.dropped_bytes}};
  }
  return j;
}

// What --randomize drew: the file and every world's values.
nlohmann::json randomization_report(const std::string& file, const std::vector<learn::DrawnWorld>& worlds) {
  nlohmann::json drawn = nlohmann::json::array();
  for (const learn::DrawnWorld& w : worlds) {
    nlohmann::json values = nlohmann::json::object();
    for (const auto& [p, v] : w.values) values[std::string(learn::perturbation_name(p))] = v;
    drawn.push_back({{"stepper", sim::stepper_kind_name(w.stepper)}, {"values", values}});
  }
  return {{"file", file}, {"worlds", drawn}};
}

// Closes the checkpoint however the run ends.
struct CheckpointScope {
  explicit CheckpointScope(const learn::CheckpointOptions& o) { learn::open_checkpoint(o); }
  ~CheckpointScope() { learn::close_checkpoint(); }
  CheckpointScope(const CheckpointScope&) = delete;
  CheckpointScope& operator=(const CheckpointScope&) = delete;
};

// A run stopped by SIGINT, SIGTERM or SIGHUP says what it keeps, then dies of
// the signal as it would have: the checkpoint's finished batches and how to go
// on, or that nothing is kept. The text is made before the handlers go in; the
// handler only writes it (async-signal-safe).
class InterruptNote {
 public:
  explicit InterruptNote(std::string text) {
    text_ = std::move(text);
    struct sigaction on{};
    on.sa_handler = &InterruptNote::on_signal;
    sigemptyset(&on.sa_mask);
    for (std::size_t i = 0; i < kSignals.size(); ++i) {
      sigaction(kSignals[i], &on, &previous_[i]);
      // An ignored signal stays ignored (a background job's SIGINT, nohup's SIGHUP).
      if (previous_[i].sa_handler == SIG_IGN) sigaction(kSignals[i], &previous_[i], nullptr);
    }
  }
  ~InterruptNote() {
    for (std::size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &previous_[i], nullptr);
  }
  InterruptNote(const InterruptNote&) = delete;
  InterruptNote& operator=(const InterruptNote&) = delete;

 private:
  static constexpr std::array<int, 3> kSignals{SIGINT, SIGTERM, SIGHUP};
  static void on_signal(int sig) {
    if (!text_.empty()) (void)!::write(STDERR_FILENO, text_.data(), text_.size());
    std::signal(sig, SIG_DFL);
    std::raise(sig);
  }
  static inline std::string text_;
  std::array<struct sigaction, kSignals.size()> previous_{};
};

// What an interrupted run keeps (rank 0 says it; the others say nothing).
std::string interrupt_text(const LearnArgs& a, bool writer) {
  if (!writer) return "";
  if (a.checkpoint.empty()) {
    return "\nlearn: interrupted; nothing is kept (--checkpoint FILE records a run as it goes, and --resume goes on "
           "from it)\n";
  }
  return "\nlearn: interrupted; " + a.checkpoint +
         " keeps every batch of balls finished so far: the same command with "
         "--resume goes on from there\n";
}

}  // namespace

int run_launcher_search(const LearnArgs& a, std::ostream& out, std::ostream& err) {
  // Thesis 5.1: 20 pull values x 10 launches; keep the one most often hittable.
  const table::Board board = table::load_belief_board(a.board, a.identified);
  const simlab::WorldSpec world_spec = simlab::world_for_belief(a.world, a.board, a.identified);
  const simlab::OwnedWorld world = simlab::make_world(world_spec, board);
  learn::LauncherSearchConfig config;
  config.seed = a.seed;
  config.camera = a.camera;
  err << "learn launcher: " << config.pulls << " pulls x " << config.launches_per_pull << " launches\n";
  const learn::LauncherSearchResult r = learn::search_launcher(board, config, world.world.get());
  nlohmann::json tried = nlohmann::json::array();
  for (std::size_t i = 0; i < r.pull.size(); ++i) {
    tried.push_back({{"pull", r.pull[i]}, {"hittable", r.successes[i]}});
  }
  if (a.json) {
    nlohmann::json j = {{"board", a.board},
                        {"method", "launcher"},
                        {"seed", a.seed},
                        {"launches_per_pull", config.launches_per_pull},
                        {"best_pull", r.best_pull},
                        {"best_hittable", r.best_successes},
                        {"pulls", tried}};
    j.update(identified_report(a.identified));
    out << json_text(j, 2) << "\n";
    return 0;
  }
  out << "launcher search on " << a.board << " (seed " << a.seed << "): pull -> launches reaching a hittable state\n"
      << identified_text_line(a.identified);
  for (std::size_t i = 0; i < r.pull.size(); ++i) {
    out << "  " << r.pull[i] << "  " << r.successes[i] << "/" << config.launches_per_pull << "\n";
  }
  out << "best pull " << r.best_pull << " (" << r.best_successes << "/" << config.launches_per_pull << ")\n";
  return 0;
}

// Gathers what shots are worth in the belief's model (learn/shot_value_collection.h)
// and writes the table a planner's or imitate's teacher values its plans by.
int run_shot_values(const LearnArgs& a, std::ostream& out, std::ostream& err) {
  if (a.out.empty()) throw std::invalid_argument("learn: --method shot-values needs --out TABLE");
  const simlab::WorldSpec world_spec = simlab::world_for_belief(a.world, a.board, a.identified);
  if (world_spec.kind != simlab::WorldKind::kModel || !world_spec.board_path.empty() || !a.randomize.empty()) {
    throw std::invalid_argument("learn: --method shot-values plays the belief's own model; not --world twin, "
                                "--world-board or --randomize");
  }
  const table::Board board = table::load_belief_board(a.board, a.identified);
  learn::ShotValueCollectionConfig config;
  config.actuation_delay_s = a.actuation_delay_s;
  config.max_ball_time_s = a.max_ball_time_s;
  config.pull = a.pull;
  if (a.drain_penalty >= 0.0) config.player.drain_penalty = a.drain_penalty;
  const auto start = std::chrono::steady_clock::now();
  const learn::ShotValueTable table = learn::collect_shot_values(
      board, config, static_cast<int>(a.budget_balls), a.seed, a.threads, [&](const std::string& line) {
        if (progress_wanted(a.progress)) err << "learn " << line << "\n";
      });
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (learn::team_root()) learn::write_shot_value_table(table, a.out);
  int valued_bins = 0;
  for (const double v : table.smoothed) valued_bins += std::isnan(v) ? 0 : 1;
  if (a.json) {
    nlohmann::json j = {{"board", a.board},         {"method", "shot-values"},
                        {"seed", a.seed},           {"balls", a.budget_balls},
                        {"out", a.out},             {"shots", learn::shots_in(table)},
                        {"valued_bins", valued_bins}, {"bins", table.smoothed.size()},
                        {"horizon_s", config.player.horizon_s}, {"drain_penalty", config.player.drain_penalty},
                        {"actuation_delay_s", config.actuation_delay_s},
                        {"max_ball_time_s", config.max_ball_time_s}, {"wall_s", wall_s}};
    j.update(identified_report(a.identified));
    out << json_text(j, 2) << "\n";
    return 0;
  }
  out << "shot values on " << a.board << " (seed " << a.seed << ", " << a.budget_balls << " balls of the looking-ahead "
      << "player on the true state): " << learn::shots_in(table) << " shots, " << valued_bins << " of "
      << table.smoothed.size() << " bins valued, " << format_duration(wall_s) << "\n"
      << identified_text_line(a.identified) << "written to " << a.out << "\n";
  return 0;
}

namespace {

// Which methods read each flag that not every method reads: an option a method
// would drop is refused, not ignored (`--method evaluate --curve c.csv` wrote
// nothing and said nothing; `--method launcher --randomize R` searched the board).
const std::vector<FlagUse>& learn_flag_uses() {
  static const std::vector<FlagUse> uses = {
      {{"--balls-per-controller"}, {"tournament"}},
      {{"--population"}, {"relay", "cem"}},
      {{"--rounds"}, {"imitate"}},
      {{"--controller"}, {"evaluate"}},
      {{"--shot-values"}, {"imitate"}},
      {{"--drain-penalty"}, {"imitate", "shot-values"}},
      {{"--curve", "--plot", "--randomize", "--lead", "--partitions", "--partition-h", "--rolling",
        "--randomise-launch"},
       {"tournament", "relay", "cem", "imitate"}},
      {{"--budget-balls"}, {"tournament", "relay", "cem", "imitate", "shot-values"}},
      {{"--eval-balls"}, {"tournament", "relay", "cem", "imitate", "none", "spastic", "evaluate"}},
      {{"--threads", "--max-ball-time", "--actuation-delay"},
       {"tournament", "relay", "cem", "imitate", "none", "spastic", "evaluate", "shot-values"}},
      // evaluate plays the controller file's own launch; only the relay credits an opportunity that lost the ball
      {{"--pull"}, {"tournament", "relay", "cem", "imitate", "none", "spastic", "shot-values"}},
      {{"--loss-penalty"}, {"relay"}},
  };
  return uses;
}

}  // namespace

int run_learn(const LearnArgs& args, std::ostream& out, std::ostream& err) {
  const auto start = std::chrono::steady_clock::now();
  // What is written at the end can be written: a typo must not cost an hour's search.
  check_output_folder(args.out, "--out");
  check_output_folder(args.curve, "--curve");
  check_output_folder(args.checkpoint, "--checkpoint");  // a missing folder had said only "cannot create it"
  check_png_output(args.plot, "--plot");
  const std::string cycle_path = args.out.empty() ? std::string() : args.out + ".cycle.json";
  check_output_folder(cycle_path, "--out's cycle file");
  check_distinct_outputs({{"--out", args.out},
                          {"--curve", args.curve},
                          {"--plot", args.plot},
                          {"--checkpoint", args.checkpoint},
                          {"--out's cycle file", cycle_path}});
  // A learned controller written over its board, or a curve over the controller: found too late, after the run.
  check_outputs_replace_no_input({{"--out", args.out},
                                  {"--curve", args.curve},
                                  {"--plot", args.plot},
                                  {"--checkpoint", args.checkpoint},
                                  {"--out's cycle file", cycle_path}},
                                 {{"board", args.board},
                                  {"--identified", args.identified},
                                  {"--randomize", args.randomize},
                                  {"--shot-values", args.shot_values},
                                  {"--controller", args.controller},
                                  {"--world-board", args.world.board_path},
                                  {"--twin-params", args.world.twin_params_path}});
  LearnArgs a = args;
  a.actuation_delay_s = world_actuation_delay_s(
      args.actuation_delay_given ? std::optional<double>(args.actuation_delay_s) : std::nullopt, args.world,
      args.identified);
  // Options a method does not read are refused, not ignored: launcher prints its pulls and
  // writes nothing; shot-values writes its table, with no curve and no checkpoint.
  if (a.method == "launcher" || a.method == "shot-values") {
    const std::vector<std::pair<const char*, std::string>> unread =
        a.method == "launcher"
            ? std::vector<std::pair<const char*, std::string>>{{"--out", a.out},
                                                               {"--curve", a.curve},
                                                               {"--plot", a.plot},
                                                               {"--checkpoint", a.checkpoint}}
            : std::vector<std::pair<const char*, std::string>>{
                  {"--curve", a.curve}, {"--plot", a.plot}, {"--checkpoint", a.checkpoint}};
    for (const auto& [option, value] : unread) {
      if (!value.empty()) throw std::invalid_argument("learn: --method " + a.method + " does not read " + option);
    }
  }
  refuse_flags_not_read(a.flags_given, learn_flag_uses(), "learn", a.method);
  if (a.method == "launcher") return run_launcher_search(a, out, err);
  if (a.method == "shot-values") return run_shot_values(a, out, err);
  const bool search = a.method == "tournament" || a.method == "relay" || a.method == "cem";
  if ((search || a.method == "imitate") && a.out.empty()) {
    throw std::invalid_argument("learn: --out CONTROLLER is required for a search");
  }
  if (a.method == "evaluate" && a.controller.empty()) throw std::invalid_argument("learn: evaluate needs --controller FILE");
  // Methods that only play: an option they would drop is refused, not ignored.
  if (a.method == "evaluate" || a.method == "none" || a.method == "spastic") {
    if (!a.out.empty()) {
      throw std::invalid_argument("learn: --method " + a.method +
                                  " writes no controller (--out is for tournament, relay, cem, imitate and "
                                  "shot-values)");
    }
    if (a.eval_balls == 0) {
      throw std::invalid_argument("learn: --eval-balls 0 leaves --method " + a.method +
                                  " nothing to do: it plays fresh balls and reports them");
    }
  }
  const table::Board board = table::load_belief_board(a.board, a.identified);
  const simlab::WorldSpec world_spec = simlab::world_for_belief(a.world, a.board, a.identified);
  const simlab::OwnedWorld world = simlab::make_world(world_spec, board);
  // What a learned controller's note says it was learned on.
  const std::string belief_args = a.board + (a.identified.empty() ? "" : " --identified " + a.identified) +
                                  (a.randomize.empty() ? "" : " --randomize " + a.randomize) + (a.lead ? " --lead" : "");
  learn::EvaluatorConfig ec;
  ec.camera = a.camera;
  ec.actuation_delay_s = a.actuation_delay_s;
  ec.max_ball_time_s = a.max_ball_time_s;
  ec.loss_penalty = a.loss_penalty;
  ec.gravity_scale = a.gravity_scale;
  ec.angle_partitions = a.partitions;
  ec.partition_by_h = a.partition_by_h;
  ec.rolling_minicontrollers = a.rolling;

  // The prototype carries the launcher settings into every candidate.
  if (!a.randomize.empty()) {
    if (world_spec.kind != simlab::WorldKind::kModel || !world_spec.board_path.empty())
      throw std::invalid_argument("learn: --randomize draws its worlds around the belief's model; it cannot be "
                                  "combined with --world twin or --world-board");
  }
  // With --randomize the search plays the drawn worlds; the final evaluation
  // (objective.ev) plays the belief's own world, the home world.
  struct Objective final : learn::BallObjective {
    Objective(const table::Board& b, const learn::EvaluatorConfig& c, const sim::World& w, const LearnArgs& args)
        : ev(b, c, w.fork()), la(args) {
      if (!args.randomize.empty() && args.method != "imitate")  // imitate draws its own (learn::TeacherWorlds)
        randomized = std::make_unique<learn::RandomizedEvaluator>(b, c, learn::load_randomization(args.randomize));
    }
    learn::BallOutcome play(const control::ControllerSpec& s, std::uint64_t seed) const override {
      return randomized ? randomized->play(s, seed) : ev.play(s, seed);
    }
    control::ControllerSpec prototype() const override {
      control::ControllerSpec s = ev.prototype();
      if (la.lead) s.actuator.lead_actuation_delay_s = la.actuation_delay_s;
      s.launcher_pull = la.pull;
      s.randomise_launch = la.randomise_launch;
      return s;
    }
    learn::PinballEvaluator ev;
    std::unique_ptr<learn::RandomizedEvaluator> randomized;
    const LearnArgs& la;
  } objective(board, ec, *world, a);

  const CheckpointScope checkpoint(learn::CheckpointOptions{a.checkpoint, a.resume, run_fingerprint(a)});
  // Every rank runs the whole command; rank 0 alone writes files.
  const bool writer = learn::team_root();
  const InterruptNote interrupt_note(interrupt_text(a, writer));

  nlohmann::json j = {{"board", a.board},
                      {"method", a.method},
                      {"seed", a.seed},
                      {"threads", a.threads}};
  j.update(identified_report(a.identified));
  if (objective.randomized) j["randomize"] = randomization_report(a.randomize, objective.randomized->worlds());
  if (search || a.method == "imitate") j["lead"] = a.lead;
  control::ControllerSpec result_spec;
  const control::ControllerSpec* eval_spec = nullptr;
  if (search) {
    learn::SearchConfig sc;
    sc.budget_balls = a.budget_balls;
    sc.seed = a.seed;
    sc.threads = a.threads;
    sc.progress = progress_wanted(a.progress) ? &err : nullptr;
    double cycle_score = -1e300;  // keep the highest-scoring cycle (a stuck ball scores little)
    sc.on_cycle = [&](const control::ControllerSpec& spec, const learn::BallOutcome& o) {
      if (o.score <= cycle_score) return;
      cycle_score = o.score;
      control::ControllerSpec s = spec;
      s.note = "cycle found by pinball learn --method " + a.method + " --seed " + std::to_string(a.seed) +
               ": ball alive at the time limit with score " + std::to_string(o.score);
      if (writer) control::save_controller(s, cycle_path);
      err << "learn: cycle controller saved to " << cycle_path << "\n";
    };
    learn::SearchResult r;
    const std::uint64_t replayed_before = learn::checkpoint_status().replayed_items;
    if (a.method == "tournament") {
      learn::TournamentConfig t;
      t.balls_per_controller = a.balls_per_controller;
      r = learn::run_tournament(objective, sc, t);
    } else if (a.method == "relay") {
      learn::RelayConfig rc;
      if (a.population > 0) rc.population = a.population;
      r = learn::run_relay_race(objective, sc, rc);
    } else {
      learn::CrossEntropyConfig cc;
      if (a.population > 0) cc.population = a.population;
      r = learn::run_cross_entropy(objective, sc, cc);
    }
    if (r.generations == 0) {
      // The seed search alone spent the budget: the "best" is an untrained prototype.
      throw std::runtime_error("learn: --budget-balls " + std::to_string(a.budget_balls) +
                               " ran out before the first " + a.method + " generation (" +
                               std::to_string(r.balls_used) + " balls played; a generation needs " +
                               std::to_string(r.generation_balls) +
                               " left after the seed search); no controller written");
    }
    result_spec = r.best;
    result_spec.note = "pinball learn " + belief_args + " --method " + a.method + " --budget-balls " +
                       std::to_string(a.budget_balls) + " --seed " + std::to_string(a.seed) + " --partitions " +
                       std::to_string(a.partitions) + "; estimated mean " + std::to_string(r.best_mean) + " over " +
                       std::to_string(r.best_balls) + " balls";
    if (writer) {
      control::save_controller(result_spec, a.out);
      if (!a.curve.empty()) learn::write_curve_csv(r, a.curve);
      if (!a.plot.empty()) plot::write_png(learn::draw_curve(r), a.plot);
    }
    eval_spec = &result_spec;
    nlohmann::json counters = nlohmann::json::object();
    for (const auto& [name, v] : r.counters) counters[name] = v;
    j["budget_balls"] = a.budget_balls;
    j["balls_used"] = r.balls_used;
    j["generations"] = r.generations;
    j["best_estimated_mean"] = r.best_mean;
    j["best_estimated_balls"] = r.best_balls;
    j["search_wall_s"] = r.wall_s;
    // Balls taken from a checkpoint took no time: the rate is of the balls played (it had said 88 balls/s for 62).
    const double played = static_cast<double>(r.balls_used) -
                          static_cast<double>(learn::checkpoint_status().replayed_items - replayed_before);
    j["search_balls_per_s"] = played > 0.0 && r.wall_s > 0 ? nlohmann::json(played / r.wall_s) : nlohmann::json();
    j["cycle_found"] = r.cycle_found;
    j["counters"] = counters;
    j["out"] = a.out;
  } else if (a.method == "evaluate") {
    result_spec = control::load_controller(a.controller);
    control::check_controller_launch(result_spec, board, a.controller);
    eval_spec = &result_spec;
    j["controller"] = a.controller;
  } else if (a.method == "imitate") {
    learn::ImitationLearningConfig ic;
    ic.demonstration.camera = a.camera;
    ic.demonstration.actuation_delay_s = a.actuation_delay_s;
    ic.demonstration.max_ball_time_s = a.max_ball_time_s;
    ic.demonstration.pull = a.pull;
    ic.rounds = a.rounds;
    if (a.drain_penalty >= 0.0) ic.demonstration.teacher.drain_penalty = a.drain_penalty;
    j["teacher_drain_penalty"] = ic.demonstration.teacher.drain_penalty;
    if (!a.shot_values.empty()) {
      ic.demonstration.teacher.shot_values =
          std::make_shared<const learn::ShotValueTable>(learn::read_shot_value_table(a.shot_values));
      j["shot_values"] = a.shot_values;
    }
    if (a.lead) {  // the shots are keyed on the led projection the table will look up
      ic.table.lead_actuation_delay_s = a.actuation_delay_s;
      ic.demonstration.lead_actuation_delay_s = a.actuation_delay_s;
    }
    // With --randomize each ball plays a drawn world and the teacher plans in
    // it; the final evaluation plays the belief's own world, as a search's does.
    const learn::TeacherWorlds teacher_worlds =
        a.randomize.empty() ? learn::TeacherWorlds(board, world.world.get())
                            : learn::TeacherWorlds(board, learn::draw_worlds(board, ec, learn::load_randomization(a.randomize)),
                                                   ec.dt_s);
    if (!teacher_worlds.drawn().empty()) j["randomize"] = randomization_report(a.randomize, teacher_worlds.drawn());
    double cycle_score = -1e300;  // keep the highest-scoring cycle, as the searches do
    const learn::ImitationResult im = learn::learn_by_imitation(
        board, ic, a.budget_balls, a.seed, a.threads,
        [&](const std::string& line) {
          if (progress_wanted(a.progress)) err << "learn imitate: " << line << "\n";
        },
        [&](const control::ShotTable& table, double score) {
          if (score <= cycle_score) return;
          cycle_score = score;
          control::ControllerSpec s = objective.prototype();
          s.shot_table = std::make_shared<const control::ShotTable>(table);
          s.note = "cycle found by pinball learn --method imitate --seed " + std::to_string(a.seed) +
                   ": ball alive at the time limit with score " + std::to_string(score);
          if (writer) control::save_controller(s, cycle_path);
          err << "learn: cycle controller saved to " << cycle_path << "\n";
        },
        &teacher_worlds);
    const learn::SearchResult curve = learn::imitation_curve(im);
    j["cycle_found"] = curve.cycle_found;
    j["balls_used"] = curve.balls_used;
    result_spec = objective.prototype();
    result_spec.shot_table = im.table;
    nlohmann::json rounds = nlohmann::json::array();
    for (const learn::ImitationRound& r : im.rounds) {
      rounds.push_back({{"round", r.round + 1}, {"player", r.round == 0 ? "teacher" : "learner"}, {"balls", r.balls},
                        {"examples", r.shots}, {"mean_score_per_ball", r.mean_score},
                        {"mean_ball_time_s", r.mean_ball_time_s}, {"balls_cut_at_time_limit", r.cut}, {"fires", r.fires},
                        {"unmatched_fires", r.unmatched_fires}, {"wall_s", r.wall_s}});
    }
    j["rounds"] = rounds;
    j["budget_balls"] = a.budget_balls;
    result_spec.note = "pinball learn " + belief_args + " --method imitate --budget-balls " + std::to_string(a.budget_balls) +
                       " --rounds " + std::to_string(a.rounds) + " --seed " + std::to_string(a.seed) + ": " +
                       std::to_string(im.table->examples().size()) +
                       " shots of a looking-ahead teacher on the true state";
    // The controller first, as the searches write it: a curve that fails must not cost it.
    if (writer) control::save_controller(result_spec, a.out);
    if (writer && !a.curve.empty()) learn::write_curve_csv(curve, a.curve);
    if (writer && !a.plot.empty()) plot::write_png(learn::draw_curve(curve), a.plot);
    eval_spec = &result_spec;
    j["out"] = a.out;
  }
  std::function<std::unique_ptr<control::FlipperController>()> make_controller = [&]() -> std::unique_ptr<control::FlipperController> {
    if (a.method == "spastic") return std::make_unique<control::SpasticController>();
    return std::make_unique<IdleController>();
  };
  const int eval_balls = a.eval_balls >= 0 ? a.eval_balls : (search ? 0 : 1000);
  if (eval_balls > 0) {
    const Evaluation e = evaluate(objective.ev, a, eval_spec, make_controller, eval_balls, err);
    j["evaluation"] = to_json_value(e);
    j["evaluation"]["camera_noise_px"] = a.camera.noise_px;
    j["evaluation"]["actuation_delay_s"] = a.actuation_delay_s;
    j["evaluation"]["gravity_scale"] = a.gravity_scale;
  }
  j["team"] = team_report();
  j.update(world_report(world_spec, a.board, *world.world));
  j["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (a.json) {
    out << json_text(j, 2) << "\n";
  } else {
    out << "learn " << a.method << " on " << a.board << " (seed " << a.seed << ", " << a.threads << " threads";
    if (learn::team_size() > 1) out << " on each of " << learn::team_size() << " MPI ranks";
    out << ")\n" << identified_text_line(a.identified);
    if (!a.world.board_path.empty() || j["world"] != "thesis") out << world_text_line(j);
    auto num = [](const nlohmann::json& x, int digits = 3) { return format_number(x.get<double>(), digits); };
    if (search) {
      out << "balls used       " << j["balls_used"] << " of " << a.budget_balls << " in " << j["generations"]
          << " generations, "
          << (j["search_balls_per_s"].is_null() ? std::string("every ball from the checkpoint")
                                                 : num(j["search_balls_per_s"]) + " balls/s")
          << "\n"
          << "best estimate    " << num(j["best_estimated_mean"], 4) << " over " << j["best_estimated_balls"]
          << " balls\n"
          << "cycle found      " << (j["cycle_found"].get<bool>() ? "yes" : "no") << "\n"
          << "controller       " << a.out << "\n";
    }
    if (j.contains("rounds")) {
      for (const auto& r : j["rounds"]) {
        out << "round " << r["round"].get<int>() << " (" << r["player"].get<std::string>() << ")  "
            << r["balls"] << " balls, " << num(r["mean_score_per_ball"], 4) << " per ball, " << r["examples"]
            << " shots so far, " << num(r["wall_s"]) << " s\n";
      }
      out << "cycle found      " << (j["cycle_found"].get<bool>() ? "yes" : "no") << "\n"
          << "controller       " << a.out << "\n";
    }
    const auto& team = j["team"];
    if (learn::team_size() > 1) {
      out << "MPI ranks        " << team["ranks"] << ", results gathered in " << team["mpi_batches"] << " batches: "
          << num(team["mpi_comm_s"]) << " s moving them, " << num(team["mpi_wait_s"]) << " s waiting for the slowest rank\n";
    }
    if (team.contains("checkpoint")) {
      const auto& k = team["checkpoint"];
      out << "checkpoint       " << a.checkpoint << ": " << k["replayed"] << " batches taken from it, " << k["recorded"]
          << " played and added\n";
    }
    if (j.contains("evaluation")) {
      const auto& e = j["evaluation"];
      out << "evaluation       " << e["balls"] << " fresh balls: "
          << format_mean_ci(e["mean_score_per_ball"].get<double>(), e["score_ci95_half_width"].get<double>())
          << " per ball (95 %), " << num(e["mean_ball_time_s"]) << " s per ball, " << num(e["flips_per_ball"])
          << " flips per ball, "
          << (e["balls_per_s"].is_number() && std::isfinite(e["balls_per_s"].get<double>())
                  ? num(e["balls_per_s"]) + " balls/s\n"
                  : std::string("every ball from the checkpoint\n"));
      // A score of balls cut at the limit is a score of the limit (0 for --max-ball-time 0.001): said.
      if (e["balls_cut_at_time_limit"].get<int>() > 0) {
        out << "                 " << e["balls_cut_at_time_limit"] << " of " << e["balls"]
            << " balls cut at --max-ball-time " << format_number(a.max_ball_time_s) << " s\n";
      }
    }
  }
  return 0;
}

}  // namespace pinball::cli
