#pragma once
// What a camera reports: where the ball was, and when (thesis 4.1).

#include "pinball/core/geometry.h"

namespace pinball::track {

/// One ball sighting in the board frame.
struct Observation {
  double t_s = 0.0;               ///< exposure time (s), on the same clock as everything else
  Vec2 p_board = Vec2::Zero();    ///< ball centre (m), board frame
  double confidence = 1.0;        ///< detector's confidence in [0, 1]
  double latency_s = 0.0;         ///< how long before its frame was delivered it was exposed (s): the
                                  ///< camera's latency (less the row's offset under a rolling shutter)
};

/// The flipper contact sensors (thesis 4.1.2): true while the ball touches that flipper.
struct ContactSensors {
  bool left = false;   ///< ball on the left flipper
  bool right = false;  ///< ball on the right flipper
};

}  // namespace pinball::track
