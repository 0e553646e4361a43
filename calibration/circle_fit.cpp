#include "pinball/calibration/circle_fit.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>

#include "pinball/core/statistics.h"

namespace pinball::calibration {
namespace {

// Keeps the residuals within trim_mad robust sigmas (1.4826·MAD) of their
// median. Returns how many are kept, or -1 when nothing changed (or all agree).
int trim(const std::vector<double>& r, double trim_mad, std::vector<char>& keep) {
  const double med = median(r);
  const double sigma = robust_sigma(r);
  if (!(sigma > 0.0)) return -1;
  bool changed = false;
  int kept = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const char k = std::abs(r[i] - med) <= trim_mad * sigma ? 1 : 0;
    changed = changed || k != keep[i];
    keep[i] = k;
    kept += k;
  }
  return changed ? kept : -1;
}

// Least-squares meeting point of the lines with keep[i]: sum of (I − d dᵀ)(x − p) = 0.
Vec2 solve_meet(std::span<const Line2> lines, const std::vector<char>& keep) {
  Eigen::Matrix2d a = Eigen::Matrix2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  int n = 0;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (!keep[i]) continue;
    const Eigen::Vector2d d = lines[i].direction.normalized();
    const Eigen::Matrix2d p = Eigen::Matrix2d::Identity() - d * d.transpose();
    a += p;
    b += p * lines[i].point;
    ++n;
  }
  // Parallel lines leave one eigenvalue of `a` near 0 (it is n·sin² of their spread, roughly).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(a);
  if (n < 2 || !(eig.eigenvalues()(0) > 1e-4 * eig.eigenvalues()(1))) {
    throw std::invalid_argument("line meet: the lines are (nearly) parallel");
  }
  return a.ldlt().solve(b);
}

double distance_to(const Line2& l, const Vec2& x) {
  const Vec2 d = l.direction.normalized();
  const Vec2 v = x - l.point;
  return d.x() * v.y() - d.y() * v.x();  // signed: which side of the line
}

// Gauss-Newton on r_i = |p_i − c| − R over the points with keep[i].
void refine(std::span<const Vec2> p, const std::vector<char>& keep, int max_iterations, CircleFit& fit) {
  for (int it = 0; it < max_iterations; ++it) {
    Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
    Eigen::Vector3d jtr = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (!keep[i]) continue;
      const Vec2 d = p[i] - fit.centre;
      const double dist = d.norm();
      if (!(dist > 0.0)) continue;
      const Eigen::Vector3d j(-d.x() / dist, -d.y() / dist, -1.0);
      const double r = dist - fit.radius;
      jtj += j * j.transpose();
      jtr += j * r;
    }
    const Eigen::Vector3d step = jtj.ldlt().solve(-jtr);
    if (!step.allFinite()) throw std::invalid_argument("circle fit: the refinement diverged");
    fit.centre += step.head<2>();
    fit.radius += step(2);
    ++fit.iterations;
    if (step.norm() <= 1e-13 * std::max(1.0, fit.radius)) break;
  }
  if (!(fit.radius > 0.0) || !fit.centre.allFinite()) throw std::invalid_argument("circle fit: the refinement diverged");
}

}  // namespace

CircleFit fit_circle_algebraic(std::span<const Vec2> p) {
  const std::size_t n = p.size();
  if (n < 3) throw std::invalid_argument("circle fit: " + std::to_string(n) + " points; at least 3 needed");
  Vec2 mean = Vec2::Zero();
  for (const Vec2& q : p) mean += q;
  mean /= static_cast<double>(n);
  double mxx = 0, myy = 0, mxy = 0, mxz = 0, myz = 0, mzz = 0;
  for (const Vec2& q : p) {
    const double x = q.x() - mean.x(), y = q.y() - mean.y(), z = x * x + y * y;
    mxx += x * x;
    myy += y * y;
    mxy += x * y;
    mxz += x * z;
    myz += y * z;
    mzz += z * z;
  }
  const double inv = 1.0 / static_cast<double>(n);
  mxx *= inv, myy *= inv, mxy *= inv, mxz *= inv, myz *= inv, mzz *= inv;
  const double mz = mxx + myy;
  const double cov_xy = mxx * myy - mxy * mxy;
  const double var_z = mzz - mz * mz;
  const double a3 = 4.0 * mz;
  const double a2 = -3.0 * mz * mz - mzz;
  const double a1 = var_z * mz + 4.0 * cov_xy * mz - mxz * mxz - myz * myz;
  const double a0 = mxz * (mxz * myy - myz * mxy) + myz * (myz * mxx - mxz * mxy) - var_z * cov_xy;
  // Newton from x = 0 for the smallest root of the characteristic polynomial.
  double x = 0.0, y = a0;
  for (int it = 0; it < 99; ++it) {
    const double dy = a1 + x * (2.0 * a2 + 3.0 * a3 * x);
    const double x_new = x - y / dy;
    if (x_new == x || !std::isfinite(x_new)) break;
    const double y_new = a0 + x_new * (a1 + x_new * (a2 + x_new * a3));
    if (std::abs(y_new) >= std::abs(y)) break;
    x = x_new;
    y = y_new;
  }
  const double det = x * x - x * mz + cov_xy;
  // Collinear points: the centre runs off to infinity.
  if (!(std::abs(det) > 1e-12 * mz * mz)) throw std::invalid_argument("circle fit: the points are (nearly) collinear");
  const double cx = (mxz * (myy - x) - myz * mxy) / det / 2.0;
  const double cy = (myz * (mxx - x) - mxz * mxy) / det / 2.0;
  CircleFit fit;
  fit.centre = mean + Vec2{cx, cy};
  fit.radius = std::sqrt(cx * cx + cy * cy + mz);
  if (!fit.centre.allFinite() || !std::isfinite(fit.radius) || fit.radius > 1e6 * std::sqrt(mz)) {
    throw std::invalid_argument("circle fit: the points are (nearly) collinear");
  }
  double ss = 0.0;
  for (const Vec2& q : p) ss += std::pow((q - fit.centre).norm() - fit.radius, 2);
  fit.rms = std::sqrt(ss * inv);
  fit.points = static_cast<int>(n);
  return fit;
}

CircleFit fit_circle(std::span<const Vec2> p, const CircleFitOptions& options) {
  CircleFit fit = fit_circle_algebraic(p);
  std::vector<char> keep(p.size(), 1);
  refine(p, keep, options.max_iterations, fit);
  for (int round = 0; round < options.trim_rounds; ++round) {
    std::vector<double> r;
    for (std::size_t i = 0; i < p.size(); ++i) r.push_back((p[i] - fit.centre).norm() - fit.radius);
    const int kept = trim(r, options.trim_mad, keep);
    if (kept < 0) break;
    if (kept < 3) throw std::invalid_argument("circle fit: fewer than 3 points left after trimming outliers");
    refine(p, keep, options.max_iterations, fit);
  }
  double ss = 0.0;
  fit.points = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!keep[i]) continue;
    ss += std::pow((p[i] - fit.centre).norm() - fit.radius, 2);
    ++fit.points;
  }
  fit.rejected = static_cast<int>(p.size()) - fit.points;
  fit.rms = std::sqrt(ss / fit.points);
  return fit;
}

LinesMeet meet_lines(std::span<const Line2> lines, const CircleFitOptions& options) {
  if (lines.size() < 2) throw std::invalid_argument("line meet: " + std::to_string(lines.size()) + " lines; at least 2 needed");
  std::vector<char> keep(lines.size(), 1);
  LinesMeet m;
  m.point = solve_meet(lines, keep);
  for (int round = 0; round < options.trim_rounds; ++round) {
    std::vector<double> r;
    for (const Line2& l : lines) r.push_back(distance_to(l, m.point));
    const int kept = trim(r, options.trim_mad, keep);
    if (kept < 0) break;
    if (kept < 2) throw std::invalid_argument("line meet: fewer than 2 lines left after trimming outliers");
    m.point = solve_meet(lines, keep);
  }
  double ss = 0.0;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (!keep[i]) continue;
    ss += std::pow(distance_to(lines[i], m.point), 2);
    ++m.lines;
  }
  m.rejected = static_cast<int>(lines.size()) - m.lines;
  m.rms = std::sqrt(ss / m.lines);
  return m;
}

}  // namespace pinball::calibration
