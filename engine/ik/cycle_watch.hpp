#pragma once
// The cycle check of the iterative IK solvers (ik/solve_impl.hpp; Options::cycle_window and
// cycle_tolerance in ik/solve.hpp): does iterate q_k come back to within
// tol = cycle_tolerance * max(1, ||q_k||) of one of q_{k-2} .. q_{k-window} (revolute joints mod 2 pi)
// while the path travelled between them is more than 1000 times that distance?
//
// The verdict is that of the plain form (every lag: the error filter, then
// d = ||joint_difference(q_k, q_i)||, then d <= tol && path > 1000 d), bit for bit; the work is less:
// a lag whose ||F|| passes the filter is first compared by its squared distance against an upper
// bound of tol^2 (no square root), and only a lag that passes this too is decided by the plain form.
#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <limits>

#include "ik/problem.hpp"

namespace ks::ik::detail {

/// Upper bound of the squared distance s = sum_j x_j^2 (x = the wrapped joint difference, summed in
/// any order) of any lag the plain form accepts, d = fl(sqrt(s)) <= tol with
/// tol = fl(tolerance * max(1, fl(sqrt(n2)))), given n2 = ||q_k||^2 summed in any order (the plain
/// form's own sum may use another) (units of q, squared). +inf when tolerance^2 is not a normal double or n2 exceeds 1e300 (every lag that passes
/// the error filter then takes the plain form).
///
/// Why it bounds: with u = 2^-53 and no overflow (the guards: when tol overflows, so does the bound;
/// tol >= |tolerance| is normal),
/// d <= tol gives sqrt(s) <= tol / (1 - u), and tol <= |tolerance| sqrt(m) (1 + u)^2 with
/// m = max(1, n2) (sqrt and max are monotone); another summation order changes a sum of N
/// non-negative terms by a factor within (1 +- u)^N; so every accepted s is at most
/// tolerance^2 m (1 + u)^(4 + 2N) / (1 - u)^(2 + 2N), while the bound computed here is at least
/// tolerance^2 m (1 + 2^-30) (1 - u)^3: larger for any N up to 2^16. Squares that underflow move a
/// sum by at most N 2^-1074, far below the margin 2^-30 DBL_MIN. A NaN n2 makes both this m and the
/// plain form's max(1, ||q_k||) equal 1 (std::max returns its first argument).
inline double squared_return_bound(double tolerance, double n2) {
  const double t2 = tolerance * tolerance;
  const double m = std::max(1.0, n2);
  if (!(t2 >= DBL_MIN) || !(m <= 1e300)) return std::numeric_limits<double>::infinity();
  return t2 * m * (1.0 + 0x1p-30);  // t2 * m may overflow to +inf: still an upper bound
}

/// The last few iterates, for the cycle check: q, ||F(q)|| and the path length travelled up to it.
template <int N>
struct CycleWatch {
  static constexpr int kCapacity = 17;  // window of at most 16 earlier iterates
  std::array<Vec<N>, kCapacity> q;
  std::array<double, kCapacity> path;
  std::array<double, kCapacity> error;
  int window = 0;
  int newest = -1;  // slot of the newest iterate
  long count = 0;
  double travelled = 0.0;
  double best_error = std::numeric_limits<double>::infinity();  // min ||F|| before the newest

  /// Record iterate qk, the length `step` of the step to it (units of q) and e = ||F(qk)||.
  void push(const Vec<N>& qk, double step, double e) {
    travelled += step;
    newest = newest + 1 == kCapacity ? 0 : newest + 1;
    q[newest] = qk;
    path[newest] = travelled;
    error[newest] = e;
    ++count;
  }

  /// Does the newest iterate return to one of the `window` iterates before its predecessor?
  /// Returning within d puts ||F|| back within |J| d of the earlier value, so only earlier iterates
  /// with ||F|| within 0.1 % are compared, and none when the newest halves the best ||F|| so far
  /// (cheap filters: converging runs do no distance computations). `tolerance` in units of q.
  bool returned(const std::array<bool, N>& revolute, double tolerance) {
    const double e = error[newest];
    const bool progress = e < 0.5 * best_error;
    best_error = std::min(best_error, e);
    if (progress) return false;
    const long last = std::min<long>(window, count - 1);  // lags 2 .. last
    if (last < 2) return false;
    const Vec<N>& qk = q[newest];
    bool have_bound = false, have_tol = false;  // computed once, when first needed
    double bound = 0.0;  // squared_return_bound (units of q, squared)
    double tol = 0.0;    // the plain form's tolerance (units of q)
    for (int p = 2; p <= last; ++p) {
      const int i = newest - p < 0 ? newest - p + kCapacity : newest - p;
      if (!(std::abs(e - error[i]) <= 1e-3 * error[i])) continue;
      if (!have_bound) {
        double n2 = 0.0;
        for (int j = 0; j < N; ++j) n2 += qk[j] * qk[j];
        bound = squared_return_bound(tolerance, n2);
        have_bound = true;
      }
      double s = 0.0;  // squared joint distance; NaN (skipped) exactly when the plain d is NaN
      for (int j = 0; j < N; ++j) {
        const double x = revolute[j] ? wrap_angle(qk[j] - q[i][j]) : qk[j] - q[i][j];
        s += x * x;
      }
      if (!(s <= bound)) continue;
      // The plain form, as written before the bound existed.
      if (!have_tol) tol = tolerance * std::max(1.0, qk.norm()), have_tol = true;
      const double d = joint_difference<N>(qk, q[i], revolute).norm();
      if (d <= tol && travelled - path[i] > 1000.0 * d) return true;
    }
    return false;
  }
};

}  // namespace ks::ik::detail
