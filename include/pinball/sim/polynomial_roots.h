#pragma once
// Real roots of low-degree polynomials for times of impact (event stepper).
// Quadratics in closed form without cancellation and with a defined answer at
// double roots; cubics and quartics isolated between the turning points found
// from the derivative (recursively), then refined by safeguarded Newton
// steps, so that no root is lost near a tangent graze.

#include "pinball/core/geometry.h"

namespace pinball::sim {

/// Largest degree the root finders accept.
inline constexpr int kMaxPolyDegree = 4;

/// c[0] + c[1]·t + ... + c[degree]·t^degree by Horner's rule.
double poly_eval(const double* c, int degree, double t);

/// Roots of a·t² + b·t + c without cancellation. A discriminant that is
/// negative only by round-off (|b² − 4ac| within a few ulps of b²) is a double
/// root, reported once (count 1, t0 == t1 == −b/2a).
QuadraticRoots quadratic_roots(double a, double b, double c);

/// Real roots of the polynomial in [lo, hi], ascending, each reported once:
/// sign changes refined to within t_tol, and double roots (a turning point
/// where the value is zero within round-off). Returns the count (<= degree);
/// an identically zero polynomial has none.
int real_roots(const double* c, int degree, double lo, double hi, double t_tol, double* roots);

/// First time in (lo, hi] at which the polynomial reaches <= 0 having been
/// > 0 just before (a start at <= 0 counts only once the value has risen above
/// 0). Writes a time that is never after that crossing and at most t_tol
/// before it (for degree <= 2: the closed-form root). False if there is none.
bool first_crossing_down(const double* c, int degree, double lo, double hi, double t_tol, double& t);

}  // namespace pinball::sim
