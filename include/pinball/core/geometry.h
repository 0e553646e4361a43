#pragma once
// Plane geometry in the board frame (metres): the handful of primitives that
// the simulator, the tracker and the renderer share.

#include <utility>
#include <vector>

#include <Eigen/Core>

namespace pinball {

/// A point or vector in the board plane (m, m/s, ...; the name says which).
using Vec2 = Eigen::Vector2d;
/// A point or vector in 3-D board coordinates, z out of the playfield (the twin's ball).
using Vec3 = Eigen::Vector3d;

/// z component of the 3-D cross product of two plane vectors.
inline double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

/// `v` rotated by +90 degrees (counter-clockwise).
inline Vec2 perp_left(const Vec2& v) { return {-v.y(), v.x()}; }

/// Parameter u in [0, 1] of the point of segment [a, b] nearest to p
/// (0 for a degenerate segment).
double closest_param_on_segment(const Vec2& p, const Vec2& a, const Vec2& b);

/// Distance from point p to segment [a, b].
double distance_point_segment(const Vec2& p, const Vec2& a, const Vec2& b);

/// Smallest distance between segments [p0, p1] and [q0, q1] (0 when they cross).
double distance_segment_segment(const Vec2& p0, const Vec2& p1, const Vec2& q0, const Vec2& q1);

/// Whether p lies inside the closed polygon `vertices` (even-odd rule; on an
/// edge counts either way).
bool point_in_polygon(const Vec2& p, const std::vector<Vec2>& vertices);

/// The first two non-adjacent edges of the closed polygon `vertices` that
/// cross or touch, as edge indices (edge i runs from vertex i to i + 1), or
/// {-1, -1} when it is simple. Sorts and sweeps along x: about n log n for an outline
/// whose edges are short beside it, n² at worst.
std::pair<int, int> polygon_self_crossing(const std::vector<Vec2>& vertices);

/// Distance from point p to the axis-aligned box [lo, hi] (0 inside).
double distance_point_box(const Vec2& p, const Vec2& lo, const Vec2& hi);

/// Distance from segment [a, b] to the axis-aligned box [lo, hi] (0 when they touch).
double distance_segment_box(const Vec2& a, const Vec2& b, const Vec2& lo, const Vec2& hi);

/// Real roots of a·t² + b·t + c = 0, computed without cancellation.
struct QuadraticRoots {
  int count = 0;        ///< 0, 1 (double root or linear equation) or 2
  double t0 = 0.0;      ///< smaller root
  double t1 = 0.0;      ///< larger root (== t0 for a double root)
};

/// Solves a·t² + b·t + c = 0. A degenerate a == 0 falls back to the linear root;
/// a == b == 0 yields no roots.
QuadraticRoots solve_quadratic(double a, double b, double c);

}  // namespace pinball
