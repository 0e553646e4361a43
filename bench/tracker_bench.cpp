#include "tracker_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "pinball/core/statistics.h"
#include "pinball/core/rng.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/simlab/oracle_policy.h"
#include "pinball/sim/penetration.h"
#include "pinball/sim/model_world.h"
#include "pinball/track/flipper_geometry.h"
#include "pinball/track/tracker.h"
#include "pinball/track/trajectory_fit.h"
#include "staged_progress.h"

namespace pinball::bench {

TrackerBenchOptions quick_tracker_bench_options() {
  TrackerBenchOptions o;
  o.approaches = 100;
  o.fps = {o.headline_camera.fps};
  o.m_per_px = {o.headline_camera.m_per_px};
  o.noise_px = {o.headline_camera.noise_px};
  o.g_factors = {};
  o.cost_windows = {8, 64};
  o.cost_passes = 1;
  return o;
}

namespace {

using Clock = std::chrono::steady_clock;

constexpr std::size_t kTracker = 0;
constexpr std::size_t kTwoPoint = 1;
constexpr std::size_t kFreeG = 2;
constexpr std::array<const char*, 3> kMethodNames{"tracker", "two_point", "free_g"};

bool touches_board(const table::Board& board, const Vec2& p) {
  const double r = board.ball.radius_m;
  // Every obstacle, hidden ones too: an approach must be free flight whatever the flags do.
  for (const table::Shape& s : board.shapes) {
    if (sim::shape_penetration_m(s, p, r) > 0.0) return true;
  }
  for (const table::Sensor& s : board.sensors) {
    if (s.kind == table::SensorKind::kHole && (p - s.shape.p0).norm() < s.shape.radius_m) return true;
  }
  return p.x() < 0.0 || p.x() > board.width_m || p.y() < 0.0 || p.y() > board.height_m;
}

enum class Verdict { kKept, kNoImpact, kTooShort, kObstacle };

Verdict judge_approach(const table::Board& board, const track::FlipperGeometry& geometry,
                       const TrackerBenchOptions& options, const Vec2& p, const Vec2& v, TrackerApproach& out) {
  const track::TrajectoryFit fit = track::exact_trajectory(p, v, board.gravity_mps2, 0.0);
  const track::TrajectoryProjection truth = track::project_trajectory(fit, geometry);
  if (!truth.valid || !truth.hittable) return Verdict::kNoImpact;
  if (truth.d_m < options.min_start_distance_m) return Verdict::kTooShort;
  for (double t = 0.0; t < truth.t_impact_s; t += options.sample_dt_s) {
    const Vec2 at = fit.position_at(t);
    if (!track::above_flippers(geometry, at) || touches_board(board, at)) return Verdict::kObstacle;
  }
  out.p0 = p;
  out.v0 = v;
  out.g_mps2 = board.gravity_mps2;
  out.truth = truth;
  return Verdict::kKept;
}

std::uint64_t camera_seed(std::uint64_t seed, std::size_t approach) {
  // One stream per approach, the same for every camera setting (paired comparisons).
  Rng mix(seed ^ (0x9E3779B97F4A7C15ull * (static_cast<std::uint64_t>(approach) + 1)));
  return mix.next_u64();
}

// Errors of one predictor, collected per distance bin, then summarised.
struct ErrorSamples {
  std::size_t observations = 0;
  std::size_t valid = 0;
  std::size_t wrong_flipper = 0;
  std::vector<float> dh, dt_ms, ds, dtheta_deg;

  void clear() {
    observations = valid = wrong_flipper = 0;
    dh.clear();
    dt_ms.clear();
    ds.clear();
    dtheta_deg.clear();
  }
  void append(const ErrorSamples& o) {
    observations += o.observations;
    valid += o.valid;
    wrong_flipper += o.wrong_flipper;
    dh.insert(dh.end(), o.dh.begin(), o.dh.end());
    dt_ms.insert(dt_ms.end(), o.dt_ms.begin(), o.dt_ms.end());
    ds.insert(ds.end(), o.ds.begin(), o.ds.end());
    dtheta_deg.insert(dtheta_deg.end(), o.dtheta_deg.begin(), o.dtheta_deg.end());
  }
};

ErrorStats stats_of(const std::vector<float>& v) {
  ErrorStats s;
  s.count = v.size();
  s.median = quantile(v, 0.5);
  s.p90 = quantile(v, 0.9);
  return s;
}

BinErrors summarise(const ErrorSamples& e) {
  BinErrors b;
  b.observations = e.observations;
  b.valid = e.valid;
  b.valid_fraction = e.observations ? static_cast<double>(e.valid) / static_cast<double>(e.observations) : 0.0;
  b.wrong_flipper = e.wrong_flipper;
  b.abs_dh = stats_of(e.dh);
  b.abs_dt_impact_ms = stats_of(e.dt_ms);
  b.abs_ds_mps = stats_of(e.ds);
  b.abs_dtheta_deg = stats_of(e.dtheta_deg);
  return b;
}

std::size_t distance_bin(double d_m) {
  std::size_t b = 0;
  while (b + 1 < kTrackerDistanceBins && d_m >= kTrackerDistanceBinStart_m[b + 1]) ++b;
  return b;
}

// Records a predictor's projection at observation time t_obs against the truth.
void record(const track::TrajectoryProjection& p, const TrackerApproach& a, const track::FlipperGeometry& geometry,
            ErrorSamples& e) {
  ++e.observations;
  const ProjectionError err = projection_error(p, a, geometry);
  if (!err.valid) return;
  ++e.valid;
  if (err.wrong_flipper) ++e.wrong_flipper;
  e.dh.push_back(static_cast<float>(err.abs_dh));
  e.dt_ms.push_back(static_cast<float>(err.abs_dt_impact_s * 1e3));
  e.ds.push_back(static_cast<float>(err.abs_ds_mps));
  e.dtheta_deg.push_back(static_cast<float>(err.abs_dtheta_deg));
}

// Observations of one approach through a fresh camera, until the true impact.
void observe(const TrackerApproach& a, const track::CameraModelConfig& camera, std::uint64_t seed,
             double sample_dt_s, std::vector<track::Observation>& out) {
  out.clear();
  track::CameraModel cam(camera, seed);
  const track::TrajectoryFit exact = track::exact_trajectory(a.p0, a.v0, a.g_mps2, 0.0);
  track::Observation o;
  for (std::size_t k = 0;; ++k) {
    const double t = static_cast<double>(k) * sample_dt_s;
    if (t >= a.truth.t_impact_s) break;
    cam.expose(t, exact.position_at(t));
    while (cam.deliver(t, o)) out.push_back(o);
  }
}

TrackerSetting run_setting(const table::Board& board, const track::FlipperGeometry& geometry,
                           const std::vector<TrackerApproach>& approaches, const TrackerBenchOptions& options,
                           const track::CameraModelConfig& camera, double g_factor) {
  TrackerSetting setting;
  setting.camera = camera;
  setting.g_factor = g_factor;
  track::TrackerConfig config = track::default_tracker_config(board, camera);
  config.g_mps2 = g_factor * board.gravity_mps2;
  setting.sigma_m = config.sigma_m;
  track::Tracker tracker(geometry, config);

  std::array<std::array<ErrorSamples, kTrackerDistanceBins>, 3> samples;
  std::vector<track::Observation> obs;
  std::vector<track::Observation> seen;
  for (std::size_t i = 0; i < approaches.size(); ++i) {
    const TrackerApproach& a = approaches[i];
    observe(a, camera, camera_seed(options.seed, i), options.sample_dt_s, obs);
    tracker.reset();
    seen.clear();
    for (const track::Observation& o : obs) {
      const std::size_t bin = distance_bin(remaining_distance(a, o.t_s));
      ++setting.observations;
      seen.push_back(o);
      const track::TrackerOutput& out = tracker.update(o, track::ContactSensors{});
      if (out.flushed) ++setting.tracker_flushes;
      record(out.projection, a, geometry, samples[kTracker][bin]);

      // The baselines follow the tracker's critical-area rule so all three
      // answer on the same observations.
      track::TrajectoryProjection two_point;
      track::TrajectoryProjection free_g;
      if (o.p_board.y() <= config.critical_y_m && seen.size() >= 2) {
        const track::Observation& prev = seen[seen.size() - 2];
        const double dt = o.t_s - prev.t_s;
        Vec2 v = (o.p_board - prev.p_board) / dt;
        v.y() -= 0.5 * config.g_mps2 * dt;  // the chord's velocity is the one half a frame back
        two_point = track::project_trajectory(track::exact_trajectory(o.p_board, v, config.g_mps2, o.t_s), geometry);
        // The same points the tracker fitted (approaches are collision-free,
        // so its window is the newest out.window observations).
        const std::size_t n = static_cast<std::size_t>(out.window);
        if (n >= 3 && n <= seen.size()) {
          const std::span<const track::Observation> window(seen.data() + seen.size() - n, n);
          const track::TrajectoryFit fit = track::fit_free_gravity(window, config.sigma_m);
          if (fit.valid) free_g = track::project_trajectory(fit, geometry);
        }
      }
      record(two_point, a, geometry, samples[kTwoPoint][bin]);
      record(free_g, a, geometry, samples[kFreeG][bin]);
    }
  }
  for (std::size_t m = 0; m < samples.size(); ++m) {
    MethodErrors me;
    me.method = kMethodNames[m];
    ErrorSamples pooled;
    for (std::size_t b = 0; b < kTrackerDistanceBins; ++b) {
      me.bins[b] = summarise(samples[m][b]);
      if (kTrackerDistanceBinStart_m[b] >= kTrackerHeadlineDistance_m - 1e-12) pooled.append(samples[m][b]);
    }
    me.beyond_headline = summarise(pooled);
    setting.methods.push_back(std::move(me));
  }
  return setting;
}

double measure_timer_overhead_ns() {
  std::vector<double> d(10'000);
  for (double& x : d) {
    const auto t0 = Clock::now();
    const auto t1 = Clock::now();
    x = std::chrono::duration<double, std::nano>(t1 - t0).count();
  }
  return quantile(std::move(d), 0.5);
}

TrackerCostPoint run_cost_point(const table::Board& board, const track::FlipperGeometry& geometry,
                                const std::vector<TrackerApproach>& approaches,
                                const std::vector<std::vector<track::Observation>>& streams,
                                const track::CameraModelConfig& camera, const std::string& name, int max_window,
                                double window_distance_m, int passes) {
  track::TrackerConfig config = track::default_tracker_config(board, camera);
  config.max_window = max_window;
  config.min_window = max_window;  // the window sits at the cap whenever the history allows
  config.window_distance_m = window_distance_m;
  track::Tracker tracker(geometry, config);
  TrackerCostPoint point;
  point.name = name;
  point.max_window = max_window;
  point.window_distance_m = window_distance_m;
  std::vector<double> times_us;
  std::vector<double> full_us;
  ErrorSamples beyond;
  double window_sum = 0.0;
  std::size_t fitted = 0;
  // Every pass replays the same streams, so the answers repeat; errors are
  // taken from the first, timings pooled over all.
  for (int pass = 0; pass < std::max(1, passes); ++pass) {
    for (std::size_t i = 0; i < approaches.size(); ++i) {
      tracker.reset();
      for (const track::Observation& o : streams[i]) {
        const auto t0 = Clock::now();
        const track::TrackerOutput& out = tracker.update(o, track::ContactSensors{});
        const auto t1 = Clock::now();
        const double us = std::chrono::duration<double, std::micro>(t1 - t0).count();
        times_us.push_back(us);
        if (out.window == max_window) full_us.push_back(us);
        if (pass > 0) continue;
        if (out.window > 0) {
          window_sum += out.window;
          ++fitted;
        }
        if (remaining_distance(approaches[i], o.t_s) >= kTrackerHeadlineDistance_m) {
          record(out.projection, approaches[i], geometry, beyond);
        }
      }
    }
  }
  point.updates = times_us.size();
  point.median_us = quantile(times_us, 0.5);
  point.p99_us = quantile(std::move(times_us), 0.99);
  point.mean_window = fitted ? window_sum / static_cast<double>(fitted) : 0.0;
  point.full_window_updates = full_us.size();
  point.median_us_full_window = quantile(std::move(full_us), 0.5);
  const BinErrors b = summarise(beyond);
  point.median_abs_dh = b.abs_dh.median;
  point.median_abs_dt_impact_ms = b.abs_dt_impact_ms.median;
  point.valid_fraction = b.valid_fraction;
  return point;
}
}  // namespace

bool same_camera(const track::CameraModelConfig& a, const track::CameraModelConfig& b) {
  return a.fps == b.fps && a.m_per_px == b.m_per_px && a.noise_px == b.noise_px;
}

std::string camera_label(const track::CameraModelConfig& c, double g_factor) {
  std::ostringstream s;
  s << c.fps << " fps, " << c.m_per_px * 1e3 << " mm/px, " << c.noise_px << " px, g x" << g_factor;
  return s.str();
}

ProjectionError projection_error(const track::TrajectoryProjection& p, const TrackerApproach& a,
                                 const track::FlipperGeometry& geometry) {
  ProjectionError e;
  if (!p.valid) return e;
  e.valid = true;
  const track::TrajectoryProjection& truth = a.truth;
  if (p.flipper == truth.flipper) {
    e.abs_dh = std::abs(p.h - truth.h);
  } else {
    // The other arm of the 'V': the way along the V through the apex.
    e.wrong_flipper = true;
    e.abs_dh = std::abs((geometry.h_apex[p.flipper] - p.h) + (geometry.h_apex[truth.flipper] - truth.h));
  }
  e.abs_dt_impact_s = std::abs(p.t_observation_s + p.t_impact_s - truth.t_impact_s);
  e.abs_ds_mps = std::abs(p.speed_mps - truth.speed_mps);
  e.abs_dtheta_deg = std::abs(track::fold_to_half_plane(p.angle_rad - truth.angle_rad)) * 180.0 / std::numbers::pi;
  return e;
}

double remaining_distance(const TrackerApproach& a, double t_s) {
  const Vec2 p = track::exact_trajectory(a.p0, a.v0, a.g_mps2, 0.0).position_at(t_s);
  return (p - a.truth.impact_point).norm();
}

std::vector<TrackerApproach> collect_tracker_approaches(const table::Board& board, const TrackerBenchOptions& options,
                                                        ApproachCounts* counts) {
  if (options.approaches < 0) throw std::invalid_argument("tracker bench: approaches must be >= 0");
  if (!(options.sample_dt_s > 0.0)) throw std::invalid_argument("tracker bench: sample_dt_s must be > 0");
  const track::FlipperGeometry geometry = track::flipper_geometry_from_board(board);
  const double critical_y_m = track::default_tracker_config(board, options.headline_camera).critical_y_m;
  sim::ModelWorldOptions wo;
  wo.dt_s = options.sim_dt_s;
  const std::unique_ptr<sim::World> world = sim::make_model_world(board, wo);
  sim::GameState state = sim::make_game_state(board, options.seed);
  sim::BallLimits limits;
  limits.max_ball_time_s = 120.0;

  std::vector<TrackerApproach> approaches;
  approaches.reserve(static_cast<std::size_t>(options.approaches));
  ApproachCounts c;
  const std::size_t wanted = static_cast<std::size_t>(options.approaches);
  // One evaluation per free-flight segment: within a segment the future is
  // one parabola, so a later instant could only shorten the approach.
  bool evaluated = true;
  constexpr std::uint32_t kContactEvents = sim::StepEvents::kHitObstacle | sim::StepEvents::kHitFlipper |
                                           sim::StepEvents::kFlipperPush | sim::StepEvents::kFlipperStall |
                                           sim::StepEvents::kSensor | sim::StepEvents::kBallLost |
                                           sim::StepEvents::kLaunch;
  const auto observer = [&](const sim::GameState& s, const sim::StepEvents& e) {
    if ((e.flags & kContactEvents) != 0) {
      evaluated = false;  // a new segment starts after this step
      return;
    }
    if (evaluated || approaches.size() >= wanted || !s.ball_in_play) return;
    for (const sim::FlipperState& f : s.flippers) {
      if (f.ball_contact) return;
    }
    const Vec2& p = s.ball.position_m;
    const Vec2& v = s.ball.velocity_mps;
    if (p.y() > critical_y_m || !track::above_flippers(geometry, p) || v.norm() < options.min_speed_mps) return;
    evaluated = true;
    ++c.segments;
    TrackerApproach a;
    switch (judge_approach(board, geometry, options, p, v, a)) {
      case Verdict::kKept:
        a.start_time_s = s.time_s;
        approaches.push_back(a);
        ++c.kept;
        break;
      case Verdict::kNoImpact: ++c.no_impact; break;
      case Verdict::kTooShort: ++c.too_short; break;
      case Verdict::kObstacle: ++c.obstacle; break;
    }
  };
  while (approaches.size() < wanted && state.time_s < options.max_simulated_s) {
    sim::play_ball(*world, state, limits, [&](sim::GameState& s) { simlab::oracle_spastic_policy(board, s); },
                   observer);
  }
  c.simulated_s = state.time_s;
  if (counts) *counts = c;
  return approaches;
}

TrackerReport run_tracker_bench(const table::Board& board, const TrackerBenchOptions& options,
                                const std::function<void(const std::string&)>& report_line) {
  const auto start = Clock::now();
  TrackerReport report;
  report.board = board.source;
  report.true_g_mps2 = board.gravity_mps2;
  report.options = options;
  const track::FlipperGeometry geometry = track::flipper_geometry_from_board(board);
  report.flipper_length_m =
      0.5 * (geometry.lines[0].axis().norm() + geometry.lines[1].axis().norm());

  // Stages: the approaches, every camera setting, every g factor, every cost point (the windows and the default).
  const auto progress = staged_progress(
      report_line, "tracker",
      static_cast<int>(1 + options.fps.size() * options.m_per_px.size() * options.noise_px.size() +
                       options.g_factors.size() + options.cost_windows.size() + 1));
  const std::vector<TrackerApproach> approaches = collect_tracker_approaches(board, options, &report.approach_counts);
  report.approaches = approaches.size();
  {
    std::vector<double> d, t, s;
    for (const TrackerApproach& a : approaches) {
      d.push_back(a.truth.d_m);
      t.push_back(a.truth.t_impact_s);
      s.push_back(a.truth.speed_mps);
    }
    report.median_start_distance_m = quantile(d, 0.5);
    report.median_approach_time_s = quantile(t, 0.5);
    report.median_impact_speed_mps = quantile(s, 0.5);
  }
  if (progress) {
    std::ostringstream line;
    const ApproachCounts& c = report.approach_counts;
    line << "approaches: " << c.kept << " kept of " << c.segments << " free-flight segments (" << c.no_impact
         << " miss the V, " << c.too_short << " too short, " << c.obstacle << " touch an obstacle) in "
         << c.simulated_s << " s of play";
    progress(line.str());
  }

  const auto run_one = [&](const track::CameraModelConfig& camera, double g_factor) {
    const auto t0 = Clock::now();
    report.settings.push_back(run_setting(board, geometry, approaches, options, camera, g_factor));
    if (progress) {
      const TrackerSetting& s = report.settings.back();
      std::ostringstream line;
      line << camera_label(camera, g_factor) << ": " << s.observations << " observations, median |dh| >= 5 cm";
      for (const MethodErrors& m : s.methods) line << " " << m.method << " " << m.beyond_headline.abs_dh.median;
      line << " (" << std::chrono::duration<double>(Clock::now() - t0).count() << " s)";
      progress(line.str());
    }
  };
  for (const double fps : options.fps) {
    for (const double res : options.m_per_px) {
      for (const double noise : options.noise_px) {
        track::CameraModelConfig camera = options.headline_camera;
        camera.fps = fps;
        camera.m_per_px = res;
        camera.noise_px = noise;
        run_one(camera, 1.0);
      }
    }
  }
  for (const double f : options.g_factors) run_one(options.headline_camera, f);

  // Cost: every approach through the headline camera, timed update by update.
  report.timer_overhead_ns = measure_timer_overhead_ns();
  std::vector<std::vector<track::Observation>> streams(approaches.size());
  for (std::size_t i = 0; i < approaches.size(); ++i) {
    observe(approaches[i], options.headline_camera, camera_seed(options.seed, i), options.sample_dt_s, streams[i]);
  }
  const track::TrackerConfig defaults = track::default_tracker_config(board, options.headline_camera);
  const auto cost_one = [&](const std::string& name, int max_window, double d_m) {
    report.cost.push_back(run_cost_point(board, geometry, approaches, streams, options.headline_camera, name,
                                         max_window, d_m, options.cost_passes));
    if (progress) {
      const TrackerCostPoint& p = report.cost.back();
      std::ostringstream line;
      line << "cost " << p.name << ": median " << p.median_us << " us, p99 " << p.p99_us << " us per update, mean window "
           << p.mean_window << ", median |dh| " << p.median_abs_dh;
      progress(line.str());
    }
  };
  for (const int w : options.cost_windows) cost_one("window_" + std::to_string(w), w, 1e3);
  cost_one("default", defaults.max_window, defaults.window_distance_m);

  TrackerHeadline& h = report.headline;
  for (const TrackerSetting& s : report.settings) {
    if (s.g_factor != 1.0 || !same_camera(s.camera, options.headline_camera)) continue;
    h.present = s.methods[kTracker].beyond_headline.valid > 0;  // no approaches: nothing to claim
    h.tracker_abs_dh = s.methods[kTracker].beyond_headline.abs_dh.median;
    h.tracker_abs_dt_impact_ms = s.methods[kTracker].beyond_headline.abs_dt_impact_ms.median;
    h.two_point_abs_dh = s.methods[kTwoPoint].beyond_headline.abs_dh.median;
    h.two_point_abs_dt_impact_ms = s.methods[kTwoPoint].beyond_headline.abs_dt_impact_ms.median;
    h.free_g_abs_dh = s.methods[kFreeG].beyond_headline.abs_dh.median;
    h.free_g_abs_dt_impact_ms = s.methods[kFreeG].beyond_headline.abs_dt_impact_ms.median;
    break;
  }
  h.has_cost = report.cost.back().updates > 0;
  h.update_median_us = report.cost.back().median_us;
  h.dh_met = h.present && h.tracker_abs_dh <= kTargetMedianAbsDh;
  h.dt_met = h.present && h.tracker_abs_dt_impact_ms <= kTargetMedianAbsDtImpact_ms;
  h.cost_met = h.has_cost && h.update_median_us <= kTargetMedianUpdate_us;
  h.all_met = h.dh_met && h.dt_met && h.cost_met;
  report.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

}  // namespace pinball::bench
