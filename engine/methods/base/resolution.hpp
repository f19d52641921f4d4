#pragma once
// Joint accelerations of the seed's redundancy resolutions at one instant (free functions, no state).
#include <type_traits>

#include "model/lanes.hpp"

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
/// T: double (Eigen types), or lanes (model/lanes.hpp) with a k and K_N per lane.
template <class T>
inline Vec3Of<T> local_acceleration(Weighting w, const SymInverse3Of<T>& Mi, const Mat23Of<T>& J, const Vec2Of<T>& b,
                                    const Vec3Of<T>& c, const Vec3Of<T>& g, std::type_identity_t<T> k,
                                    std::type_identity_t<T> K_N, const Vec3Of<T>& qd) {
  using V3 = Vec3Of<T>;
  const Sym3Of<T>& P = Mi.P;
  const T D = Mi.det;
  const V3 j0{J(0, 0), J(0, 1), J(0, 2)}, j1{J(1, 0), J(1, 1), J(1, 2)};
  V3 y0 = P * j0, y1 = P * j1;
  if (w == Weighting::inertia_squared) {
    y0 = P * y0;
    y1 = P * y1;
  }
  V3 pv = P * V3{c[0] + k * g[0], c[1] + k * g[1], c[2] + k * g[2]};
  const auto damped = K_N != 0.0;  // lanes: each lane adds its damping term only when its K_N is not 0
  if (any(damped)) {
    const T s = D * K_N;
    pv = V3{select(damped, pv[0] + s * qd[0], pv[0]), select(damped, pv[1] + s * qd[1], pv[1]),
            select(damped, pv[2] + s * qd[2], pv[2])};
  }
  const T a00 = j0[0] * y0[0] + j0[1] * y0[1] + j0[2] * y0[2];
  const T a01 = j0[0] * y1[0] + j0[1] * y1[1] + j0[2] * y1[2];  // Ah is symmetric
  const T a11 = j1[0] * y1[0] + j1[1] * y1[1] + j1[2] * y1[2];
  const T r0 = D * b[0] + (j0[0] * pv[0] + j0[1] * pv[1] + j0[2] * pv[2]);
  const T r1 = D * b[1] + (j1[0] * pv[0] + j1[1] * pv[1] + j1[2] * pv[2]);
  const T det = a00 * a11 - a01 * a01;
  const T inv = 1.0 / (D * det);
  const T w0 = a11 * r0 - a01 * r1, w1 = a00 * r1 - a01 * r0;
  return {(y0[0] * w0 + y1[0] * w1 - det * pv[0]) * inv, (y0[1] * w0 + y1[1] * w1 - det * pv[1]) * inv,
          (y0[2] * w0 + y1[2] * w1 - det * pv[2]) * inv};
}

/// Non-redundant resolution (vertex_alpha, seed cases 3-5): solve [J; 1 1 1] qdd = [b; alpha_dd]
/// (the alpha row of Jdot is zero). Inputs: J (2x3) [m], b [m/s^2], alpha_dd [rad/s^2]. Output: qdd.
/// det_out receives det [J; 1 1 1] [m^2], the singularity measure.
/// The solve is Eigen's PartialPivLU<Matrix3d> written out (the same operations in the same order,
/// the pivot chosen per lane): pivot = the first largest |entry| of the column, rows swapped, the
/// column below divided by the pivot, the rank-1 update; det = (+-1) * (u00 * (u11 * u22)); then the
/// unit lower and the upper triangular solves with the row sums Eigen takes.
template <class T>
inline Vec3Of<T> nonredundant_acceleration(const Mat23Of<T>& J, const Vec2Of<T>& b, std::type_identity_t<T> alpha_dd,
                                           T& det_out) {
  // column 0: rows (J00, J10, 1)
  T r0[3] = {J(0, 0), J(0, 1), J(0, 2)}, r1[3] = {J(1, 0), J(1, 1), J(1, 2)}, r2[3] = {T(1.0), T(1.0), T(1.0)};
  T x0 = b[0], x1 = b[1], x2 = alpha_dd;
  const T s0 = vabs(r0[0]), s1 = vabs(r1[0]), s2 = vabs(r2[0]);
  const auto to1 = s1 > s0;
  const T best01 = select(to1, s1, s0);
  const auto to2 = s2 > best01;
  const auto nz0 = select(to2, s2, best01) != 0.0;
  const auto swap01 = nz0 & to1 & !to2, swap02 = nz0 & to2;
  for (int j = 0; j < 3; ++j) {
    const T a = r0[j], b1 = r1[j], b2 = r2[j];
    r0[j] = select(swap02, b2, select(swap01, b1, a));
    r1[j] = select(swap01, a, b1);
    r2[j] = select(swap02, a, b2);
  }
  {
    const T a = x0, b1 = x1, b2 = x2;  // the permutation applied to the right-hand side
    x0 = select(swap02, b2, select(swap01, b1, a));
    x1 = select(swap01, a, b1);
    x2 = select(swap02, a, b2);
  }
  r1[0] = select(nz0, r1[0] / r0[0], r1[0]);
  r2[0] = select(nz0, r2[0] / r0[0], r2[0]);
  r1[1] = r1[1] - r0[1] * r1[0];  // Eigen's outer product: row entry times column entry
  r1[2] = r1[2] - r0[2] * r1[0];
  r2[1] = r2[1] - r0[1] * r2[0];
  r2[2] = r2[2] - r0[2] * r2[0];
  // column 1: rows 1 and 2
  const T t1 = vabs(r1[1]), t2 = vabs(r2[1]);
  const auto to2b = t2 > t1;
  const auto nz1 = select(to2b, t2, t1) != 0.0;
  const auto swap12 = nz1 & to2b;
  for (int j = 0; j < 3; ++j) {
    const T a = r1[j], c = r2[j];
    r1[j] = select(swap12, c, a);
    r2[j] = select(swap12, a, c);
  }
  {
    const T a = x1, c = x2;
    x1 = select(swap12, c, a);
    x2 = select(swap12, a, c);
  }
  r2[1] = select(nz1, r2[1] / r1[1], r2[1]);
  r2[2] = r2[2] - r1[2] * r2[1];
  const auto odd = ((swap01 | swap02) & !swap12) | (swap12 & !(swap01 | swap02));  // an odd number of swaps
  det_out = select(odd, T(-1.0), T(1.0)) * (r0[0] * (r1[1] * r2[2]));
  // L y = P rhs (unit lower), then U x = y
  x1 = x1 - r1[0] * x0;
  x2 = x2 - (r2[0] * x0 + r2[1] * x1);
  x2 = x2 / r2[2];
  x1 = (x1 - r1[2] * x2) / r1[1];
  x0 = (x0 - (r0[1] * x1 + r0[2] * x2)) / r0[0];
  return {x0, x1, x2};
}

}  // namespace ks
