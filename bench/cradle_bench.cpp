#include "cradle_bench.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "pinball/core/format.h"
#include "pinball/core/progress.h"
#include "pinball/core/rng.h"
#include "pinball/core/running_stats.h"
#include "pinball/learn/parallel_runner.h"
#include "pinball/sim/ball_runner.h"

namespace pinball::bench {

namespace {

constexpr double kTenMinutes_s = 600.0;
constexpr double kShareAtTenMinutes = 0.01;  // the target: 1 % of balls

// The cradle player and its bookkeeping: policy() before each step,
// observe() after it.
class CradlePlayer {
 public:
  CradlePlayer(const table::Board& board, double drop_s, const CradleBenchOptions& o)
      : o_(o), drop_s_(drop_s), left_y_m_(drain_zones(board).line_y_m + o.left_height_m) {}

  void policy(sim::GameState& s) const {
    for (std::size_t i = 0; i < s.flippers.size(); ++i) {
      s.flippers[i].energized = !(static_cast<int>(i) == dropped_ && s.time_s < raise_at_s_);
    }
  }

  void observe(const sim::GameState& s) {
    if (dropped_ >= 0 && s.time_s >= raise_at_s_) dropped_ = -1;
    if (s.ball.position_m.y() > left_y_m_) left_bats_ = true;
    const int bat = cradling_bat(s);
    if (bat < 0) {
      still_since_s_ = -1.0;
      return;
    }
    if (still_since_s_ < 0.0) still_since_s_ = s.time_s;
    if (s.time_s - still_since_s_ < o_.rest_s) return;
    // Cradled: settle the last drop's outcome, then drop the bat again.
    ball_.cradled = true;
    if (pending_ && left_bats_) {
      ++ball_.returns;
      ball_.cycle_time_s += s.time_s - last_cradle_s_;
      ball_.cycle_points += s.score - last_cradle_score_;
      last_return_s_ = s.time_s;
    } else if (pending_) {
      ++ball_.duds;
      if (bat != last_dropped_) {  // rolled or hopped across to the other bat: a pass
        ++ball_.passes;
        last_pass_s_ = s.time_s;
      }
    }
    last_cradle_s_ = s.time_s;
    last_cradle_score_ = s.score;
    dropped_ = bat;
    last_dropped_ = bat;
    raise_at_s_ = s.time_s + drop_s_;
    pending_ = true;
    left_bats_ = false;
    still_since_s_ = -1.0;
  }

  CradleBall finish(const sim::BallResult& r, DrainCause drain) {
    ball_.ball_time_s = r.duration_s;
    ball_.score = r.score;
    ball_.cut = r.cut;
    ball_.cycling_at_cut = r.cut && ball_.returns > 0 && r.duration_s - (last_return_s_ - start_s_) <= o_.cycling_gap_s;
    ball_.passing_at_cut = r.cut && ball_.passes > 0 && r.duration_s - (last_pass_s_ - start_s_) <= o_.cycling_gap_s;
    if (!r.cut && pending_) {  // lost after a drop: the cycle broke
      ball_.lost_after_drop = true;
      ball_.drain = drain;
    }
    ball_.shots = ball_.returns + (ball_.lost_after_drop ? 1 : 0);
    return ball_;
  }

  void start(double t_s) { start_s_ = t_s; }

 private:
  // The raised bat the ball lies still on, or -1.
  int cradling_bat(const sim::GameState& s) const {
    if (s.ball.velocity_mps.norm() >= o_.still_speed_mps) return -1;
    for (std::size_t i = 0; i < s.flippers.size(); ++i) {
      if (s.flippers[i].energized && s.flippers[i].ball_contact && static_cast<int>(i) != dropped_) {
        return static_cast<int>(i);
      }
    }
    return -1;
  }

  const CradleBenchOptions& o_;
  double drop_s_;
  double left_y_m_;
  CradleBall ball_;
  int dropped_ = -1;
  int last_dropped_ = -1;  // the bat of the latest drop, still known once it is raised
  double raise_at_s_ = 0.0;
  double still_since_s_ = -1.0;
  double last_cradle_s_ = 0.0;
  double last_cradle_score_ = 0.0;
  double last_return_s_ = 0.0;
  double last_pass_s_ = 0.0;
  double start_s_ = 0.0;
  bool left_bats_ = false;
  bool pending_ = false;  // a drop whose outcome is not known yet
};

void check_options(const CradleBenchOptions& o) {
  if (o.balls < 1) throw std::invalid_argument("bench cradle: balls must be at least 1");
  if (!(o.drop_from_s > 0.0) || !(o.drop_to_s >= o.drop_from_s) || !(o.drop_step_s > 0.0)) {
    throw std::invalid_argument("bench cradle: the drop durations need 0 < from <= to and a step > 0 (got " +
                                format_number(o.drop_from_s) + " to " + format_number(o.drop_to_s) + " by " +
                                format_number(o.drop_step_s) + " s)");
  }
  if ((o.drop_to_s - o.drop_from_s) / o.drop_step_s > 1000.0) {
    throw std::invalid_argument("bench cradle: over 1000 drop durations; take a larger step");
  }
  if (!(o.rest_s > 0.0) || !(o.max_ball_time_s > 0.0) || !(o.left_height_m > 0.0) || !(o.still_speed_mps > 0.0)) {
    throw std::invalid_argument("bench cradle: rest time, ball time cap, still speed and leaving height must be > 0");
  }
}

std::vector<double> drop_durations(const CradleBenchOptions& o) {
  std::vector<double> drops;
  const int n = static_cast<int>(std::floor((o.drop_to_s - o.drop_from_s) / o.drop_step_s + 1e-9));
  for (int k = 0; k <= n; ++k) drops.push_back(o.drop_from_s + k * o.drop_step_s);
  return drops;
}

}  // namespace

double CradleDropResult::return_share() const {
  return shots > 0 ? static_cast<double>(returns) / shots : std::numeric_limits<double>::quiet_NaN();
}

double CradleDropResult::return_share_needed() const {
  return returns > 0 ? std::pow(kShareAtTenMinutes, mean_period_s / kTenMinutes_s) : 1.0;
}

double CradleDropResult::projected_share_at_10_min() const {
  if (returns == 0 || !(mean_period_s > 0.0)) return 0.0;
  return std::pow(return_share(), kTenMinutes_s / mean_period_s);
}

CradleBall play_cradle_ball(const sim::World& world, std::uint64_t seed, double drop_s,
                            const CradleBenchOptions& options) {
  const table::Board& board = world.board();
  if (board.flippers.size() < 2) throw std::invalid_argument("bench cradle: the board needs two flippers");
  const std::unique_ptr<sim::World> w = world.fork();
  sim::GameState state = sim::make_game_state(board, seed);
  CradlePlayer player(board, drop_s, options);
  DrainWatch watch(state, drain_zones(board));
  player.start(state.time_s);
  sim::BallLimits limits;
  limits.max_ball_time_s = options.max_ball_time_s;
  const sim::BallResult r = sim::play_ball(
      *w, state, limits, [&](sim::GameState& s) { player.policy(s); },
      [&](const sim::GameState& s, const sim::StepEvents& e) {
        watch(s, e);
        if (e.has(sim::StepEvents::kBallLost) || e.has(sim::StepEvents::kLaunch)) return;
        player.observe(s);
      });
  return player.finish(r, classify_drain(drain_zones(board), watch.crossing_x_m()));
}

CradleReport run_cradle_bench(const sim::World& world, const CradleBenchOptions& options,
                              const std::function<void(const std::string&)>& progress) {
  check_options(options);
  const auto start = std::chrono::steady_clock::now();
  CradleReport report;
  report.options = options;
  report.world = std::string(world.name());
  const std::vector<double> drops = drop_durations(options);
  const std::size_t balls = static_cast<std::size_t>(options.balls);
  std::vector<CradleBall> played(drops.size() * balls);
  const auto total = static_cast<long>(played.size());
  SharedProgress balls_done(total, 1, [&](long d, double elapsed_s) {
    if (progress) progress(format_progress("cradle", d, total, "balls", elapsed_s));
  });
  learn::parallel_for(played.size(), options.threads, [&](std::size_t k) {
    played[k] = play_cradle_ball(world, ball_seed(options.seed, k % balls), drops[k / balls], options);
    balls_done.one_done();
  });
  for (std::size_t d = 0; d < drops.size(); ++d) {
    CradleDropResult r;
    r.drop_s = drops[d];
    double time_sum_s = 0.0, cycle_time_s = 0.0, cycle_points = 0.0;
    RunningStats score;
    for (std::size_t b = 0; b < balls; ++b) {
      const CradleBall& ball = played[d * balls + b];
      ++r.balls;
      r.cradled += ball.cradled ? 1 : 0;
      r.shots += ball.shots;
      r.returns += ball.returns;
      r.duds += ball.duds;
      r.passes += ball.passes;
      if (ball.lost_after_drop) r.drains.add(ball.drain, false);
      r.cut += ball.cut ? 1 : 0;
      r.cut_cycling += ball.cycling_at_cut ? 1 : 0;
      r.cut_passing += ball.passing_at_cut ? 1 : 0;
      time_sum_s += ball.ball_time_s;
      cycle_time_s += ball.cycle_time_s;
      cycle_points += ball.cycle_points;
      score.add(ball.score);
    }
    r.return_interval = wilson_ci95(r.returns, r.shots);
    // No return, no cycle: its period and points are unknown (null in JSON), not 0.
    r.mean_period_s = r.returns > 0 ? cycle_time_s / r.returns : std::numeric_limits<double>::quiet_NaN();
    r.points_per_cycle = r.returns > 0 ? cycle_points / r.returns : std::numeric_limits<double>::quiet_NaN();
    r.mean_ball_time_s = time_sum_s / r.balls;
    r.mean_score = score.mean();
    r.score_ci95 = score.ci95_half_width();
    report.drops.push_back(r);
    if (r.shots == 0) continue;  // no shot, no share: never the best
    const CradleDropResult* best = report.best ? &report.drops[*report.best] : nullptr;
    if (best == nullptr || r.return_share() > best->return_share() ||
        (r.return_share() == best->return_share() && r.return_interval.low > best->return_interval.low)) {
      report.best = d;
    }
  }
  report.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

nlohmann::json to_json(const CradleReport& report) {
  const CradleBenchOptions& o = report.options;
  nlohmann::json drops = nlohmann::json::array();
  for (const CradleDropResult& r : report.drops) {
    drops.push_back({{"drop_s", r.drop_s},
                     {"balls", r.balls},
                     {"cradled", r.cradled},
                     {"shots", r.shots},
                     {"returns", r.returns},
                     {"duds", r.duds},
                     {"passes", r.passes},
                     {"return_share", r.return_share()},
                     {"return_ci95_low", r.return_interval.low},
                     {"return_ci95_high", r.return_interval.high},
                     {"return_share_needed", r.return_share_needed()},
                     {"projected_share_at_10_min", r.projected_share_at_10_min()},
                     {"mean_period_s", r.mean_period_s},
                     {"points_per_cycle", r.points_per_cycle},
                     {"losses_after_drop",
                      {{"left_outlane", r.drains.left_outlane},
                       {"right_outlane", r.drains.right_outlane},
                       {"centre", r.drains.centre},
                       {"other", r.drains.other}}},
                     {"balls_cut_at_time_limit", r.cut},
                     {"balls_cut_cycling", r.cut_cycling},
                     {"balls_cut_passing", r.cut_passing},
                     {"mean_ball_time_s", r.mean_ball_time_s},
                     {"mean_score_per_ball", r.mean_score},
                     {"score_ci95_half_width", r.score_ci95}});
  }
  return {{"benchmark", "cradle"},
          {"world", report.world},
          {"player", "true state, exact timing: a ceiling, not a controller"},
          {"balls_per_drop", o.balls},
          {"seed", o.seed},
          {"max_ball_time_s", o.max_ball_time_s},
          {"rest_s", o.rest_s},
          {"still_speed_mps", o.still_speed_mps},
          {"left_height_m", o.left_height_m},
          {"drops", drops},
          {"best_drop_s", report.best ? nlohmann::json(report.drops[*report.best].drop_s) : nlohmann::json()},
          {"wall_s", report.wall_s}};
}

std::string to_text(const CradleReport& report) {
  const CradleBenchOptions& o = report.options;
  std::ostringstream out;
  out << "cradle cycles in the " << report.world << " (true state, exact timing: a ceiling, not a controller): "
      << o.balls << " balls per drop, seed " << o.seed << ", cut at " << format_number(o.max_ball_time_s) << " s\n"
      << "both bats held up; a ball still " << format_number(o.rest_s) << " s on a raised bat is shot by dropping "
      << "that bat for the drop time; a return: the next cradle after the ball rose "
      << format_number(o.left_height_m * 1e3) << " mm above the pivots\n";
  for (std::size_t d = 0; d < report.drops.size(); ++d) {
    const CradleDropResult& r = report.drops[d];
    out << (report.best == d ? "* " : "  ") << "drop " << format_number(r.drop_s * 1e3) << " ms: ";
    if (r.shots == 0) {
      out << "no shot";
    } else {
      out << "returns " << r.returns << " of " << r.shots << " shots = " << format_number(r.return_share()) << " ("
          << format_number(r.return_interval.low) << "-" << format_number(r.return_interval.high) << ")";
    }
    if (r.returns > 0) {
      out << ", needed " << format_number(r.return_share_needed()) << "; period " << format_number(r.mean_period_s)
          << " s, " << format_number(r.points_per_cycle) << " points a cycle";
    }
    out << "; lost after a drop: outlane "
        << r.drains.left_outlane + r.drains.right_outlane << ", centre " << r.drains.centre << "; cut "
        << r.cut << " (" << r.cut_cycling << " cycling, " << r.cut_passing << " passing); duds " << r.duds << " ("
        << r.passes << " passes); mean ball " << format_number(r.mean_ball_time_s)
        << " s, " << format_mean_ci(r.mean_score, r.score_ci95) << " points\n";
  }
  if (!report.drops.empty() && !report.best) {
    out << "no drop had a shot: no ball came to rest on a raised bat (a longer --max-ball-time or more --balls?)\n";
  }
  if (report.best) {
    const CradleDropResult& b = report.drops[*report.best];
    out << "best drop " << format_number(b.drop_s * 1e3) << " ms: at " << format_number(b.return_share())
        << (b.returns > 0 ? " a return and " + format_number(b.mean_period_s) + " s a cycle, " : " a return, ");
    const double projected = b.projected_share_at_10_min();
    out << (projected < 1e-4 ? std::string("under 0.01") : format_number(100.0 * projected))
        << " % of cradled balls would live 10 minutes (1 % needs " << format_number(b.return_share_needed()) << ")\n";
  }
  return out.str();
}

}  // namespace pinball::bench
