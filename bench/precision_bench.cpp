#include "precision_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "pinball/core/least_squares_line.h"
#include "pinball/sim/event_stepper.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/thesis_stepper.h"
#include "staged_progress.h"

namespace pinball::bench {
namespace {

using table::Board;
using sim::GameState;

// The scenes use the table's constants: along-table gravity and ball radius.
constexpr double kG = 1.11;
constexpr double kR = 0.0135;

// free_flight: a tall empty board so that 10 s of free fall stays on it.
const Vec2 kFlightP0{0.2, 56.0};
const Vec2 kFlightV0{0.05, 0.5};

// bounce_to_rest: dropped from rest h0 above its resting height on a line with rho < 1.
constexpr double kFloorY = 0.1;
constexpr double kDropX = 0.5;
constexpr double kDropH = 0.3;
constexpr double kBounceRho = 0.7;

// incline_slide: a line descending at 5 degrees; the ball starts on it at rest.
constexpr double kInclineRad = 5.0 * std::numbers::pi / 180.0;
const Vec2 kInclineP0{0.1, 0.6};
constexpr double kInclineLength = 5.3;
constexpr double kInclineStart = 0.05;  // along the line from p0

// elastic_box: the table-sized box with rho = 1 walls; the ball never reaches the roof.
constexpr double kBoxW = 0.51;
constexpr double kBoxH = 1.07;
const Vec2 kBoxP0{0.1, 0.5};
const Vec2 kBoxV0{0.37, 0.3};

// circle_bounce: dropped from rest onto a circle 5 mm off its centre line, then free fall.
const Vec2 kCircleC{2.0, 58.0};
constexpr double kCircleR = 0.05;
constexpr double kCircleRho = 0.9;
const Vec2 kCircleDrop{1.995, 58.3};

Board scene_base(double width_m, double height_m) {
  Board b;
  b.source = "precision";
  b.width_m = width_m;
  b.height_m = height_m;
  b.ball.radius_m = kR;
  b.ball.speed_max_mps = 50.0;  // far above every speed of the scenes: the clamp never acts
  b.gravity_mps2 = kG;
  b.dt_s = 1e-3;
  b.launcher.position = Vec2{0.5 * width_m, 0.05};
  return b;
}

void add_line(Board& b, const Vec2& p0, const Vec2& p1, double rho) {
  b.shapes.push_back(table::make_line_shape(p0, p1));
  table::Obstacle o;
  o.rho = rho;
  o.name = "line";
  b.obstacles.push_back(o);
}

Vec2 incline_dir() { return {std::cos(kInclineRad), -std::sin(kInclineRad)}; }

Vec2 free_fall(const Vec2& p0, const Vec2& v0, double t) { return p0 + t * v0 + Vec2{0.0, -0.5 * kG * t * t}; }

Vec2 bounce_exact(double t) {
  const double rest_y = kFloorY + kR;
  const double v0 = std::sqrt(2.0 * kG * kDropH);  // speed at the first impact
  const double t0 = std::sqrt(2.0 * kDropH / kG);
  if (t <= t0) return {kDropX, rest_y + kDropH - 0.5 * kG * t * t};
  // Impact k (k = 0 at t0) leaves at u_k = v0·ρ^(k+1); impacts at
  // T_k = t0 + (2 v0 ρ / g)(1 − ρ^k)/(1 − ρ), accumulating at the rest time.
  const double a = 2.0 * v0 * kBounceRho / (kG * (1.0 - kBounceRho));
  const double q = 1.0 - (t - t0) / a;  // ρ^k at the last impact before t
  if (q <= 0.0) return {kDropX, rest_y};
  auto impact_time = [&](int k) { return t0 + a * (1.0 - std::pow(kBounceRho, k)); };
  int k = static_cast<int>(std::floor(std::log(q) / std::log(kBounceRho)));
  k = std::max(k, 0);
  while (k > 0 && impact_time(k) > t) --k;
  while (impact_time(k + 1) <= t) ++k;
  const double u = v0 * std::pow(kBounceRho, k + 1);
  const double tau = t - impact_time(k);
  return {kDropX, rest_y + std::max(0.0, u * tau - 0.5 * kG * tau * tau)};
}

Vec2 incline_exact(double t) {
  const Vec2 d = incline_dir();
  const Vec2 start = kInclineP0 + kInclineStart * d + kR * perp_left(d);
  return start + (0.5 * kG * std::sin(kInclineRad) * t * t) * d;
}

// Folds a free coordinate onto [lo, hi] as elastic walls reflect it.
double fold(double x, double lo, double hi) {
  const double span = hi - lo;
  double m = std::fmod(x - lo, 2.0 * span);
  if (m < 0.0) m += 2.0 * span;
  return lo + (m <= span ? m : 2.0 * span - m);
}

Vec2 box_exact(double t) {
  const double x = fold(kBoxP0.x() + kBoxV0.x() * t, kR, kBoxW - kR);
  // Vertically: one free fall to the floor, then periodic floor bounces (the roof is out of reach).
  const double vy = kBoxV0.y();
  const double drop = kBoxP0.y() - kR;
  const double t1 = (vy + std::sqrt(vy * vy + 2.0 * kG * drop)) / kG;
  if (t <= t1) return {x, kBoxP0.y() + vy * t - 0.5 * kG * t * t};
  const double vf = std::sqrt(vy * vy + 2.0 * kG * drop);
  const double tau = std::fmod(t - t1, 2.0 * vf / kG);
  return {x, kR + vf * tau - 0.5 * kG * tau * tau};
}

Vec2 circle_exact(double t) {
  // The ball falls straight down 5 mm off the centre line: it meets the circle
  // where its centre is R + r from the circle's, then leaves along the reflection.
  const double reach = kCircleR + kR;
  const double dx = kCircleDrop.x() - kCircleC.x();
  const double y_hit = kCircleC.y() + std::sqrt(reach * reach - dx * dx);
  const double t_hit = std::sqrt(2.0 * (kCircleDrop.y() - y_hit) / kG);
  if (t <= t_hit) return free_fall(kCircleDrop, Vec2::Zero(), t);
  const Vec2 p_hit{kCircleDrop.x(), y_hit};
  const Vec2 n = (p_hit - kCircleC) / reach;
  const Vec2 v_in{0.0, -kG * t_hit};
  const Vec2 v_out = v_in - (1.0 + kCircleRho) * v_in.dot(n) * n;
  return free_fall(p_hit, v_out, t - t_hit);
}

Vec2 scene_start_velocity(const std::string& scene) {
  if (scene == "free_flight") return kFlightV0;
  if (scene == "elastic_box") return kBoxV0;
  return Vec2::Zero();
}

// A scene ready to run: board, start state and the answer at time t.
struct Scene {
  std::string name;
  const Board* board = nullptr;
  GameState start;
  double horizon_s = 0.0;
  double sample_period_s = 0.0;  // 0: compare at every step end
  std::function<Vec2(double)> exact;
};

GameState ball_state(const Board& board, const Vec2& p, const Vec2& v) {
  GameState s = sim::make_game_state(board, 1);
  s.ball_in_play = true;
  s.ball.position_m = p;
  s.ball.velocity_mps = v;
  return s;
}

double min_time(const std::vector<double>& times) { return *std::min_element(times.begin(), times.end()); }

template <class Stepper>
PrecisionPoint measure(const Scene& scene, const Stepper& stepper, const std::string& kind, double setting,
                       int repeats) {
  const double dt = stepper.dt_s();
  const long n = std::lround(scene.horizon_s / dt);
  const long stride = scene.sample_period_s > 0.0 ? std::max(1L, std::lround(scene.sample_period_s / dt)) : 1L;
  PrecisionPoint pt;
  pt.scene = scene.name;
  pt.stepper = kind;
  pt.setting = setting;
  pt.steps = static_cast<std::uint64_t>(n);
  // Errors from an untimed pass; time at step i is i·dt exactly (time_s sums rounding).
  GameState s = scene.start;
  for (long i = 1; i <= n; ++i) {
    stepper.step(s);
    if (i % stride != 0 && i != n) continue;
    const double e = (s.ball.position_m - scene.exact(static_cast<double>(i) * dt)).norm();
    pt.max_error_m = std::max(pt.max_error_m, std::isfinite(e) ? e : INFINITY);
    if (i == n) pt.final_error_m = e;
  }
  pt.events = s.events;
  // Timed passes: stepping only. The first is a warm-up.
  std::vector<double> times;
  for (int r = 0; r <= std::max(1, repeats); ++r) {
    GameState t = scene.start;  // copied outside the timed loop (it allocates)
    const auto t0 = std::chrono::steady_clock::now();
    for (long i = 0; i < n; ++i) stepper.step(t);
    const auto t1 = std::chrono::steady_clock::now();
    if (r > 0) times.push_back(std::chrono::duration<double>(t1 - t0).count());
  }
  pt.run_time_s = min_time(times);
  return pt;
}

PrecisionPoint measure_thesis(const Scene& scene, double dt, int repeats) {
  sim::ThesisStepperOptions o;
  o.dt_s = dt;
  const sim::ThesisStepper stepper(*scene.board, o);
  return measure(scene, stepper, "thesis", dt, repeats);
}

sim::EventStepperOptions event_options(const PrecisionBenchOptions& options, double tolerance, double step_s) {
  sim::EventStepperOptions o;
  o.dt_s = step_s;
  o.relative_tolerance = tolerance;
  o.rest_height_m = options.event_rest_height_m;
  return o;
}

PrecisionPoint measure_event(const Scene& scene, const PrecisionBenchOptions& options, double tolerance) {
  const sim::EventStepper stepper(*scene.board, event_options(options, tolerance, options.event_step_s));
  return measure(scene, stepper, "event", tolerance, options.repeats);
}

void run_scene(const Scene& scene, const PrecisionBenchOptions& options, PrecisionReport& report,
               const std::function<void(const std::string&)>& progress) {
  const double dt_max = table::max_stable_dt_s(*scene.board);
  for (double dt : options.thesis_dt_s) {
    if (dt >= dt_max) continue;  // illegal for this board's flippers
    report.points.push_back(measure_thesis(scene, dt, options.repeats));
  }
  if (options.with_event) {
    for (double tol : options.event_tolerances) report.points.push_back(measure_event(scene, options, tol));
  }
  if (progress) {
    std::ostringstream line;
    line << scene.name << ": " << options.thesis_dt_s.size() << " thesis, "
         << (options.with_event ? options.event_tolerances.size() : 0) << " event settings";
    progress(line.str());
  }
}

std::vector<std::pair<double, double>> curve(const PrecisionReport& report, const std::string& scene,
                                             const std::string& stepper, bool error_first) {
  std::vector<std::pair<double, double>> xy;
  for (const PrecisionPoint& p : report.points) {
    if (p.scene != scene || p.stepper != stepper) continue;
    const double e = std::max(p.max_error_m, kPrecisionErrorFloor_m);
    xy.emplace_back(error_first ? e : p.run_time_s, error_first ? p.run_time_s : e);
  }
  std::sort(xy.begin(), xy.end());
  return xy;
}

// Equal run time: the thesis error at the event's run time, interpolated
// log-log between the two thesis settings around it. Equal error: the thesis
// run time at the event's error, interpolated the same way inside the thesis
// curve's range; outside it (the usual case: the event error is far below
// the thesis's best), extrapolated along a least-squares power law fitted to
// the whole thesis curve. best_speedup needs no extrapolation.
void compare(PrecisionReport& report, const std::string& scene) {
  const auto thesis_by_time = curve(report, scene, "thesis", false);
  const auto thesis_by_error = curve(report, scene, "thesis", true);
  if (thesis_by_time.size() < 2) return;
  const LogLogFit fit = loglog_fit(thesis_by_time);  // error against time
  const auto best = *std::min_element(thesis_by_time.begin(), thesis_by_time.end(),
                                      [](const auto& a, const auto& b) { return a.second < b.second; });
  for (const PrecisionPoint& p : report.points) {
    if (p.scene != scene || p.stepper != "event") continue;
    PrecisionComparison c;
    c.scene = scene;
    c.tolerance = p.setting;
    c.event_error_m = p.max_error_m;
    c.event_time_s = p.run_time_s;
    const double e = std::max(p.max_error_m, kPrecisionErrorFloor_m);
    c.error_ratio = loglog_interpolate(thesis_by_time, p.run_time_s, c.error_ratio_extrapolated) / e;
    double thesis_time = loglog_interpolate(thesis_by_error, e, c.speedup_extrapolated);
    if (c.speedup_extrapolated) {
      thesis_time = fit.slope < 0.0 ? std::exp((std::log(e) - fit.intercept) / fit.slope) : INFINITY;
    }
    c.speedup = thesis_time / p.run_time_s;
    c.thesis_fit_exponent = fit.slope;
    c.thesis_best_error_m = best.second;
    c.thesis_best_time_s = best.first;
    c.best_speedup = best.first / p.run_time_s;
    report.comparisons.push_back(c);
  }
}


PrecisionTargets evaluate_targets(const PrecisionReport& report) {
  PrecisionTargets t;
  t.tolerance = sim::EventStepperOptions{}.relative_tolerance;
  t.min_error_ratio = t.min_best_speedup = t.min_fit_speedup = INFINITY;
  const auto& closed = closed_form_scenes();
  for (const PrecisionComparison& c : report.comparisons) {
    if (c.tolerance != t.tolerance) continue;
    t.evaluated = true;
    const bool is_closed = std::find(closed.begin(), closed.end(), c.scene) != closed.end();
    if (is_closed && c.event_error_m >= t.worst_closed_form_error_m) {
      t.worst_closed_form_error_m = c.event_error_m;
      t.worst_scene = c.scene;
    }
    t.min_error_ratio = std::min(t.min_error_ratio, c.error_ratio);
    t.min_best_speedup = std::min(t.min_best_speedup, c.best_speedup);
    t.min_fit_speedup = std::min(t.min_fit_speedup, c.speedup);
  }
  return t;
}

}  // namespace

PrecisionBenchOptions default_precision_bench_options() {
  PrecisionBenchOptions o;
  for (double decade = 1e-2; decade > 0.5e-6; decade /= 10.0) {
    for (double m : {1.0, 0.5, 0.2}) {
      if (m * decade >= 0.9e-6) o.thesis_dt_s.push_back(m * decade);
    }
  }
  for (int k = 6; k <= 14; ++k) o.event_tolerances.push_back(std::pow(10.0, -k));
  return o;
}

PrecisionBenchOptions quick_precision_bench_options() {
  PrecisionBenchOptions o;
  o.thesis_dt_s = {1e-2, 1e-3, 1e-4};
  o.event_tolerances = {1e-6, 1e-12, 1e-14};
  o.repeats = 1;
  return o;
}

const std::vector<std::string>& closed_form_scenes() {
  static const std::vector<std::string> names{"free_flight", "bounce_to_rest", "incline_slide", "elastic_box",
                                              "circle_bounce"};
  return names;
}

Board precision_scene_board(const std::string& scene) {
  if (scene == "free_flight") return scene_base(1.0, 60.0);
  if (scene == "bounce_to_rest") {
    Board b = scene_base(1.0, 1.0);
    add_line(b, {0.0, kFloorY}, {1.0, kFloorY}, kBounceRho);
    return b;
  }
  if (scene == "incline_slide") {
    Board b = scene_base(5.5, 1.0);
    add_line(b, kInclineP0, kInclineP0 + kInclineLength * incline_dir(), 0.5);
    return b;
  }
  if (scene == "elastic_box") {
    Board b = scene_base(kBoxW, kBoxH);
    add_line(b, {0.0, 0.0}, {kBoxW, 0.0}, 1.0);
    add_line(b, {kBoxW, 0.0}, {kBoxW, kBoxH}, 1.0);
    add_line(b, {kBoxW, kBoxH}, {0.0, kBoxH}, 1.0);
    add_line(b, {0.0, kBoxH}, {0.0, 0.0}, 1.0);
    return b;
  }
  if (scene == "circle_bounce") {
    Board b = scene_base(4.0, 62.0);
    b.shapes.push_back(table::make_circle_shape(kCircleC, kCircleR));
    table::Obstacle o;
    o.rho = kCircleRho;
    o.name = "circle";
    b.obstacles.push_back(o);
    return b;
  }
  throw std::invalid_argument("unknown precision scene: " + scene);
}

Vec2 precision_scene_exact(const std::string& scene, double t_s) {
  if (scene == "free_flight") return free_fall(kFlightP0, kFlightV0, t_s);
  if (scene == "bounce_to_rest") return bounce_exact(t_s);
  if (scene == "incline_slide") return incline_exact(t_s);
  if (scene == "elastic_box") return box_exact(t_s);
  if (scene == "circle_bounce") return circle_exact(t_s);
  throw std::invalid_argument("unknown precision scene: " + scene);
}

double loglog_interpolate(const std::vector<std::pair<double, double>>& xy, double x, bool& extrapolated) {
  if (xy.size() < 2) throw std::invalid_argument("loglog_interpolate: need two points");
  const double lx = std::log(x);
  std::size_t i = 0;  // segment [i, i+1]
  while (i + 2 < xy.size() && std::log(xy[i + 1].first) < lx) ++i;
  extrapolated = x < xy.front().first || x > xy.back().first;
  const double x0 = std::log(xy[i].first), x1 = std::log(xy[i + 1].first);
  const double y0 = std::log(xy[i].second), y1 = std::log(xy[i + 1].second);
  const double w = x1 == x0 ? 0.0 : (lx - x0) / (x1 - x0);
  return std::exp(y0 + w * (y1 - y0));
}

LogLogFit loglog_fit(const std::vector<std::pair<double, double>>& xy) {
  if (xy.size() < 2) throw std::invalid_argument("loglog_fit: need two points");
  std::vector<std::pair<double, double>> logs;
  logs.reserve(xy.size());
  for (const auto& [x, y] : xy) logs.emplace_back(std::log(x), std::log(y));
  const LineFit line = fit_line(logs);
  return {line.intercept, line.slope};
}

PrecisionReport run_precision_bench(const Board& table, const PrecisionBenchOptions& options,
                                    const std::function<void(const std::string&)>& report_line) {
  // Stages: the closed-form scenes, then the table when the event stepper runs.
  const bool with_table = !table.source.empty() && options.with_event;
  const auto progress = staged_progress(report_line, "precision",
                                        static_cast<int>(closed_form_scenes().size()) + (with_table ? 1 : 0), "scenes");
  PrecisionReport report;
  report.options = options;
  for (const std::string& name : closed_form_scenes()) {
    const Board board = precision_scene_board(name);
    Scene scene;
    scene.name = name;
    scene.board = &board;
    scene.start = ball_state(board, precision_scene_exact(name, 0.0), scene_start_velocity(name));
    scene.horizon_s = options.horizon_s;
    scene.exact = [name](double t) { return precision_scene_exact(name, t); };
    run_scene(scene, options, report, progress);
    compare(report, name);
  }
  if (with_table) {
    // The full table is chaotic: its reference is the event stepper at its
    // tightest tolerance from the same launch, over a horizon short enough
    // that the trajectories have not yet diverged.
    Scene scene;
    scene.name = "table";
    scene.board = &table;
    scene.start = sim::make_game_state(table, options.table_seed);
    scene.start.ball_in_play = true;
    sim::launch_ball(table, scene.start, options.table_pull);
    scene.horizon_s = options.table_horizon_s;
    scene.sample_period_s = options.table_reference_step_s;
    std::vector<Vec2> path{scene.start.ball.position_m};
    const sim::EventStepper reference(
        table, event_options(options, options.table_reference_tolerance, options.table_reference_step_s));
    GameState s = scene.start;
    const long n = std::lround(scene.horizon_s / options.table_reference_step_s);
    for (long i = 0; i < n; ++i) {
      reference.step(s);
      path.push_back(s.ball.position_m);
    }
    const double h = options.table_reference_step_s;
    scene.exact = [path, h](double t) {
      const auto k = static_cast<std::size_t>(std::clamp(std::lround(t / h), 0L, static_cast<long>(path.size()) - 1));
      return path[k];
    };
    run_scene(scene, options, report, progress);
    compare(report, "table");
  }
  report.targets = evaluate_targets(report);
  return report;
}

}  // namespace pinball::bench
