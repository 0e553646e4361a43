#pragma once
// The camera latency procedure played on the simulated camera, whose latency
// is known: a board's flipper is fired N times at random phases against the
// frames; after the actuation delay it swings from the down stop to the up
// stop with constant angular acceleration (a solenoid), is held, and falls
// back when released. The camera (SimCameraRealism::typical() by default)
// draws it as it was while each row was exposed and delivers each frame its
// latency later; the frames and the command times are what
// calibration::measure_latency reads, the camera's minimum latency the truth
// to compare with.

#include <cstdint>
#include <vector>

#include "pinball/calibration/latency_calibration.h"
#include "pinball/firmware/flipper_actuation.h"
#include "pinball/simlab/sim_camera_source.h"
#include "pinball/table/board.h"

namespace pinball::simlab {

/// How the simulated run is set up.
struct SimLatencyOptions {
  std::uint64_t seed = 1;              ///< the camera's art and noise, and the events' phases
  int events = 20;                     ///< times the flipper is fired
  std::size_t flipper = 0;             ///< which of the board's flippers (board order)
  SimCameraConfig camera = typical_camera();  ///< the camera (its seed is replaced by `seed`)
  double actuation_delay_s = firmware::kDefaultActuationDelay_s;  ///< command to the flipper's first motion (s)
  double stroke_s = 0.025;             ///< down stop to up stop, at constant angular acceleration (s)
  double hold_s = 0.1;                 ///< the coil is held on this long (s)
  double return_s = 0.04;              ///< up stop back to the down stop once the coil is off (s)
  double spacing_s = 0.4;              ///< from one command to the next (s), plus a random part of a frame period
  double lead_in_s = 0.7;              ///< frames before the first command (s): the frame clock settles
  double step_s = 1e-4;                ///< simulation step (s)
  std::vector<int> dead_events;        ///< events (from 0) whose flipper does not move: a coil that failed

  /// A 640x480 200 fps camera with SimCameraRealism::typical().
  static SimCameraConfig typical_camera();
};

/// What the run recorded and the truth behind it.
struct SimLatencyRun {
  calibration::FlipperRegion region;        ///< the flipper's region through the camera's true mapping
  calibration::LatencyRecording recording;  ///< the frames (the region only) and the command times
  calibration::LatencyOptions timing;       ///< frame period, row time, exposure and actuation delay as the lab gives them
  double true_latency_s = 0.0;              ///< the camera's minimum latency: what the measurement should find (s)
  double true_mean_latency_s = 0.0;         ///< the mean latency of the frames delivered (s)
  std::uint64_t frames_dropped = 0;         ///< frames the camera lost
};

/// The shortest step (s) at which the camera's history spans its frame
/// period, exposure and latency: a slow camera or a long latency needs a
/// longer one than SimLatencyOptions' default (at most 1 ms works).
double min_latency_step_s(const SimCameraConfig& camera);

/// Plays the procedure. Throws std::invalid_argument for a bad option (no
/// such flipper, a step that the camera's history cannot hold, ...).
SimLatencyRun simulate_latency_run(const table::Board& board, const SimLatencyOptions& options);

}  // namespace pinball::simlab
