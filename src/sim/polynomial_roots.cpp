#include "pinball/sim/polynomial_roots.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pinball::sim {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

int effective_degree(const double* c, int degree) {
  while (degree > 0 && c[degree] == 0.0) --degree;
  return degree;
}

// Bound on the round-off of poly_eval at t: a value smaller than this is zero
// as far as double arithmetic can tell.
double eval_error_bound(const double* c, int degree, double t) {
  const double at = std::abs(t);
  double s = 0.0;
  for (int i = degree; i >= 0; --i) s = s * at + std::abs(c[i]);
  return 4.0 * (degree + 1) * kEps * s;
}

void derivative(const double* c, int degree, double* d) {
  for (int i = 1; i <= degree; ++i) d[i - 1] = i * c[i];
}

// Shrinks a bracket [a, b] with f(a), f(b) of opposite signs (fa != 0) to a
// width of at most tol by Newton steps that fall back to bisection when they
// leave the bracket; once a Newton step is below tol the points tol/2 either
// side of its target close the bracket. Leaves the bracket in a, b.
void refine_bracket(const double* c, int degree, double& a, double& b, double fa, double tol) {
  double d[kMaxPolyDegree] = {};
  derivative(c, degree, d);
  const bool a_positive = fa > 0.0;
  double x = 0.5 * (a + b);
  for (int it = 0; it < 200 && b - a > tol; ++it) {
    const double fx = poly_eval(c, degree, x);
    if (fx == 0.0) {
      // An exact zero: keep the side that matches fa just left of it.
      b = x;
      if (a_positive) {
        const double left = std::max(a, x - 0.5 * tol);
        if (poly_eval(c, degree, left) > 0.0) a = left;
      }
      x = 0.5 * (a + b);
      continue;
    }
    if ((fx > 0.0) == a_positive) {
      a = x;
    } else {
      b = x;
    }
    const double dfx = poly_eval(d, degree - 1, x);
    const double step = dfx != 0.0 ? fx / dfx : 0.0;
    double next = x - step;
    if (dfx != 0.0 && std::abs(step) < 0.5 * tol && next > a && next < b) {
      // Converged: probe either side of the target to close the bracket.
      for (const double probe : {next - 0.5 * tol, next + 0.5 * tol}) {
        if (probe <= a || probe >= b) continue;
        const double fp = poly_eval(c, degree, probe);
        if (fp != 0.0 && (fp > 0.0) == a_positive) {
          a = probe;
        } else {
          b = probe;
        }
      }
      next = 0.5 * (a + b);
    }
    if (!(next > a && next < b) || dfx == 0.0) next = 0.5 * (a + b);
    // A Newton step that barely moves one end makes no progress on the
    // width; every fourth iteration bisects.
    if (it % 4 == 3) next = 0.5 * (a + b);
    x = next;
  }
}

// lo, the turning points inside (lo, hi), and hi: the polynomial is
// monotone between consecutive knots. Returns the number of knots.
int monotone_knots(const double* c, int degree, double lo, double hi, double t_tol, double* knots) {
  double d[kMaxPolyDegree] = {};
  derivative(c, degree, d);
  const int turns = real_roots(d, degree - 1, lo, hi, t_tol, knots + 1);
  knots[0] = lo;
  int k = turns + 1;
  if (knots[k - 1] < hi) knots[k++] = hi;
  return k;
}

}  // namespace

double poly_eval(const double* c, int degree, double t) {
  double s = c[degree];
  for (int i = degree - 1; i >= 0; --i) s = s * t + c[i];
  return s;
}

QuadraticRoots quadratic_roots(double a, double b, double c) {
  if (a != 0.0) {
    // Round-off in b² − 4ac is a few ulps of the larger term; within that the
    // discriminant is zero and the root double.
    const double b2 = b * b;
    const double ac4 = 4.0 * a * c;
    if (std::abs(b2 - ac4) <= 4.0 * kEps * std::max(b2, std::abs(ac4))) {
      QuadraticRoots r;
      r.count = 1;
      r.t0 = r.t1 = -b / (2.0 * a);
      return r;
    }
  }
  return solve_quadratic(a, b, c);
}

int real_roots(const double* c, int degree, double lo, double hi, double t_tol, double* roots) {
  degree = effective_degree(c, std::min(degree, kMaxPolyDegree));
  if (degree == 0 || !(lo <= hi)) return 0;
  int n = 0;
  auto add = [&](double t) {
    if (n > 0 && t - roots[n - 1] <= t_tol) return;  // the same root seen from both sides
    roots[n++] = t;
  };
  if (degree == 1) {
    const double t = -c[0] / c[1];
    if (t >= lo && t <= hi) add(t);
    return n;
  }
  if (degree == 2) {
    const QuadraticRoots q = quadratic_roots(c[2], c[1], c[0]);
    if (q.count >= 1 && q.t0 >= lo && q.t0 <= hi) add(q.t0);
    if (q.count == 2 && q.t1 >= lo && q.t1 <= hi) add(q.t1);
    return n;
  }
  // Between consecutive turning points the polynomial is monotone: at most
  // one root each, found by its sign change; a turning point where the value
  // is zero within round-off is a double root.
  double knots[kMaxPolyDegree + 2];
  const int k = monotone_knots(c, degree, lo, hi, t_tol, knots);
  double a = knots[0];
  double fa = poly_eval(c, degree, a);
  if (fa == 0.0) add(a);
  for (int i = 1; i < k; ++i) {
    const double b = knots[i];
    const double fb = poly_eval(c, degree, b);
    if ((fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0)) {
      double x0 = a, x1 = b;
      refine_bracket(c, degree, x0, x1, fa, t_tol);
      add(0.5 * (x0 + x1));
    } else if (fb == 0.0 || (i < k - 1 && std::abs(fb) <= eval_error_bound(c, degree, b))) {
      add(b);
    }
    a = b;
    fa = fb;
  }
  return n;
}

bool first_crossing_down(const double* c, int degree, double lo, double hi, double t_tol, double& t) {
  degree = effective_degree(c, std::min(degree, kMaxPolyDegree));
  if (!(lo < hi)) return false;
  if (degree == 0) return false;  // a constant never crosses
  bool positive = poly_eval(c, degree, lo) > 0.0;
  if (degree <= 2) {
    // Closed form: walk the roots in order, tracking the sign between them.
    double r[2];
    int n = 0;
    if (degree == 1) {
      r[n++] = -c[0] / c[1];
    } else {
      const QuadraticRoots q = quadratic_roots(c[2], c[1], c[0]);
      if (q.count >= 1) r[n++] = q.t0;
      if (q.count == 2) r[n++] = q.t1;
    }
    for (int i = 0; i < n; ++i) {
      if (!(r[i] > lo)) continue;
      if (r[i] > hi) break;
      const double slope = degree == 1 ? c[1] : 2.0 * c[2] * r[i] + c[1];
      if (positive && slope <= 0.0) {  // slope 0: a double root, touching from above
        t = r[i];
        return true;
      }
      positive = slope > 0.0;
    }
    return false;
  }
  double knots[kMaxPolyDegree + 2];
  const int k = monotone_knots(c, degree, lo, hi, t_tol, knots);
  double a = lo;
  double fa = poly_eval(c, degree, a);
  for (int i = 1; i < k; ++i) {
    const double b = knots[i];
    if (!(b > a)) continue;
    const double fb = poly_eval(c, degree, b);
    if (positive && fb <= 0.0) {
      double x0 = a, x1 = b;
      refine_bracket(c, degree, x0, x1, fa, t_tol);
      t = x0;  // the side where the value is still positive: never after the crossing
      return true;
    }
    positive = fb > 0.0;
    a = b;
    fa = fb;
  }
  return false;
}

}  // namespace pinball::sim
