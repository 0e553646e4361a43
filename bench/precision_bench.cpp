#include "precision_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pinball/sim/event_stepper.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/thesis_stepper.h"

namespace pinball::bench {
namespace {

using table::Board;
using sim::GameState;

// The scenes use the table's constants: along-table gravity and ball radius.
constexpr double kG = 1.11;
constexpr double kR = 0.0135;
// Errors below this (the rounding unit of a coordinate of tens of metres) are
// counted as this in ratios and on the plot, whose axes are logarithmic.
constexpr double kErrorFloor_m = 1e-15;

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
    const double e = std::max(p.max_error_m, kErrorFloor_m);
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
    const double e = std::max(p.max_error_m, kErrorFloor_m);
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

std::string sci(double v, int digits = 2) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.*e", digits - 1, v);
  return buf;
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
  double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  for (const auto& [x, y] : xy) {
    const double lx = std::log(x), ly = std::log(y);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
  }
  const double n = static_cast<double>(xy.size());
  LogLogFit f;
  const double den = n * sxx - sx * sx;
  f.slope = den == 0.0 ? 0.0 : (n * sxy - sx * sy) / den;
  f.intercept = (sy - f.slope * sx) / n;
  return f;
}

PrecisionReport run_precision_bench(const Board& table, const PrecisionBenchOptions& options,
                                    const std::function<void(const std::string&)>& progress) {
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
  if (!table.source.empty() && options.with_event) {
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

nlohmann::json to_json(const PrecisionReport& report) {
  nlohmann::json points = nlohmann::json::array();
  for (const PrecisionPoint& p : report.points) {
    points.push_back({{"scene", p.scene},
                      {"stepper", p.stepper},
                      {"setting", p.setting},
                      {"max_error_m", p.max_error_m},
                      {"final_error_m", p.final_error_m},
                      {"run_time_s", p.run_time_s},
                      {"steps", p.steps},
                      {"events", p.events}});
  }
  nlohmann::json comparisons = nlohmann::json::array();
  for (const PrecisionComparison& c : report.comparisons) {
    comparisons.push_back({{"scene", c.scene},
                           {"tolerance", c.tolerance},
                           {"event_error_m", c.event_error_m},
                           {"event_time_s", c.event_time_s},
                           {"error_ratio", c.error_ratio},
                           {"error_ratio_extrapolated", c.error_ratio_extrapolated},
                           {"speedup", c.speedup},
                           {"speedup_extrapolated", c.speedup_extrapolated},
                           {"thesis_fit_exponent", c.thesis_fit_exponent},
                           {"thesis_best_error_m", c.thesis_best_error_m},
                           {"thesis_best_time_s", c.thesis_best_time_s},
                           {"best_speedup", c.best_speedup}});
  }
  const PrecisionBenchOptions& o = report.options;
  const PrecisionTargets& t = report.targets;
  nlohmann::json targets = nullptr;
  if (t.evaluated) {
    targets = {{"tolerance", t.tolerance},
               {"worst_closed_form_error_m", t.worst_closed_form_error_m},
               {"worst_scene", t.worst_scene},
               {"error_target_met", t.worst_closed_form_error_m <= 1e-9},
               {"min_error_ratio", t.min_error_ratio},
               {"error_ratio_target_met", t.min_error_ratio >= 1000.0},
               {"min_best_speedup", t.min_best_speedup},
               {"best_speedup_target_met", t.min_best_speedup >= 100.0},
               {"min_fit_speedup", std::isfinite(t.min_fit_speedup) ? nlohmann::json(t.min_fit_speedup) : nullptr}};
  }
  return {{"benchmark", "precision"},
          {"horizon_s", o.horizon_s},
          {"event_step_s", o.event_step_s},
          {"event_rest_height_m", o.event_rest_height_m},
          {"table_horizon_s", o.table_horizon_s},
          {"table_reference_tolerance", o.table_reference_tolerance},
          {"table_reference_step_s", o.table_reference_step_s},
          {"repeats", o.repeats},
          {"error_floor_m", kErrorFloor_m},
          {"points", points},
          {"comparisons", comparisons},
          {"targets", targets}};
}

std::string to_csv(const PrecisionReport& report) {
  std::ostringstream out;
  out << "scene,stepper,setting,max_error_m,final_error_m,run_time_s\n";
  out.precision(6);
  for (const PrecisionPoint& p : report.points) {
    out << p.scene << ',' << p.stepper << ',' << p.setting << ',' << p.max_error_m << ',' << p.final_error_m << ','
        << p.run_time_s << '\n';
  }
  return out.str();
}

std::string to_markdown(const PrecisionReport& report) {
  std::vector<std::string> scenes;
  for (const PrecisionPoint& p : report.points) {
    if (std::find(scenes.begin(), scenes.end(), p.scene) == scenes.end()) scenes.push_back(p.scene);
  }
  std::ostringstream out;
  for (const std::string stepper : {"thesis", "event"}) {
    std::map<double, std::map<std::string, const PrecisionPoint*>, std::greater<>> rows;
    for (const PrecisionPoint& p : report.points) {
      if (p.stepper == stepper) rows[p.setting][p.scene] = &p;
    }
    if (rows.empty()) continue;
    out << "| " << (stepper == std::string("thesis") ? "thesis dt (s)" : "event tolerance") << " |";
    for (const std::string& s : scenes) out << ' ' << s << " |";
    out << "\n|---|";
    for (std::size_t i = 0; i < scenes.size(); ++i) out << "---:|";
    out << '\n';
    for (const auto& [setting, by_scene] : rows) {
      out << "| " << sci(setting, 1) << " |";
      for (const std::string& s : scenes) {
        const auto it = by_scene.find(s);
        out << ' ';
        if (it != by_scene.end()) out << sci(it->second->max_error_m) << " m / " << sci(it->second->run_time_s) << " s";
        out << " |";
      }
      out << '\n';
    }
    out << '\n';
  }
  if (report.comparisons.empty()) return out.str();
  // Headline at the event stepper's default tolerance.
  const double tol = sim::EventStepperOptions{}.relative_tolerance;
  out << "| scene (event tolerance " << sci(tol, 1) << ") | event error (m) | event run time (s) | thesis error at "
      << "equal run time (m) | error ratio | thesis best error (m) at run time (s) | speed-up over thesis best "
      << "(measured) | speed-up at equal error (power-law fit) |\n|---|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const PrecisionComparison& c : report.comparisons) {
    if (c.tolerance != tol) continue;
    out << "| " << c.scene << " | " << sci(c.event_error_m) << " | " << sci(c.event_time_s) << " | "
        << sci(c.error_ratio * std::max(c.event_error_m, kErrorFloor_m)) << (c.error_ratio_extrapolated ? "*" : "")
        << " | " << sci(c.error_ratio) << " | " << sci(c.thesis_best_error_m) << " at " << sci(c.thesis_best_time_s)
        << " | " << sci(c.best_speedup) << " | ";
    if (std::isfinite(c.speedup)) {
      out << sci(c.speedup) << (c.speedup_extrapolated ? "*" : "") << " (p = " << sci(c.thesis_fit_exponent) << ")";
    } else {
      out << "never (p = " << sci(c.thesis_fit_exponent) << ")";
    }
    out << " |\n";
  }
  const PrecisionTargets& tg = report.targets;
  if (tg.evaluated) {
    auto met = [](bool ok) { return ok ? "met" : "NOT met"; };
    out << "| target (event tolerance " << sci(tg.tolerance, 1) << ") | measured | |\n|---|---:|---|\n"
        << "| event error <= 1e-9 m on every closed-form scene | " << sci(tg.worst_closed_form_error_m) << " m ("
        << tg.worst_scene << ") | " << met(tg.worst_closed_form_error_m <= 1e-9) << " |\n"
        << "| error >= 1000x lower at equal run time | " << sci(tg.min_error_ratio) << "x | "
        << met(tg.min_error_ratio >= 1000.0) << " |\n"
        << "| >= 100x faster at equal error (over the thesis's best, measured) | " << sci(tg.min_best_speedup)
        << "x | " << met(tg.min_best_speedup >= 100.0) << " |\n"
        << "| ... at equal error by power-law extrapolation | " << sci(tg.min_fit_speedup) << "x | "
        << met(tg.min_fit_speedup >= 100.0) << " |\n";
  }
  out << "\n| event tolerance |";
  for (const std::string& s : scenes) out << ' ' << s << " |";
  out << "\n|---|";
  for (std::size_t i = 0; i < scenes.size(); ++i) out << "---:|";
  out << '\n';
  std::map<double, std::map<std::string, const PrecisionComparison*>, std::greater<>> rows;
  for (const PrecisionComparison& c : report.comparisons) rows[c.tolerance][c.scene] = &c;
  for (const auto& [t, by_scene] : rows) {
    out << "| " << sci(t, 1) << " |";
    for (const std::string& s : scenes) {
      const auto it = by_scene.find(s);
      out << ' ';
      if (it != by_scene.end()) {
        const PrecisionComparison& c = *it->second;
        out << sci(c.error_ratio) << (c.error_ratio_extrapolated ? "*" : "") << " / " << sci(c.best_speedup);
      }
      out << " |";
    }
    out << '\n';
  }
  return out.str();
}

void plot_precision_png(const PrecisionReport& report, const std::string& path) {
  std::vector<std::string> scenes;
  double t_lo = 1e300, t_hi = 0.0, e_lo = 1e300, e_hi = 0.0;
  for (const PrecisionPoint& p : report.points) {
    if (std::find(scenes.begin(), scenes.end(), p.scene) == scenes.end()) scenes.push_back(p.scene);
    const double e = std::max(p.max_error_m, kErrorFloor_m);
    t_lo = std::min(t_lo, p.run_time_s);
    t_hi = std::max(t_hi, p.run_time_s);
    e_lo = std::min(e_lo, e);
    e_hi = std::max(e_hi, e);
  }
  if (scenes.empty()) throw std::runtime_error(path + ": nothing to plot");
  // Whole decades around the data, shared by every panel so that panels compare.
  const int tx0 = static_cast<int>(std::floor(std::log10(std::max(t_lo, 1e-12))));
  const int tx1 = std::max(tx0 + 1, static_cast<int>(std::ceil(std::log10(std::max(t_hi, 1e-12)))));
  const int ey0 = static_cast<int>(std::floor(std::log10(e_lo)));
  const int ey1 = std::max(ey0 + 1, static_cast<int>(std::ceil(std::log10(e_hi))));
  constexpr int kPanelW = 460, kPanelH = 360, kCols = 3, kLeft = 62, kRight = 26, kTop = 30, kBottom = 44;
  constexpr int kHeader = 40;
  const int rows = (static_cast<int>(scenes.size()) + kCols - 1) / kCols;
  cv::Mat img(kHeader + rows * kPanelH, kCols * kPanelW, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Scalar black(0, 0, 0), grey(215, 215, 215), thesis_colour(200, 90, 0), event_colour(0, 0, 210);
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  cv::putText(img, "max position error (m) against run time (s), log-log; blue o: thesis (dt sweep), red []: event (tolerance sweep)",
              cv::Point(10, 26), font, 0.5, black, 1, cv::LINE_AA);
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    const int ox = static_cast<int>(k % kCols) * kPanelW;
    const int oy = kHeader + static_cast<int>(k / kCols) * kPanelH;
    const int w = kPanelW - kLeft - kRight, h = kPanelH - kTop - kBottom;
    auto to_px = [&](double t, double e) {
      const double fx = (std::log10(t) - tx0) / (tx1 - tx0);
      const double fy = (std::log10(std::max(e, kErrorFloor_m)) - ey0) / (ey1 - ey0);
      return cv::Point(ox + kLeft + static_cast<int>(w * fx), oy + kTop + h - static_cast<int>(h * fy));
    };
    char label[32];
    for (int d = tx0; d <= tx1; ++d) {
      const cv::Point a = to_px(std::pow(10.0, d), std::pow(10.0, ey0));
      cv::line(img, a, to_px(std::pow(10.0, d), std::pow(10.0, ey1)), grey, 1);
      std::snprintf(label, sizeof(label), "1e%d", d);
      cv::putText(img, label, a + cv::Point(-14, 16), font, 0.38, black, 1, cv::LINE_AA);
    }
    const int ey_step = std::max(1, (ey1 - ey0 + 7) / 8);  // at most ~8 labelled decades
    for (int d = ey0; d <= ey1; ++d) {
      const cv::Point a = to_px(std::pow(10.0, tx0), std::pow(10.0, d));
      cv::line(img, a, to_px(std::pow(10.0, tx1), std::pow(10.0, d)), grey, 1);
      if ((d - ey0) % ey_step != 0) continue;
      std::snprintf(label, sizeof(label), "1e%d", d);
      cv::putText(img, label, a + cv::Point(-44, 4), font, 0.38, black, 1, cv::LINE_AA);
    }
    cv::rectangle(img, to_px(std::pow(10.0, tx0), std::pow(10.0, ey1)), to_px(std::pow(10.0, tx1), std::pow(10.0, ey0)),
                  black, 1);
    cv::putText(img, scenes[k] + ": error (m)", cv::Point(ox + kLeft - 40, oy + kTop - 8), font, 0.5, black, 1,
                cv::LINE_AA);
    cv::putText(img, "run time (s)", cv::Point(ox + kLeft + w / 2 - 40, oy + kPanelH - 8), font, 0.4, black, 1,
                cv::LINE_AA);
    for (const std::string stepper : {"thesis", "event"}) {
      std::vector<cv::Point> pts;  // in sweep order, so a curve runs from coarse to fine
      for (const PrecisionPoint& p : report.points) {
        if (p.scene == scenes[k] && p.stepper == stepper) pts.push_back(to_px(p.run_time_s, p.max_error_m));
      }
      const bool is_thesis = stepper == std::string("thesis");
      const cv::Scalar colour = is_thesis ? thesis_colour : event_colour;
      if (pts.size() >= 2) cv::polylines(img, pts, false, colour, 1, cv::LINE_AA);
      for (const cv::Point& q : pts) {
        if (is_thesis) {
          cv::circle(img, q, 4, colour, 1, cv::LINE_AA);
        } else {
          cv::rectangle(img, q - cv::Point(3, 3), q + cv::Point(3, 3), colour, 1);
        }
      }
    }
    // Legend in each panel's top right corner.
    const cv::Point lg(ox + kPanelW - kRight - 90, oy + kTop + 16);
    cv::circle(img, lg, 4, thesis_colour, 1, cv::LINE_AA);
    cv::putText(img, "thesis", lg + cv::Point(10, 4), font, 0.4, thesis_colour, 1, cv::LINE_AA);
    cv::rectangle(img, lg + cv::Point(-3, 15), lg + cv::Point(3, 21), event_colour, 1);
    cv::putText(img, "event", lg + cv::Point(10, 22), font, 0.4, event_colour, 1, cv::LINE_AA);
  }
  if (!cv::imwrite(path, img)) throw std::runtime_error(path + ": cannot write PNG");
}

}  // namespace pinball::bench
