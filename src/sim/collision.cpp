#include "pinball/sim/collision.h"

#include <algorithm>
#include <cmath>

namespace pinball::sim {

bool line_time_of_impact(const table::Shape& line, const Vec2& p, const Vec2& v, double r, double t_max, Contact& out) {
  const Vec2& n = line.normal;
  const double vn = v.dot(n);
  if (vn >= 0.0) return false;                  // moving along or away from the face
  const double s = (p - line.p0).dot(n);        // signed distance of the centre
  if (s < 0.0) return false;                    // behind a one-sided line: passes through
  const double t = s > r ? (s - r) / -vn : 0.0;  // overlapping the face: touch now
  if (t > t_max) return false;
  // The ball's nearest point at contact; for an overlapping ball, the centre's foot on the line.
  const Vec2 foot = p + t * v - std::min(s, r) * n;
  const Vec2 ab = line.p1 - line.p0;
  const double u = (foot - line.p0).dot(ab) / ab.squaredNorm();
  if (u < 0.0 || u > 1.0) return false;
  out.t_s = t;
  out.normal = n;
  out.point = line.p0 + u * ab;
  return true;
}

bool circle_time_of_impact(const Vec2& c, double radius_m, const Vec2& p, const Vec2& v, double r, double t_max,
                           Contact& out) {
  const Vec2 d = p - c;
  const double b = d.dot(v);
  if (b >= 0.0) return false;  // moving away or tangentially
  const double reach = r + radius_m;
  const double cc = d.squaredNorm() - reach * reach;
  double t = 0.0;
  if (cc > 0.0) {
    const double a = v.squaredNorm();
    const double disc = b * b - a * cc;
    if (disc <= 0.0) return false;  // miss or tangent graze (thesis: one root is no hit)
    t = cc / (-b + std::sqrt(disc));  // smaller root without cancellation
    if (t > t_max) return false;
  }
  const Vec2 at = p + t * v - c;
  const double dist = at.norm();
  if (dist <= 0.0) return false;  // centres coincide: no defined normal
  out.t_s = t;
  out.normal = at / dist;
  out.point = c + radius_m * out.normal;
  return true;
}

bool shape_time_of_impact(const table::Shape& shape, const Vec2& p, const Vec2& v, double r, double t_max, Contact& out) {
  if (shape.kind == table::ShapeKind::kLine) return line_time_of_impact(shape, p, v, r, t_max, out);
  return circle_time_of_impact(shape.p0, shape.radius_m, p, v, r, t_max, out);
}

double wall_friction_loss_mps(double tangential_mps, double normal_in_mps, double normal_change_mps, double mu) {
  const double along = std::abs(tangential_mps);
  const double slip = std::hypot(along, normal_in_mps);
  if (!(mu > 0.0) || !(along > 0.0) || !(normal_change_mps > 0.0)) return 0.0;
  // A solid sphere: a unit impulse changes the contact's slip by 1 + 5/2.
  constexpr double kSlipPerImpulse = 3.5;
  const double impulse = mu * normal_change_mps;
  if (kSlipPerImpulse * impulse >= slip) return along / kSlipPerImpulse;  // the contact sticks
  return impulse * along / slip;
}

Vec2 obstacle_response(const table::Obstacle& o, const Vec2& n, const Vec2& v) {
  const double vn = v.dot(n);
  Vec2 out = reflect(v, n, o.rho);
  if (o.friction > 0.0 && vn < 0.0) {
    const Vec2 tangential = v - vn * n;
    const double speed = tangential.norm();
    const double loss = wall_friction_loss_mps(speed, -vn, (1.0 + o.rho) * -vn + o.action.kick_mps, o.friction);
    if (loss > 0.0) out -= (loss / speed) * tangential;
  }
  return out + o.action.kick_mps * n;
}

table::Shape flipper_face(const table::Flipper& f, double theta_rad, const Vec2& p) {
  table::Shape face;
  face.kind = table::ShapeKind::kLine;
  face.p0 = f.pivot;
  face.p1 = table::flipper_tip(f, theta_rad);
  const Vec2 up = table::flipper_up_normal(f, theta_rad);
  face.normal = (p - f.pivot).dot(up) >= 0.0 ? up : Vec2(-up);
  return face;
}

Vec2 flipper_point_velocity(const table::Flipper& f, double theta_rad, double omega_rad_s, const Vec2& q) {
  const double arm_m = (q - f.pivot).dot(table::flipper_direction(f, theta_rad));
  return omega_rad_s * arm_m * table::flipper_up_normal(f, theta_rad);
}

Vec2 flipper_response(const table::Flipper& f, double theta_rad, double omega_rad_s, const Vec2& q, const Vec2& n,
                      const Vec2& v) {
  Vec2 out = v.dot(n) < 0.0 ? reflect(v, n, f.rho) : v;
  const double face_speed = flipper_point_velocity(f, theta_rad, omega_rad_s, q).dot(n);
  if (face_speed > 0.0) out += f.mu * face_speed * n;
  return out;
}

}  // namespace pinball::sim
