#pragma once
// Closed-form rigid-body dynamics of the planar 3R arm (seed 000, Eq. 35 and Appendix F):
// tau = M(q) qdd + c(q, qd) + g(q). Units: rad, rad/s, rad/s^2, Nm.
#include <Eigen/Core>

#include "model/arm.hpp"
#include "model/kinematics.hpp"
#include "model/trig.hpp"

namespace ks {

/// Joint-space inertia matrix M(q) [kg m^2], symmetric positive definite (in either InertiaForm).
inline Mat3 mass_matrix(const PlanarArm3& a, const JointTrig& t) {
  const auto &l = a.l, &m = a.m, &lc = a.lc, &I = a.I;
  const double k2 = l[0] * (m[1] * lc[1] + m[2] * l[1]) * t.c2;  // couples links 1-2
  const double k23 = m[2] * l[0] * lc[2] * t.c23;                 // couples links 1-3
  const double k3 = m[2] * l[1] * lc[2] * t.c3;                   // couples links 2-3
  const double m33 = I[2] + m[2] * lc[2] * lc[2];
  const double m22 = I[1] + m[1] * lc[1] * lc[1] + m[2] * l[1] * l[1] + m33 + 2.0 * k3;
  double m11 = I[0] + m[0] * lc[0] * lc[0] + (m[1] + m[2]) * l[0] * l[0] + m22 + 2.0 * (k2 + k23);
  if (a.inertia_form == InertiaForm::thesis_m11)  // m2*(l1^2 + lc2^2 + 2 l1 lc2 c2 + m3*(...)): see InertiaForm
    m11 += (m[1] - 1.0) * m[2] *
           (l[0] * l[0] + l[1] * l[1] + lc[2] * lc[2] + 2.0 * (l[0] * l[1] * t.c2 + l[1] * lc[2] * t.c3 + l[0] * lc[2] * t.c23));
  const double m12 = m22 + k2 + k23;
  const double m13 = m33 + k3 + k23;
  const double m23 = m33 + k3;
  Mat3 M;
  M << m11, m12, m13, m12, m22, m23, m13, m23, m33;
  return M;
}

/// Centrifugal and Coriolis torques c(q, qd) [Nm] (Christoffel form of M).
inline Vec3 coriolis(const PlanarArm3& a, const JointTrig& t, const Vec3& qd) {
  const auto &l = a.l, &m = a.m, &lc = a.lc;
  const double h2 = l[0] * (m[1] * lc[1] + m[2] * l[1]) * t.s2;
  const double h23 = m[2] * l[0] * lc[2] * t.s23;
  const double h3 = m[2] * l[1] * lc[2] * t.s3;
  const double d1 = qd[0], d2 = qd[1], d3 = qd[2];
  const double d23 = d2 + d3, d12 = d1 + d2;
  return {-h2 * d2 * (2.0 * d1 + d2) - h23 * d23 * (2.0 * d1 + d23) - h3 * d3 * (2.0 * d12 + d3),
          (h2 + h23) * d1 * d1 - h3 * d3 * (2.0 * d12 + d3),
          h3 * d12 * d12 + h23 * d1 * d1};
}

/// Gravity torques g(q) = dU/dq [Nm], gravity along -y.
inline Vec3 gravity(const PlanarArm3& a, const JointTrig& t) {
  const auto &l = a.l, &m = a.m, &lc = a.lc;
  const double g3 = a.g * m[2] * lc[2] * t.c123;
  const double g2 = a.g * (m[1] * lc[1] + m[2] * l[1]) * t.c12 + g3;
  const double g1 = a.g * (m[0] * lc[0] + (m[1] + m[2]) * l[0]) * t.c1 + g2;
  return {g1, g2, g3};
}

/// Inverse dynamics: tau = M(q) qdd + c(q, qd) + g(q) [Nm].
inline Vec3 inverse_dynamics(const PlanarArm3& a, const Vec3& q, const Vec3& qd, const Vec3& qdd) {
  const JointTrig t = joint_trig(q);
  return mass_matrix(a, t) * qdd + coriolis(a, t, qd) + gravity(a, t);
}

/// Potential energy U(q) [J] of the three centres of mass (zero at y = 0).
inline double potential_energy(const PlanarArm3& a, const JointTrig& t) {
  const double y1 = a.lc[0] * t.s1;
  const double y2 = a.l[0] * t.s1 + a.lc[1] * t.s12;
  const double y3 = a.l[0] * t.s1 + a.l[1] * t.s12 + a.lc[2] * t.s123;
  return a.g * (a.m[0] * y1 + a.m[1] * y2 + a.m[2] * y3);
}

}  // namespace ks
