#pragma once
// What happened during one step of a world: the game events every world
// reports the same way (thesis and event steppers, the twin).

#include <cstdint>

#include "pinball/core/geometry.h"

namespace pinball::sim {

/// What happened during one step (bit flags plus the first index of each kind).
struct StepEvents {
  enum Flag : std::uint32_t {
    kHitObstacle = 1u << 0,     ///< reflected off a static obstacle
    kHitFlipper = 1u << 1,      ///< reflected off a flipper during the ball update
    kFlipperPush = 1u << 2,     ///< a moving flipper swept into the ball and pushed it
    kFlipperStall = 1u << 3,    ///< a flipper stopped because the ball is jammed against a wall
    kSensor = 1u << 4,          ///< the ball entered a sensor or hole
    kBallLost = 1u << 5,        ///< the ball was eaten (or left the table)
    kBankComplete = 1u << 6,    ///< the last flag of a bank fell
    kLeftTable = 1u << 7,       ///< the ball left the table's bounds (also sets kBallLost)
    kLaunch = 1u << 8,          ///< the ball was launched (set by the ball runner, not by a step)
  };
  std::uint32_t flags = 0;       ///< Flag bits
  std::int32_t obstacle = -1;    ///< obstacle hit (kHitObstacle)
  std::int32_t flipper = -1;     ///< flipper hit or pushing (kHitFlipper, kFlipperPush, kFlipperStall)
  std::int32_t sensor = -1;      ///< first sensor entered (kSensor)
  double score_gained = 0.0;     ///< points scored this step
  // Where the ball was lost (kBallLost): the state after the step already holds it in the launcher.
  Vec2 lost_position_m = Vec2::Zero();
  Vec2 lost_velocity_mps = Vec2::Zero();

  bool has(Flag f) const { return (flags & f) != 0; }
};

}  // namespace pinball::sim
