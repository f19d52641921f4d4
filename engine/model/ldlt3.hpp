#pragma once
// Square-root-free Cholesky (LDL^T) factorisation of a 3x3 symmetric positive definite matrix,
// written out in scalars. Eigen's LLT takes a blocked general path for a 3x2 right-hand side (ten
// times slower here), and square roots lengthen the step's dependency chain: LDL^T needs none.
// A non-positive-definite or non-finite input yields non-finite results, which propagate (the
// simulation reports that as diverged); it never throws.
#include "model/kinematics.hpp"

namespace ks {

struct Ldlt3 {
  double l10, l20, l21;  // unit lower factor L
  double r0, r1, r2;     // reciprocals of D's diagonal

  Ldlt3() = default;
  explicit Ldlt3(const Mat3& M) { compute(M); }

  /// D from the leading principal minors: d0 = P1, d1 = P2 / P1, d2 = P3 / P2, so the three
  /// divisions are independent of one another instead of a chain of three.
  void compute(const Mat3& M) {
    const double p1 = M(0, 0);
    const double p2 = M(0, 0) * M(1, 1) - M(1, 0) * M(1, 0);
    const double c21 = M(0, 0) * M(2, 1) - M(2, 0) * M(1, 0);  // cofactor terms for l21 and P3
    const double p3 = M(2, 2) * p2 - M(2, 0) * (M(2, 0) * M(1, 1) - M(1, 0) * M(2, 1)) -
                      M(2, 1) * c21;
    const double i1 = 1.0 / p1, i2 = 1.0 / p2, i3 = 1.0 / p3;
    r0 = i1;
    r1 = p1 * i2;
    r2 = p2 * i3;
    l10 = M(1, 0) * i1;
    l20 = M(2, 0) * i1;
    l21 = c21 * i2;
  }
  /// y = L^-1 b (unit lower)
  Vec3 solve_lower(const Vec3& b) const {
    const double y1 = b[1] - l10 * b[0];
    return {b[0], y1, b[2] - l20 * b[0] - l21 * y1};
  }
  /// x = L^-T D^-1 y
  Vec3 solve_upper(const Vec3& y) const {
    const double x2 = y[2] * r2;
    const double x1 = y[1] * r1 - l21 * x2;
    return {y[0] * r0 - l10 * x1 - l20 * x2, x1, x2};
  }
  /// x = M^-1 b
  Vec3 solve(const Vec3& b) const { return solve_upper(solve_lower(b)); }
  /// b^T M^-1 b (>= 0 for SPD M)
  double inverse_quadratic_form(const Vec3& b) const {
    const Vec3 y = solve_lower(b);
    return y[0] * y[0] * r0 + y[1] * y[1] * r1 + y[2] * y[2] * r2;
  }
};

}  // namespace ks
