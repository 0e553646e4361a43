#include "pinball/core/geometry.h"

#include <algorithm>
#include <cmath>

namespace pinball {

double closest_param_on_segment(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  if (len2 <= 0.0) return 0.0;
  return std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
}

double distance_point_segment(const Vec2& p, const Vec2& a, const Vec2& b) {
  const double u = closest_param_on_segment(p, a, b);
  return (p - (a + u * (b - a))).norm();
}

double distance_segment_segment(const Vec2& p0, const Vec2& p1, const Vec2& q0, const Vec2& q1) {
  // Proper crossing: each segment's end points lie on opposite sides of the other.
  const Vec2 dp = p1 - p0;
  const Vec2 dq = q1 - q0;
  const double s0 = cross(dp, q0 - p0);
  const double s1 = cross(dp, q1 - p0);
  const double s2 = cross(dq, p0 - q0);
  const double s3 = cross(dq, p1 - q0);
  if (((s0 < 0.0 && s1 > 0.0) || (s0 > 0.0 && s1 < 0.0)) &&
      ((s2 < 0.0 && s3 > 0.0) || (s2 > 0.0 && s3 < 0.0))) {
    return 0.0;
  }
  return std::min({distance_point_segment(p0, q0, q1), distance_point_segment(p1, q0, q1),
                   distance_point_segment(q0, p0, p1), distance_point_segment(q1, p0, p1)});
}

bool point_in_polygon(const Vec2& p, const std::vector<Vec2>& vertices) {
  bool inside = false;
  for (std::size_t i = 0, j = vertices.size() - 1; i < vertices.size(); j = i++) {
    const Vec2& a = vertices[i];
    const Vec2& b = vertices[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y())) {
      inside = !inside;
    }
  }
  return inside;
}

std::pair<int, int> polygon_self_crossing(const std::vector<Vec2>& vertices) {
  // Sort and sweep along x: only edges whose x extents overlap can cross, so an outline of
  // thousands of vertices (an arc from CAD) is checked in about n log n, not n².
  const std::size_t n = vertices.size();
  const auto x_lo = [&](std::size_t e) { return std::min(vertices[e].x(), vertices[(e + 1) % n].x()); };
  const auto x_hi = [&](std::size_t e) { return std::max(vertices[e].x(), vertices[(e + 1) % n].x()); };
  const auto y_lo = [&](std::size_t e) { return std::min(vertices[e].y(), vertices[(e + 1) % n].y()); };
  const auto y_hi = [&](std::size_t e) { return std::max(vertices[e].y(), vertices[(e + 1) % n].y()); };
  std::vector<std::size_t> by_x_lo(n);
  for (std::size_t e = 0; e < n; ++e) by_x_lo[e] = e;
  std::sort(by_x_lo.begin(), by_x_lo.end(), [&](std::size_t a, std::size_t b) { return x_lo(a) < x_lo(b); });
  std::pair<int, int> first{-1, -1};
  std::vector<std::size_t> open;  // edges whose x extent reaches the sweep line
  for (const std::size_t e : by_x_lo) {
    const double x = x_lo(e);
    std::erase_if(open, [&](std::size_t o) { return x_hi(o) < x; });
    for (const std::size_t o : open) {
      const std::size_t i = std::min(e, o);
      const std::size_t k = std::max(e, o);
      if (k == i + 1 || (i == 0 && k == n - 1)) continue;  // neighbours share a vertex
      if (y_hi(i) < y_lo(k) || y_hi(k) < y_lo(i)) continue;
      // The same pair as the pairwise scan reports: the first in (i, k) order.
      const std::pair<int, int> pair{static_cast<int>(i), static_cast<int>(k)};
      if (first.first >= 0 && pair >= first) continue;
      if (distance_segment_segment(vertices[i], vertices[(i + 1) % n], vertices[k], vertices[(k + 1) % n]) == 0.0) {
        first = pair;
      }
    }
    open.push_back(e);
  }
  return first;
}

double distance_point_box(const Vec2& p, const Vec2& lo, const Vec2& hi) {
  const double dx = std::max({lo.x() - p.x(), 0.0, p.x() - hi.x()});
  const double dy = std::max({lo.y() - p.y(), 0.0, p.y() - hi.y()});
  return std::hypot(dx, dy);
}

double distance_segment_box(const Vec2& a, const Vec2& b, const Vec2& lo, const Vec2& hi) {
  const auto inside = [&](const Vec2& p) {
    return p.x() >= lo.x() && p.x() <= hi.x() && p.y() >= lo.y() && p.y() <= hi.y();
  };
  if (inside(a) || inside(b)) return 0.0;
  const Vec2 c00 = lo;
  const Vec2 c10{hi.x(), lo.y()};
  const Vec2 c11 = hi;
  const Vec2 c01{lo.x(), hi.y()};
  return std::min({distance_segment_segment(a, b, c00, c10), distance_segment_segment(a, b, c10, c11),
                   distance_segment_segment(a, b, c11, c01), distance_segment_segment(a, b, c01, c00)});
}

QuadraticRoots solve_quadratic(double a, double b, double c) {
  QuadraticRoots r;
  if (a == 0.0) {
    if (b == 0.0) return r;
    r.count = 1;
    r.t0 = r.t1 = -c / b;
    return r;
  }
  const double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return r;
  if (disc == 0.0) {
    r.count = 1;
    r.t0 = r.t1 = -b / (2.0 * a);
    return r;
  }
  // q has the sign of b, so b + sign(b)·sqrt(disc) never cancels.
  const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
  double x0 = q / a;
  double x1 = (q != 0.0) ? c / q : -x0;
  if (x0 > x1) std::swap(x0, x1);
  r.count = 2;
  r.t0 = x0;
  r.t1 = x1;
  return r;
}

}  // namespace pinball
