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
    const Vec3 f0 = llt.solve_lower(J.row(0).transpose()), f1 = llt.solve_lower(J.row(1).transpose());
    const Vec3 fu = llt.solve_lower(Vec3(c[0] + k * g[0], c[1] + k * g[1], c[2] + k * g[2]));
    const double d[3] = {llt.r0, llt.r1, llt.r2};
    double a00 = 0, a01 = 0, a11 = 0, ju0 = 0, ju1 = 0;
    for (int i = 0; i < 3; ++i) {
      const double g0 = f0[i] * d[i], g1 = f1[i] * d[i];
      a00 += g0 * f0[i];
      a01 += g0 * f1[i];
      a11 += g1 * f1[i];
      ju0 += g0 * fu[i];
      ju1 += g1 * fu[i];
    }
    const double r0 = b[0] + ju0 + K_N * J.row(0).dot(qd), r1 = b[1] + ju1 + K_N * J.row(1).dot(qd);
    const double inv_det = 1.0 / (a00 * a11 - a01 * a01);  // overlaps with adj(A) r below
    const double w0 = a11 * r0 - a01 * r1, w1 = a00 * r1 - a01 * r0;
    const Vec3 h((f0[0] * w0 + f1[0] * w1) * inv_det - fu[0], (f0[1] * w0 + f1[1] * w1) * inv_det - fu[1],
                 (f0[2] * w0 + f1[2] * w1) * inv_det - fu[2]);
    return llt.solve_upper(h) - K_N * qd;
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
