#pragma once
// Joint accelerations of the seed's redundancy resolutions at one instant (free functions, no state).
#include <Eigen/LU>

#include "model/ldlt3.hpp"
#include "model/kinematics.hpp"

namespace ks {

enum class Weighting {
  inertia,         ///< W = M   (local_weighted, seed Eq. 51): minimises ||M qdd + c + k g||^2 in M^-1
  inertia_squared  ///< W = M^2 (local_unweighted, seed Eq. 56): minimises ||M qdd + c + k g||^2
};

/// Local (instantaneous) resolution at acceleration level:
///   qdd = J_W+ b - (I - J_W+ J) v,  J_W+ = W^-1 J^T (J W^-1 J^T)^-1,  v = M^-1 (c + k g) + K_N qd,
/// computed as qdd = Y A^-1 (b + J v) - v with Y = W^-1 J^T and A = J Y (a 2x2 solve, no inverse).
/// Inputs: Cholesky factor of M (Ldlt3) [kg m^2], J (2x3) [m], b = xdd - Jdot qd [m/s^2], c and g [Nm],
/// gravity weight k [-], null-space damping K_N [1/s], qd [rad/s]. Output: qdd [rad/s^2].
inline Vec3 local_acceleration(Weighting w, const Ldlt3& llt, const Mat23& J, const Vec2& b, const Vec3& c,
                               const Vec3& g, double k, double K_N, const Vec3& qd) {
  if (w == Weighting::inertia) {
    // W = M: with M = L D L^T and f = L^-1 (J^T, c + k g), A = f^T D^-1 f and
    // qdd = L^-T D^-1 (f0 z0 + f1 z1 - fu) - K_N qd: forward solves only, one back solve at the end.
    // Written in scalars: this is the hottest code of a sweep.
    const double l10 = llt.l10, l20 = llt.l20, l21 = llt.l21, d0 = llt.r0, d1 = llt.r1, d2 = llt.r2;
    const double u0 = c[0] + k * g[0], u1 = c[1] + k * g[1], u2 = c[2] + k * g[2];
    const double a0 = J(0, 0), a1 = J(0, 1) - l10 * a0, a2 = J(0, 2) - l20 * a0 - l21 * a1;  // f0
    const double b0 = J(1, 0), b1 = J(1, 1) - l10 * b0, b2 = J(1, 2) - l20 * b0 - l21 * b1;  // f1
    const double e0 = u0, e1 = u1 - l10 * e0, e2 = u2 - l20 * e0 - l21 * e1;                 // fu
    const double ga0 = a0 * d0, ga1 = a1 * d1, ga2 = a2 * d2, gb0 = b0 * d0, gb1 = b1 * d1, gb2 = b2 * d2;
    const double a00 = ga0 * a0 + ga1 * a1 + ga2 * a2, a01 = ga0 * b0 + ga1 * b1 + ga2 * b2;
    const double a11 = gb0 * b0 + gb1 * b1 + gb2 * b2;
    double r0 = b[0] + (ga0 * e0 + ga1 * e1 + ga2 * e2), r1 = b[1] + (gb0 * e0 + gb1 * e1 + gb2 * e2);
    if (K_N != 0.0) {
      r0 += K_N * (J(0, 0) * qd[0] + J(0, 1) * qd[1] + J(0, 2) * qd[2]);
      r1 += K_N * (J(1, 0) * qd[0] + J(1, 1) * qd[1] + J(1, 2) * qd[2]);
    }
    const double inv_det = 1.0 / (a00 * a11 - a01 * a01);  // overlaps with adj(A) r below
    const double w0 = a11 * r0 - a01 * r1, w1 = a00 * r1 - a01 * r0;
    const double h0 = (a0 * w0 + b0 * w1) * inv_det - e0, h1 = (a1 * w0 + b1 * w1) * inv_det - e1,
                 h2 = (a2 * w0 + b2 * w1) * inv_det - e2;
    const double x2 = h2 * d2, x1 = h1 * d1 - l21 * x2, x0 = h0 * d0 - l10 * x1 - l20 * x2;  // L^-T D^-1 h
    return {x0 - K_N * qd[0], x1 - K_N * qd[1], x2 - K_N * qd[2]};
  }
  // W = M^2: Y = M^-2 J^T
  const Vec3 y0 = llt.solve(llt.solve(J.row(0).transpose())), y1 = llt.solve(llt.solve(J.row(1).transpose()));
  const Vec3 v = llt.solve(Vec3(c[0] + k * g[0], c[1] + k * g[1], c[2] + k * g[2])) + K_N * qd;
  const double a00 = J(0, 0) * y0[0] + J(0, 1) * y0[1] + J(0, 2) * y0[2];
  const double a01 = J(0, 0) * y1[0] + J(0, 1) * y1[1] + J(0, 2) * y1[2];  // A is symmetric
  const double a11 = J(1, 0) * y1[0] + J(1, 1) * y1[1] + J(1, 2) * y1[2];
  const double r0 = b[0] + J(0, 0) * v[0] + J(0, 1) * v[1] + J(0, 2) * v[2];
  const double r1 = b[1] + J(1, 0) * v[0] + J(1, 1) * v[1] + J(1, 2) * v[2];
  // z = A^-1 r = adj(A) r / det(A): the division runs while Y adj(A) r is formed (shorter chain)
  const double inv_det = 1.0 / (a00 * a11 - a01 * a01);
  const double w0 = a11 * r0 - a01 * r1, w1 = a00 * r1 - a01 * r0;
  const Vec3 yw(y0[0] * w0 + y1[0] * w1, y0[1] * w0 + y1[1] * w1, y0[2] * w0 + y1[2] * w1);
  return {yw[0] * inv_det - v[0], yw[1] * inv_det - v[1], yw[2] * inv_det - v[2]};
}

/// Non-redundant resolution (vertex_alpha, seed cases 3-5): solve [J; 1 1 1] qdd = [b; alpha_dd]
/// (the alpha row of Jdot is zero). Inputs: J (2x3) [m], b [m/s^2], alpha_dd [rad/s^2]. Output: qdd.
/// det_out receives det [J; 1 1 1] [m^2], the singularity measure.
inline Vec3 nonredundant_acceleration(const Mat23& J, const Vec2& b, double alpha_dd, double& det_out) {
  Mat3 J3;
  J3.topRows<2>() = J;
  J3.row(2).setOnes();
  const Eigen::PartialPivLU<Mat3> lu(J3);
  det_out = lu.determinant();
  return lu.solve(Vec3(b.x(), b.y(), alpha_dd));
}

}  // namespace ks
