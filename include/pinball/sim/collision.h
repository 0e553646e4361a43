#pragma once
// Times of impact along a straight move and the collision response (thesis
// 3.3.2). Shared by every stepper so that steppers differ only in how they
// integrate, never in what a collision does.

#include "pinball/core/geometry.h"
#include "pinball/table/board.h"

namespace pinball::sim {

/// First contact of a moving ball with a shape.
struct Contact {
  double t_s = 0.0;             ///< time from the start of the move (s); 0 if already touching
  Vec2 normal = Vec2::Zero();   ///< unit contact normal, pointing from the surface to the ball
  Vec2 point = Vec2::Zero();    ///< contact point on the surface (m)
};

/// Ball of radius r at p moving with constant v against a one-sided line
/// (thesis eq. 3.3–3.4: the ball's nearest point B − r·n meets the segment).
/// Finds a contact with t in [0, t_max]; a ball already overlapping the front
/// face while approaching it collides at t = 0; a ball behind passes through.
bool line_time_of_impact(const table::Shape& line, const Vec2& p, const Vec2& v, double r, double t_max, Contact& out);

/// Same against a circle of radius `radius_m` (0 = point) centred at c
/// (thesis eq. 3.5). A tangent graze is no contact; an overlapping ball that
/// approaches collides at t = 0.
bool circle_time_of_impact(const Vec2& c, double radius_m, const Vec2& p, const Vec2& v, double r, double t_max,
                           Contact& out);

/// Dispatches on the shape's kind.
bool shape_time_of_impact(const table::Shape& shape, const Vec2& p, const Vec2& v, double r, double t_max, Contact& out);

/// Reflection with reflectivity rho (thesis 3.3.2): mirror v about the surface,
/// then scale the normal component: v − (1 + ρ)(v·n)n.
inline Vec2 reflect(const Vec2& v, const Vec2& n, double rho) { return v - (1.0 + rho) * v.dot(n) * n; }

/// The flipper as a two-sided segment at theta_rad: which face the ball at p
/// is in front of, as a line shape from pivot to tip with that face's normal.
table::Shape flipper_face(const table::Flipper& f, double theta_rad, const Vec2& p);

/// Velocity (m/s) of the flipper's material point at `q` when it turns at omega_rad_s.
Vec2 flipper_point_velocity(const table::Flipper& f, double theta_rad, double omega_rad_s, const Vec2& q);

/// Ball velocity after touching a flipper at point q with contact normal n
/// (thesis 3.3.2, "Collision with a Flipper"): reflect with the flipper's ρ if
/// the ball moves into the face, then add E = μ·(v_q·n)·n when the face at q
/// moves toward the ball with speed v_q·n = l_moment·θ̇.
Vec2 flipper_response(const table::Flipper& f, double theta_rad, double omega_rad_s, const Vec2& q, const Vec2& n,
                      const Vec2& v);

}  // namespace pinball::sim
