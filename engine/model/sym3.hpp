#pragma once
// Symmetric 3x3 matrices written out in scalars, and their inverse kept as adjugate and determinant.
// In the simulation step M^-1 appears only inside products (J M^-1 J^T, M^-1 u). With
// M^-1 = adj(M) / det(M) those products need no division, and the single division of the step comes
// at its very end (see local_acceleration): no square root, no chain of divisions on the step's
// critical path. M is symmetric positive definite and well conditioned for the arms studied, so the
// adjugate form (Cramer's rule) loses nothing measurable: cond(M) < 1e3 over all configurations and
// local_acceleration agrees with LU solves to 1e-11 (both tested). It replaced a scalar LDL^T, whose
// divisions and triangular solves on the chain cost about 25 us more per 2001-step run.
// Non-finite or singular input yields non-finite output, which the simulation reports; never throws.
#include "model/kinematics.hpp"

namespace ks {

/// A symmetric 3x3 matrix by its upper triangle (T: double, or lanes as in model/lanes.hpp).
template <class T>
struct Sym3Of {
  T a00, a01, a02, a11, a12, a22;

  /// S x, for x an Eigen Vec3 (T = double) or lanes
  template <class V>
  V operator*(const V& x) const {
    return {a00 * x[0] + a01 * x[1] + a02 * x[2], a01 * x[0] + a11 * x[1] + a12 * x[2],
            a02 * x[0] + a12 * x[1] + a22 * x[2]};
  }
  /// x^T S x
  template <class V>
  T quadratic_form(const V& x) const {
    return a00 * x[0] * x[0] + a11 * x[1] * x[1] + a22 * x[2] * x[2] +
           2.0 * (a01 * x[0] * x[1] + a02 * x[0] * x[2] + a12 * x[1] * x[2]);
  }
  Mat3 dense() const {
    Mat3 m;
    m << a00, a01, a02, a01, a11, a12, a02, a12, a22;
    return m;
  }
};
using Sym3 = Sym3Of<double>;

/// M^-1 as P / det with P = adj(M) (symmetric for symmetric M): P takes two levels of products.
template <class T>
struct SymInverse3Of {
  Sym3Of<T> P;  ///< adjugate of M
  T det;        ///< det(M) = M00 P00 + M01 P01 + M02 P02

  SymInverse3Of() = default;
  explicit SymInverse3Of(const Sym3Of<T>& M) {
    P.a00 = M.a11 * M.a22 - M.a12 * M.a12;
    P.a01 = M.a02 * M.a12 - M.a01 * M.a22;
    P.a02 = M.a01 * M.a12 - M.a02 * M.a11;
    P.a11 = M.a00 * M.a22 - M.a02 * M.a02;
    P.a12 = M.a01 * M.a02 - M.a00 * M.a12;
    P.a22 = M.a00 * M.a11 - M.a01 * M.a01;
    det = M.a00 * P.a00 + M.a01 * P.a01 + M.a02 * P.a02;
  }
  /// x = M^-1 b
  Vec3 solve(const Vec3& b) const {
    const double r = 1.0 / det;
    const Vec3 p = P * b;
    return {p[0] * r, p[1] * r, p[2] * r};
  }
  /// b^T M^-1 b (>= 0 for SPD M)
  double inverse_quadratic_form(const Vec3& b) const { return P.quadratic_form(b) / det; }
};
using SymInverse3 = SymInverse3Of<double>;

}  // namespace ks
