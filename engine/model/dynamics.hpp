#pragma once
// Closed-form rigid-body dynamics of the planar 3R arm (seed 000, Eq. 35 and Appendix F):
// tau = M(q) qdd + c(q, qd) + g(q). Units: rad, rad/s, rad/s^2, Nm.
#include <Eigen/Core>

#include "model/arm.hpp"
#include "model/kinematics.hpp"
#include "model/sym3.hpp"
#include "model/trig.hpp"

namespace ks {

/// The constant products of masses and lengths that M, c and g are made of: computed once per arm,
/// so that the per-step functions below only multiply them by the trigonometric terms.
struct DynamicsCoefficients {
  double k2, k23, k3;          ///< couplings 1-2, 1-3, 2-3 [kg m^2]: l1 (m2 lc2 + m3 l2), m3 l1 lc3, m3 l2 lc3
  double m11, m22, m33;        ///< configuration-independent parts of the diagonal [kg m^2]
  double thesis_extra;         ///< (m2 - 1) m3 for InertiaForm::thesis_m11, else 0 [kg]
  double b0, b2, b3, b23;      ///< the thesis' M11 bracket: b0 + b2 c2 + b3 c3 + b23 c23 [m^2]
  double g1, g2, g3;           ///< gravity moments g (m_i lc_i + ...) [N m]
  double l1, l2, l3;           ///< link lengths [m]

  explicit DynamicsCoefficients(const PlanarArm3& a) {
    const auto &l = a.l, &m = a.m, &lc = a.lc, &I = a.I;
    k2 = l[0] * (m[1] * lc[1] + m[2] * l[1]);
    k23 = m[2] * l[0] * lc[2];
    k3 = m[2] * l[1] * lc[2];
    m33 = I[2] + m[2] * lc[2] * lc[2];
    m22 = I[1] + m[1] * lc[1] * lc[1] + m[2] * l[1] * l[1] + m33;
    m11 = I[0] + m[0] * lc[0] * lc[0] + (m[1] + m[2]) * l[0] * l[0] + m22;
    thesis_extra = a.inertia_form == InertiaForm::thesis_m11 ? (m[1] - 1.0) * m[2] : 0.0;
    b0 = l[0] * l[0] + l[1] * l[1] + lc[2] * lc[2];
    b2 = 2.0 * l[0] * l[1];
    b3 = 2.0 * l[1] * lc[2];
    b23 = 2.0 * l[0] * lc[2];
    g3 = a.g * m[2] * lc[2];
    g2 = a.g * (m[1] * lc[1] + m[2] * l[1]);
    g1 = a.g * (m[0] * lc[0] + (m[1] + m[2]) * l[0]);
    l1 = l[0];
    l2 = l[1];
    l3 = l[2];
  }
};

/// Joint-space inertia matrix M(q) [kg m^2], symmetric positive definite (in either InertiaForm).
/// T: double, or lanes (model/lanes.hpp) for runs computed side by side.
template <class T>
inline Sym3Of<T> mass_matrix_sym(const DynamicsCoefficients& d, const JointTrigOf<T>& t) {
  const T k2 = d.k2 * t.c2, k23 = d.k23 * t.c23, k3 = d.k3 * t.c3;
  const T m22 = d.m22 + 2.0 * k3;
  T m11 = d.m11 + 2.0 * (k3 + k2 + k23);
  // InertiaForm::thesis_m11: m2*(l1^2 + lc2^2 + 2 l1 lc2 c2 + m3*(bracket)) adds (m2 - 1) m3 bracket
  if (d.thesis_extra != 0.0) m11 += d.thesis_extra * (d.b0 + d.b2 * t.c2 + d.b3 * t.c3 + d.b23 * t.c23);
  return {m11, m22 + k2 + k23, d.m33 + k3 + k23, m22, d.m33 + k3, T(d.m33)};
}
inline Mat3 mass_matrix(const DynamicsCoefficients& d, const JointTrig& t) { return mass_matrix_sym(d, t).dense(); }

/// Centrifugal and Coriolis torques c(q, qd) [Nm] (Christoffel form of M).
template <class T>
inline Vec3Of<T> coriolis(const DynamicsCoefficients& d, const JointTrigOf<T>& t, const Vec3Of<T>& qd) {
  const T h2 = d.k2 * t.s2, h23 = d.k23 * t.s23, h3 = d.k3 * t.s3;
  const T d1 = qd[0], d2 = qd[1], d3 = qd[2];
  const T d23 = d2 + d3, d12 = d1 + d2;
  const T h3t = h3 * d3 * (2.0 * d12 + d3);
  return {-h2 * d2 * (2.0 * d1 + d2) - h23 * d23 * (2.0 * d1 + d23) - h3t, (h2 + h23) * d1 * d1 - h3t,
          h3 * d12 * d12 + h23 * d1 * d1};
}

/// Gravity torques g(q) = dU/dq [Nm], gravity along -y.
template <class T>
inline Vec3Of<T> gravity(const DynamicsCoefficients& d, const JointTrigOf<T>& t) {
  const T g3 = d.g3 * t.c123;
  const T g2 = d.g2 * t.c12 + g3;
  return {d.g1 * t.c1 + g2, g2, g3};
}

inline Mat3 mass_matrix(const PlanarArm3& a, const JointTrig& t) { return mass_matrix(DynamicsCoefficients(a), t); }
inline Vec3 coriolis(const PlanarArm3& a, const JointTrig& t, const Vec3& qd) {
  return coriolis(DynamicsCoefficients(a), t, qd);
}
inline Vec3 gravity(const PlanarArm3& a, const JointTrig& t) { return gravity(DynamicsCoefficients(a), t); }

/// Inverse dynamics: tau = M(q) qdd + c(q, qd) + g(q) [Nm].
inline Vec3 inverse_dynamics(const PlanarArm3& a, const Vec3& q, const Vec3& qd, const Vec3& qdd) {
  const DynamicsCoefficients d(a);
  const JointTrig t = joint_trig(q);
  return mass_matrix(d, t) * qdd + coriolis(d, t, qd) + gravity(d, t);
}

/// Potential energy U(q) [J] of the three centres of mass (zero at y = 0).
inline double potential_energy(const PlanarArm3& a, const JointTrig& t) {
  const double y1 = a.lc[0] * t.s1;
  const double y2 = a.l[0] * t.s1 + a.lc[1] * t.s12;
  const double y3 = a.l[0] * t.s1 + a.l[1] * t.s12 + a.lc[2] * t.s123;
  return a.g * (a.m[0] * y1 + a.m[1] * y2 + a.m[2] * y3);
}

}  // namespace ks
