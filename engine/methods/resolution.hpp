#pragma once
// Joint accelerations of the seed's redundancy resolutions at one instant (free functions, no state).
#include <Eigen/LU>

#include "model/sym3.hpp"
#include "model/kinematics.hpp"

namespace ks {

enum class Weighting {
  inertia,         ///< W = M   (local_weighted, seed Eq. 51): minimises ||M qdd + c + k g||^2 in M^-1
  inertia_squared  ///< W = M^2 (local_unweighted, seed Eq. 56): minimises ||M qdd + c + k g||^2
};

/// Local (instantaneous) resolution at acceleration level:
///   qdd = J_W+ b - (I - J_W+ J) v,  J_W+ = W^-1 J^T (J W^-1 J^T)^-1,  v = M^-1 (c + k g) + K_N qd,
/// i.e. qdd = Y A^-1 (b + J v) - v with Y = W^-1 J^T and A = J Y (a 2x2 system).
/// With M^-1 = P / D (P = adj M, D = det M) and Q = P (W = M) or P^2 (W = M^2), every factor of D
/// cancels but one: with Yh = Q J^T, Ah = J Yh, pv = P u + D K_N qd and rh = D b + J pv,
///   qdd = (Yh adj(Ah) rh - det(Ah) pv) / (D det(Ah)),
/// one division, computed while the numerator is formed (the step's dependency chain runs through here).
/// Inputs: M^-1 as SymInverse3 [1/(kg m^2)], J (2x3) [m], b = xdd - Jdot qd [m/s^2], c and g [Nm],
/// gravity weight k [-], null-space damping K_N [1/s], qd [rad/s]. Output: qdd [rad/s^2].
inline Vec3 local_acceleration(Weighting w, const SymInverse3& Mi, const Mat23& J, const Vec2& b, const Vec3& c,
                               const Vec3& g, double k, double K_N, const Vec3& qd) {
  const Sym3& P = Mi.P;
  const double D = Mi.det;
  const Vec3 j0(J(0, 0), J(0, 1), J(0, 2)), j1(J(1, 0), J(1, 1), J(1, 2));
  Vec3 y0 = P * j0, y1 = P * j1;
  if (w == Weighting::inertia_squared) {
    y0 = P * y0;
    y1 = P * y1;
  }
  Vec3 pv = P * Vec3(c[0] + k * g[0], c[1] + k * g[1], c[2] + k * g[2]);
  if (K_N != 0.0) {
    const double s = D * K_N;
    pv = Vec3(pv[0] + s * qd[0], pv[1] + s * qd[1], pv[2] + s * qd[2]);
  }
  const double a00 = j0[0] * y0[0] + j0[1] * y0[1] + j0[2] * y0[2];
  const double a01 = j0[0] * y1[0] + j0[1] * y1[1] + j0[2] * y1[2];  // Ah is symmetric
  const double a11 = j1[0] * y1[0] + j1[1] * y1[1] + j1[2] * y1[2];
  const double r0 = D * b[0] + (j0[0] * pv[0] + j0[1] * pv[1] + j0[2] * pv[2]);
  const double r1 = D * b[1] + (j1[0] * pv[0] + j1[1] * pv[1] + j1[2] * pv[2]);
  const double det = a00 * a11 - a01 * a01;
  const double inv = 1.0 / (D * det);
  const double w0 = a11 * r0 - a01 * r1, w1 = a00 * r1 - a01 * r0;
  return {(y0[0] * w0 + y1[0] * w1 - det * pv[0]) * inv, (y0[1] * w0 + y1[1] * w1 - det * pv[1]) * inv,
          (y0[2] * w0 + y1[2] * w1 - det * pv[2]) * inv};
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
