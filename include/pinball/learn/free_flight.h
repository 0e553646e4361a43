#pragma once
// Free flights in recorded play, and the gravity that bends them (issue 20).
// A free flight is a run of frames in which the ball touches nothing: its
// surface stays clear of every obstacle and of every flipper's sweep, the
// contact switches are open, no frame is missing for long, and one parabola
// fits it within the camera's noise (the tracker's χ² test, so a collision
// that happens away from the board's obstacles still ends it). All free
// flights of a recording share one acceleration: the board's g along −y, a
// sideways tilt along x, and (as a diagnostic: the model has no such term) a
// linear drag −c·v. They are fitted together by Levenberg–Marquardt (Eigen's),
// each flight's start position and velocity eliminated by linear least
// squares at every step (variable projection), so the solver sees 2 or 3
// unknowns however many flights there are.

#include <cstddef>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "pinball/bus/recorded_play.h"
#include "pinball/core/name_value.h"
#include "pinball/table/board.h"
#include "pinball/track/trajectory_fit.h"

namespace pinball::learn {

/// How free flights are found.
struct FlightOptions {
  double sigma_m = 0.001;          ///< standard deviation of one detected coordinate (m)
  double clearance_m = 0.003;      ///< the ball's surface at least this far from every obstacle and flipper sweep (m)
  int min_points = 8;              ///< a flight needs at least this many frames
  double min_duration_s = 0.04;    ///< ... spanning at least this long (s)
  double max_gap_s = 0.0125;       ///< a longer gap between sightings ends a flight (s; 2.5 frames at 200 fps)
  double min_speed_mps = 0.05;     ///< a slower ball is resting against something, not flying (m/s)
};

/// One free flight: frames [first, last] of one recording, and its own
/// parabola (g free along y, as track::fit_free_gravity fits it).
struct FreeFlight {
  std::size_t recording = 0;  ///< index into the recordings
  std::size_t first = 0;      ///< first frame (index into RecordedPlay::frames)
  std::size_t last = 0;       ///< last frame, inclusive
  double t_first_s = 0.0;     ///< the first frame's time (s)
  double t_last_s = 0.0;      ///< the last frame's time (s)
  track::TrajectoryFit fit;   ///< referred to the last frame's time
};

/// Every free flight of `play` (recording index `recording`), in time order.
std::vector<FreeFlight> find_free_flights(const bus::RecordedPlay& play, std::size_t recording,
                                          const table::Board& board, const FlightOptions& options = {});

/// True when the ball at `p` (m) is clear of every obstacle and every
/// flipper's sweep by `clearance_m` (its surface; the board's ball radius).
bool ball_is_clear(const table::Board& board, const Vec2& p, double clearance_m);

/// True when the ball at `p` (m) is clear of every flipper's sweep, from
/// down stop to up stop, by `clearance_m`.
bool ball_clear_of_flippers(const table::Board& board, const Vec2& p, double clearance_m);

/// What the shared acceleration of the free flights is.
struct FlightGravity {
  double g_mps2 = 0.0;               ///< along −y (m/s²)
  double lateral_mps2 = 0.0;         ///< along +x: a table tilted sideways (m/s²)
  double drag_per_s = 0.0;           ///< c in −c·v (1/s); 0 when not fitted
  bool drag_fitted = false;          ///< c was a free parameter
  double g_stderr_mps2 = 0.0;        ///< standard uncertainty of g: bootstrap over flights when run, else the fit's covariance
  double lateral_stderr_mps2 = 0.0;  ///< same for the tilt
  double drag_stderr_per_s = 0.0;    ///< same for c
  double g_covariance_stderr_mps2 = 0.0;  ///< the fit's covariance alone (assumes independent frames)
  int bootstrap_resamples = 0;       ///< resamples behind the stderr (0: covariance)
  int flights = 0;                   ///< flights in the fit (after dropping the ones no shared acceleration fits)
  int flights_dropped = 0;           ///< flights left out: χ² beyond the 99.9 % level under the shared fit
  std::size_t points = 0;            ///< frames in the fit
  double rms_nominal_m = 0.0;        ///< RMS residual per coordinate with the board's g, no tilt, no drag (m)
  double rms_fitted_m = 0.0;         ///< ... with the fitted acceleration (m)

  /// Every figure, for --json (core/json_write_archive.h).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(g_mps2));
    a->Visit(PINBALL_NVP(g_stderr_mps2));
    a->Visit(PINBALL_NVP(g_covariance_stderr_mps2));
    a->Visit(PINBALL_NVP(lateral_mps2));
    a->Visit(PINBALL_NVP(lateral_stderr_mps2));
    a->Visit(PINBALL_NVP(drag_fitted));
    a->Visit(PINBALL_NVP(drag_per_s));
    a->Visit(PINBALL_NVP(drag_stderr_per_s));
    a->Visit(PINBALL_NVP(bootstrap_resamples));
    a->Visit(PINBALL_NVP(flights));
    a->Visit(PINBALL_NVP(flights_dropped));
    a->Visit(PINBALL_NVP(points));
    a->Visit(PINBALL_NVP(rms_nominal_m));
    a->Visit(PINBALL_NVP(rms_fitted_m));
  }
};

/// Fits the acceleration every flight shares. `recordings[f.recording]`
/// holds each flight's frames. `nominal_g_mps2` starts the search and gives
/// the "before" residual. With `fit_drag` c is free, else 0. `bootstrap`
/// resamples of the flights (0: none) give the stderrs, drawn from `seed`;
/// `progress(done, total)` is called with 0 before the first and after each. Throws std::runtime_error
/// with fewer than 2 flights.
FlightGravity fit_flight_gravity(std::span<const bus::RecordedPlay> recordings, std::span<const FreeFlight> flights,
                                 double nominal_g_mps2, double sigma_m, bool fit_drag, int bootstrap,
                                 std::uint64_t seed, const std::function<void(int, int)>& progress = {});

/// What the flights that skid say of the playfield's sliding friction. A
/// ball that bounces keeps the spin it rolled with, so it skids until the
/// playfield's friction, μ·g_n against the slip, has made it roll again; on
/// the way its acceleration is the slope's plus that friction, where a
/// rolling ball's is 5/7 of the slope's (a solid ball). So a skidding
/// flight's own acceleration a gives μ·g_n = |a − (7/5)·a_rolling|, with
/// a_rolling the shared acceleration of the flights (most roll). A
/// diagnostic: the model's ball has no spin and never skids.
struct SlidingFriction {
  int flights = 0;                ///< flights long enough to judge (min_duration_s)
  int skidding = 0;               ///< of them, flights whose own acceleration fits beyond the 99.9 % point of χ²(2)
  double decel_mps2 = 0.0;        ///< μ·g_n: the median over the skidding flights (m/s²); 0 with none
  double decel_stderr_mps2 = 0.0; ///< its standard uncertainty (the median's, from the spread; m/s²)
  double min_duration_s = 0.0;    ///< the shortest flight judged (s)

  /// Every figure, for --json (core/json_write_archive.h).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(flights));
    a->Visit(PINBALL_NVP(skidding));
    a->Visit(PINBALL_NVP(decel_mps2));
    a->Visit(PINBALL_NVP(decel_stderr_mps2));
    a->Visit(PINBALL_NVP(min_duration_s));
  }
};

/// The sliding friction the skidding flights among `flights` show (see
/// SlidingFriction), against the shared acceleration `gravity` (what
/// fit_flight_gravity found). Only flights of at least `min_duration_s` are
/// judged: a short one measures its acceleration too coarsely to tell.
SlidingFriction fit_sliding_friction(std::span<const bus::RecordedPlay> recordings,
                                     std::span<const FreeFlight> flights, const FlightGravity& gravity,
                                     double sigma_m, double min_duration_s = 0.1);

}  // namespace pinball::learn
