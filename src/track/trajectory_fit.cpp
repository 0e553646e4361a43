#include "pinball/track/trajectory_fit.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace pinball::track {
namespace {

// Times of the window relative to the newest sample, and their spread (s):
// below this the points are simultaneous and velocity is unobservable.
constexpr double kMinTimeSpan_s = 1e-9;

bool usable(std::span<const Observation> obs) {
  return obs.size() >= 3 && std::abs(obs.back().t_s - obs.front().t_s) > kMinTimeSpan_s;
}

// Point count, degrees of freedom and χ² of a solved fit over its observations.
void finish(TrajectoryFit& fit, std::span<const Observation> obs, int parameters, double sigma_m) {
  fit.points = static_cast<int>(obs.size());
  fit.dof = 2 * fit.points - parameters;
  double chi2 = 0.0;
  for (const Observation& o : obs) chi2 += (o.p_board - fit.position_at(o.t_s)).squaredNorm();
  fit.chi2 = sigma_m > 0.0 ? chi2 / (sigma_m * sigma_m) : 0.0;
}

}  // namespace

TrajectoryFit exact_trajectory(const Vec2& p_ref, const Vec2& v_ref, double g_mps2, double t_ref_s) {
  TrajectoryFit fit;
  fit.valid = true;
  fit.t_ref_s = t_ref_s;
  fit.p_ref = p_ref;
  fit.v_ref = v_ref;
  fit.g_mps2 = g_mps2;
  return fit;
}

TrajectoryFit fit_fixed_gravity(std::span<const Observation> obs, double g_mps2, double sigma_m) {
  TrajectoryFit fit;
  if (!usable(obs)) return fit;
  const double t_ref = obs.back().t_s;
  // Both coordinates share the design matrix [1 τ]: accumulate its normal
  // equations once, with y corrected for the known gravity term.
  Eigen::Matrix2d ata = Eigen::Matrix2d::Zero();
  Eigen::Vector2d atx = Eigen::Vector2d::Zero();
  Eigen::Vector2d aty = Eigen::Vector2d::Zero();
  for (const Observation& o : obs) {
    const double tau = o.t_s - t_ref;
    const double y = o.p_board.y() + 0.5 * g_mps2 * tau * tau;
    ata(0, 0) += 1.0;
    ata(0, 1) += tau;
    ata(1, 1) += tau * tau;
    atx += Eigen::Vector2d{o.p_board.x(), o.p_board.x() * tau};
    aty += Eigen::Vector2d{y, y * tau};
  }
  ata(1, 0) = ata(0, 1);
  const double det = ata.determinant();
  if (!(std::abs(det) > 0.0)) return fit;
  const Eigen::Matrix2d inv = ata.inverse();
  const Eigen::Vector2d cx = inv * atx;
  const Eigen::Vector2d cy = inv * aty;
  fit.valid = std::isfinite(cx.sum()) && std::isfinite(cy.sum());
  if (!fit.valid) return fit;
  fit.t_ref_s = t_ref;
  fit.p_ref = {cx(0), cy(0)};
  fit.v_ref = {cx(1), cy(1)};
  fit.g_mps2 = g_mps2;
  finish(fit, obs, 4, sigma_m);
  return fit;
}

TrajectoryFit fit_free_gravity(std::span<const Observation> obs, double sigma_m) {
  TrajectoryFit fit;
  if (!usable(obs)) return fit;
  const double t_ref = obs.back().t_s;
  // x: [1 τ]; y: [1 τ −τ²/2] with g as the third unknown.
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d aty = Eigen::Vector3d::Zero();
  Eigen::Matrix2d atax = Eigen::Matrix2d::Zero();
  Eigen::Vector2d atx = Eigen::Vector2d::Zero();
  for (const Observation& o : obs) {
    const double tau = o.t_s - t_ref;
    const Eigen::Vector3d row{1.0, tau, -0.5 * tau * tau};
    ata += row * row.transpose();
    aty += row * o.p_board.y();
    const Eigen::Vector2d rx{1.0, tau};
    atax += rx * rx.transpose();
    atx += rx * o.p_board.x();
  }
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(ata);
  if (ldlt.info() != Eigen::Success || !(std::abs(atax.determinant()) > 0.0)) return fit;
  const Eigen::Vector3d cy = ldlt.solve(aty);
  const Eigen::Vector2d cx = atax.inverse() * atx;
  fit.valid = std::isfinite(cy.sum()) && std::isfinite(cx.sum());
  if (!fit.valid) return fit;
  fit.t_ref_s = t_ref;
  fit.p_ref = {cx(0), cy(0)};
  fit.v_ref = {cx(1), cy(1)};
  fit.g_mps2 = cy(2);
  finish(fit, obs, 5, sigma_m);
  return fit;
}

AccelerationFit fit_free_acceleration(std::span<const Observation> obs, double sigma_m) {
  AccelerationFit fit;
  if (!usable(obs)) return fit;
  const double t_ref = obs.back().t_s;
  const Vec2 origin = obs.back().p_board;  // positions near zero: the closed-form χ² below cancels less
  // Both coordinates share the design matrix [1 τ τ²/2]: accumulate the
  // moments of τ and of q·τ^k once (the tracker calls this every frame).
  double s1 = 0.0, s2 = 0.0, s3 = 0.0, s4 = 0.0;
  Eigen::Matrix<double, 3, 2> atq = Eigen::Matrix<double, 3, 2>::Zero();
  double qq = 0.0;
  for (const Observation& o : obs) {
    const double tau = o.t_s - t_ref;
    const double tau2 = tau * tau;
    const Vec2 q = o.p_board - origin;
    s1 += tau;
    s2 += tau2;
    s3 += tau2 * tau;
    s4 += tau2 * tau2;
    atq.row(0) += q.transpose();
    atq.row(1) += tau * q.transpose();
    atq.row(2) += 0.5 * tau2 * q.transpose();
    qq += q.squaredNorm();
  }
  const double n = static_cast<double>(obs.size());
  Eigen::Matrix3d ata;
  ata << n, s1, 0.5 * s2, s1, s2, 0.5 * s3, 0.5 * s2, 0.5 * s3, 0.25 * s4;
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(ata);
  if (ldlt.info() != Eigen::Success || !(std::abs(ata.determinant()) > 0.0)) return fit;
  const Eigen::Matrix<double, 3, 2> c = ldlt.solve(atq);
  fit.valid = c.allFinite();
  if (!fit.valid) return fit;
  fit.t_ref_s = t_ref;
  fit.p_ref = origin + Vec2(c.row(0).transpose());
  fit.v_ref = c.row(1).transpose();
  fit.a_mps2 = c.row(2).transpose();
  fit.points = static_cast<int>(obs.size());
  fit.dof = 2 * fit.points - 6;
  // At the least-squares solution Σ|q − A·c|² = Σ|q|² − Σ cᵀ(Aᵀq).
  const double residual = std::max(0.0, qq - (c.array() * atq.array()).sum());
  fit.chi2 = sigma_m > 0.0 ? residual / (sigma_m * sigma_m) : 0.0;
  return fit;
}

double chi2_threshold(int dof) {
  if (dof <= 0) return INFINITY;
  // Wilson–Hilferty: (χ²/k)^(1/3) is nearly normal with mean 1 − 2/(9k) and
  // variance 2/(9k); z = 3.09 is the 99.9 % point.
  const double k = dof;
  const double a = 2.0 / (9.0 * k);
  const double c = 1.0 - a + 3.090232306167813 * std::sqrt(a);
  return k * c * c * c;
}

}  // namespace pinball::track
