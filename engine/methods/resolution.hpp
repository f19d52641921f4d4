#pragma once
// Joint accelerations of the seed's redundancy resolutions at one instant (free functions, no state).
#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "model/kinematics.hpp"

namespace ks {

enum class Weighting {
  inertia,         ///< W = M   (local_weighted, seed Eq. 51): minimises ||M qdd + c + k g||^2 in M^-1
  inertia_squared  ///< W = M^2 (local_unweighted, seed Eq. 56): minimises ||M qdd + c + k g||^2
};

/// Local (instantaneous) resolution at acceleration level:
///   qdd = J_W+ b - (I - J_W+ J) v,  J_W+ = W^-1 J^T (J W^-1 J^T)^-1,  v = M^-1 (c + k g) + K_N qd,
/// computed as qdd = Y A^-1 (b + J v) - v with Y = W^-1 J^T and A = J Y (a 2x2 solve, no inverse).
/// Inputs: Cholesky factor of M [kg m^2], J (2x3) [m], b = xdd - Jdot qd [m/s^2], c and g [Nm],
/// gravity weight k [-], null-space damping K_N [1/s], qd [rad/s]. Output: qdd [rad/s^2].
inline Vec3 local_acceleration(Weighting w, const Eigen::LLT<Mat3>& llt, const Mat23& J, const Vec2& b,
                               const Vec3& c, const Vec3& g, double k, double K_N, const Vec3& qd) {
  Eigen::Matrix<double, 3, 2> Y = llt.solve(J.transpose());
  if (w == Weighting::inertia_squared) Y = llt.solve(Y);
  const Vec3 v = llt.solve(c + k * g) + K_N * qd;
  const Eigen::Matrix2d A = J * Y;
  const Vec2 r = b + J * v;
  const double det = A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
  const Vec2 z((A(1, 1) * r.x() - A(0, 1) * r.y()) / det, (A(0, 0) * r.y() - A(1, 0) * r.x()) / det);
  return Y * z - v;
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
