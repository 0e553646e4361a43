#pragma once
// One step of the event stepper as a chain of stages over one context, in the
// manner of Box2D's solver: classify the ball's contacts (event_contact.cpp),
// choose a horizon and search it for the earliest event (event_search.cpp),
// advance to it and respond (event_response.cpp); event_stepper.cpp runs the
// loop. Internal to pinball_sim.

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <span>

#include "pinball/core/geometry.h"
#include "pinball/sim/broadphase.h"
#include "pinball/sim/event_stepper.h"
#include "pinball/sim/game_state.h"
#include "pinball/table/board.h"

namespace pinball::sim::event {

// Cells one box query may cover; the query horizon is chosen so that the
// ball's path box spans at most 2 x 2 cells.
constexpr int kMaxLists = 4;

/// Uniformly accelerated motion: p(τ) = p + v·τ + ½·a·τ².
struct Motion {
  Vec2 p = Vec2::Zero();
  Vec2 v = Vec2::Zero();
  Vec2 a = Vec2::Zero();
  Vec2 pos(double t) const { return p + t * (v + 0.5 * t * a); }
  Vec2 vel(double t) const { return v + t * a; }
};

/// Cell lists merged in ascending index order without duplicates.
struct CandidateLists {
  std::array<std::span<const std::int32_t>, kMaxLists> lists{};
  int count = 0;

  template <class Fn>
  void for_each(Fn&& fn) const {
    if (count == 1) {
      for (const std::int32_t i : lists[0]) fn(i);
      return;
    }
    std::array<std::size_t, kMaxLists> at{};
    while (true) {
      std::int32_t next = std::numeric_limits<std::int32_t>::max();
      for (int k = 0; k < count; ++k) {
        if (at[k] < lists[k].size()) next = std::min(next, lists[k][at[k]]);
      }
      if (next == std::numeric_limits<std::int32_t>::max()) return;
      fn(next);
      for (int k = 0; k < count; ++k) {
        if (at[k] < lists[k].size() && lists[k][at[k]] == next) ++at[k];
      }
    }
  }
};

/// How the ball moves until the next event.
enum class Mode { kFlight, kSlide, kRest };
/// What the next event is.
enum class Kind { kHorizon, kObstacle, kFlipper, kFlipperStop, kSensor, kEdge };
/// What a touching surface is.
enum class Surface { kNone, kObstacle, kFlipperFace, kFlipperEnd };

/// The earliest event found so far.
struct Next {
  double t = 0.0;  ///< time from now (s)
  Kind kind = Kind::kHorizon;
  std::int32_t index = -1;  ///< obstacle, flipper or sensor
  Vec2 normal = Vec2::Zero();  ///< contact normal, towards the ball
  Vec2 point = Vec2::Zero();   ///< contact point (flippers)
};

/// A surface the ball touches, and the stretch of it the ball may slide on.
struct Touch {
  Surface surface = Surface::kNone;
  std::int32_t index = -1;
  double gap = 0.0;
  Vec2 normal = Vec2::Zero();
  Vec2 origin = Vec2::Zero();   // where u = 0 along the tangent
  Vec2 tangent = Vec2::Zero();
  double u_lo = 0.0;
  double u_hi = 0.0;
};

/// One step's working state: what the stepper fixed at construction, the
/// ball's current mode and motion, and the candidates near it.
struct StepContext {
  // Fixed for the step (EventStepper's constructor derived the tolerances).
  const table::Board& board;
  const EventStepperOptions& options;
  const UniformGrid& obstacle_grid;
  const UniformGrid& sensor_grid;
  std::span<const std::int32_t> all_obstacles;  // 0..n-1 for use_grid = false
  std::span<const std::int32_t> all_sensors;
  double length_tol_m = 0.0;
  double touch_m = 0.0;
  double touch_speed_mps = 0.0;
  double separation_speed_mps = 0.0;
  double circle_slide_m = 0.0;
  double r = 0.0;                 // ball radius (m)
  Vec2 gravity = Vec2::Zero();    // (m/s²)

  // What the step changes.
  GameState& state;
  StepEvents& events;
  Mode mode = Mode::kFlight;
  Touch contact{};  // the surface the ball slides on (kSlide)
  Motion m{};
  CandidateLists obstacles{};
  CandidateLists sensors{};
  Vec2 box_lo = Vec2::Zero();
  Vec2 box_hi = Vec2::Zero();
  double speed_bound = 0.0;  // |v| + |a|·h: the fastest the ball moves over the horizon
  double t_tol = 0.0;        // time tolerance of the roots over the horizon
};

/// Whether the ball slides on this surface now.
inline bool is_contact(const StepContext& ctx, Surface s, std::int32_t index) {
  return ctx.mode == Mode::kSlide && ctx.contact.surface == s && ctx.contact.index == index;
}

// ---- Contact mode (event_contact.cpp) ---------------------------------------

/// Sets the mode, the contact and the acceleration from the surfaces the ball
/// touches now (snapping a sliding ball onto its surface).
void classify(StepContext& ctx);

// ---- Event search (event_search.cpp) ----------------------------------------

/// Starts the motion from the ball's state and picks the horizon (at most
/// remaining_s) and the candidates near the ball's path over it.
double choose_horizon(StepContext& ctx, double remaining_s);

/// A turning flipper reaching its stop.
void find_flipper_stops(const StepContext& ctx, Next& next);
/// The ball meeting a static obstacle.
void find_obstacle_impact(const StepContext& ctx, Next& next);
/// The ball sliding off the end of its contact surface.
void find_edge(const StepContext& ctx, Next& next);
/// The ball entering a sensor or a hole.
void find_sensor_entry(const StepContext& ctx, Next& next);
/// The ball meeting a flipper, stopped or turning.
void find_flipper_impact(const StepContext& ctx, Next& next);

// ---- Collision response (event_response.cpp) --------------------------------

/// Applies the event the ball has just been advanced to.
void handle(StepContext& ctx, const Next& next);

}  // namespace pinball::sim::event
