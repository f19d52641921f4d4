#pragma once
// One sample of the seed 3R arm's path-global joint path, over a scalar type T: a lane type L (double,
// or several samples in SIMD lanes: model/lanes.hpp) for the value, or DualOf<L, 3> (model/dual.hpp)
// seeded with the chart coordinate, its rate and its acceleration, for the value and its exact
// partials in one pass. Branches are per-lane selects, so every lane computes what a double would. The joint path is the exact inverse kinematics of
// (tip, alpha) at the sample; qd and qdd solve the extended task [tip; alpha] with J3 = [J; 1 1 1]
// (J3 qd = [xd; alpha_d], J3 qdd = [xdd - Jd qd; alpha_dd]) by its closed-form adjugate, whose
// determinant is l1 l2 sin(theta2); tau = M qdd + c + g. Every sine and cosine of the joint angles
// comes from those of alpha, theta2 and the wrist's direction by angle sums: no atan2 on the way.
#include <algorithm>
#include <cmath>
#include <utility>

#include "methods/base/trajectory.hpp"
#include "model/dual.hpp"
#include "model/dynamics.hpp"

namespace ks {

/// The self-motion chart at one sample (Extension::self_motion): alpha = phi + beta sin psi with phi
/// the tip's direction from the base and beta half the arc of tip angles the wrist can reach, and
/// their first two time derivatives [rad, rad/s, rad/s^2].
struct ChartSample {
  double phi[3], beta[3];
};

/// The lane type (model/lanes.hpp) of a scalar type: L itself, or the lanes of DualOf<L, N>.
template <class T>
using LaneOf = decltype(value_of(std::declval<T>()));

/// sin^2(theta2 / 2) = (1 - cos theta2) / 2 of a 3R arm at the point psi of its self-motion chart
/// (sp = sin psi, cp = cos psi) with half-arc beta [rad], the tip at distance r [m] from the base,
/// links l1, l2, l3 [m]: r l3 sin(beta u / 2) sin(beta v / 2) / (l1 l2) with u = 1 - sin psi and
/// v = 1 + sin psi, each written without cancellation (1 - s = c^2 / (1 + s)), so that it keeps its
/// precision near the stretched arm (theta2 near 0, where the chart changes branch). Within [0, 1].
template <class T, class L = LaneOf<T>>
inline T self_motion_half_versine(const T& sp, const T& cp, const L& beta, const L& r, double l3, double l1,
                                  double l2) {
  const auto up = value_of(sp) > L(0.0), down = value_of(sp) < L(0.0);
  const T u = select(up, cp * cp / (1.0 + sp), 1.0 - sp);
  const T v = select(down, cp * cp / (1.0 - sp), 1.0 + sp);
  T su, sv, unused;
  sincos_of(T(L(0.5) * beta) * u, su, unused);
  sincos_of(T(L(0.5) * beta) * v, sv, unused);
  const T h = T(r * (l3 / (l1 * l2))) * su * sv;
  return select(value_of(h) > L(0.0), select(value_of(h) > L(1.0), T(1.0), h), T(0.0));
}

/// One sample of the joint path: what the objective and the run's metrics read (lanes: as many
/// samples); sample_3r sets every member.
template <class T>
struct Sample3ROf {
  MaskOf<LaneOf<T>> reachable;  ///< the wrist is within reach of links 1 and 2 (|cos theta2| <= 1)
  T det;                        ///< det J3 = l1 l2 sin(theta2) [m^2]
  JointTrigOf<T> trig;          ///< sines and cosines of the joint angles
  Vec3Of<T> qd, qdd, tau;       ///< [rad/s], [rad/s^2], [Nm]
  Sym3Of<T> M;                  ///< M(q) [kg m^2]
  Mat23Of<T> J;                 ///< position Jacobian [m/rad]
};

/// What the evaluator reads of one sample of the path (lanes: as many samples).
template <class L>
struct Sample3RPointOf {
  L px, py, vx, vy, ax, ay;  ///< tip position [m], velocity [m/s], acceleration [m/s^2]
};

/// x = J3^-1 b by the adjugate of J3 = [J; 1 1 1], its cofactors written in the link terms of the
/// joint trig (exact for any configuration), times inv_det = 1 / det J3 = 1 / (l1 l2 s2).
template <class T>
inline Vec3Of<T> solve_extended_3r(const PlanarArm3& a, const JointTrigOf<T>& t, const T& inv_det, const T& b0,
                                   const T& b1, const T& b2) {
  const double l1 = a.l[0], l2 = a.l[1], l3 = a.l[2];
  const T r1c = l1 * t.c1, r2c = l2 * t.c12, r1s = l1 * t.s1, r2s = l2 * t.s12;
  const T c20 = (l2 * l3) * t.s3, c21 = -((l1 * l3) * t.s23) - (l2 * l3) * t.s3,
          c22 = (l1 * l2) * t.s2 + (l1 * l3) * t.s23;
  return {(r2c * b0 + r2s * b1 + c20 * b2) * inv_det, (-(r1c + r2c) * b0 - (r1s + r2s) * b1 + c21 * b2) * inv_det,
          (r1c * b0 + r1s * b1 + c22 * b2) * inv_det};
}

/// The sample at tip angle a [rad] (rate ad, acceleration add) on the elbow whose cos and sin of
/// theta2 are c2, s2 (given: the self-motion chart's), or, when `solve_elbow` is set, solved from
/// the reach (the law of cosines, |cos theta2| clamped within `clamp`, sin theta2 of sign `elbow`).
/// Past the reach the sample is taken at the boundary (reachable false); a wrist at the base gives
/// non-finite values (reachable false).
template <class T, class L = LaneOf<T>>
inline void sample_3r(const PlanarArm3& arm, const DynamicsCoefficients& dyn, const Sample3RPointOf<L>& pt,
                      const T& a, const T& ad, const T& add, bool solve_elbow, int elbow, double clamp, T c2, T s2,
                      Sample3ROf<T>& s) {
  const double l1 = arm.l[0], l2 = arm.l[1], l3 = arm.l[2];
  T sa, ca;
  sincos_of(a, sa, ca);
  const T x2 = T(pt.px) - l3 * ca, y2 = T(pt.py) - l3 * sa;
  const T d = x2 * x2 + y2 * y2;
  if (solve_elbow) {
    const T c2_raw = (d - (l1 * l1 + l2 * l2)) * (1.0 / (2.0 * l1 * l2));
    const L raw = value_of(c2_raw);
    s.reachable = both(value_of(d) > L(0.0), vabs(raw) <= L(1.0));
    c2 = select(raw > L(clamp), T(clamp), select(raw < L(-clamp), T(-clamp), c2_raw));
    s2 = static_cast<double>(elbow) * sqrt_of(1.0 - c2 * c2);
  } else {
    s.reachable = value_of(d) > L(0.0);
  }
  // the first link's direction: the wrist's turned back by the angle link 2 makes with it
  const T k1 = l1 + l2 * c2, k2 = l2 * s2;
  const T cw = k1 * x2 + k2 * y2, sw = k1 * y2 - k2 * x2;
  const T inv_n = T(1.0) / sqrt_of(cw * cw + sw * sw);
  JointTrigOf<T>& t = s.trig;
  t.c1 = cw * inv_n, t.s1 = sw * inv_n, t.c2 = c2, t.s2 = s2, t.c123 = ca, t.s123 = sa;
  t.c12 = t.c1 * c2 - t.s1 * s2, t.s12 = t.s1 * c2 + t.c1 * s2;
  t.c3 = ca * t.c12 + sa * t.s12, t.s3 = sa * t.c12 - ca * t.s12;  // theta3 = alpha - theta12
  t.c23 = ca * t.c1 + sa * t.s1, t.s23 = sa * t.c1 - ca * t.s1;    // theta23 = alpha - theta1
  s.J = jacobian(arm, t);
  s.det = (l1 * l2) * s2;
  const T inv_det = T(1.0) / s.det;
  s.qd = solve_extended_3r(arm, t, inv_det, T(pt.vx), T(pt.vy), ad);
  const Vec2Of<T> jdqd = jacobian_dot_times_qd(arm, t, s.qd);
  s.qdd = solve_extended_3r(arm, t, inv_det, T(pt.ax) - jdqd[0], T(pt.ay) - jdqd[1], add);
  s.M = mass_matrix_sym(dyn, t);
  const Vec3Of<T> c = coriolis(dyn, t, s.qd), g = gravity(dyn, t), Mq = s.M * s.qdd;
  s.tau = {Mq[0] + c[0] + g[0], Mq[1] + c[1] + g[1], Mq[2] + c[2] + g[2]};
}

/// The self-motion chart at a sample, in lanes.
template <class L>
struct ChartLanes {
  L phi[3], beta[3], r;  ///< ChartSample's, and the tip's distance from the base [m]
};

/// alpha and its first two time derivatives at the point (x, xd, xdd) of the self-motion chart c,
/// with cos and sin of theta2 there.
template <class T, class L = LaneOf<T>>
inline void self_motion_point(const ChartLanes<L>& c, const PlanarArm3& arm, const T& x, const T& xd, const T& xdd,
                              T& a, T& ad, T& add, T& c2, T& s2) {
  T sp, cp;
  sincos_of(x, sp, cp);
  const T b0(c.beta[0]), b1(c.beta[1]), b2(c.beta[2]);
  a = T(c.phi[0]) + b0 * sp;
  ad = T(c.phi[1]) + b1 * sp + b0 * cp * xd;
  add = T(c.phi[2]) + b2 * sp + 2.0 * b1 * cp * xd - b0 * sp * xd * xd + b0 * cp * xdd;
  const T h = self_motion_half_versine(sp, cp, c.beta[0], c.r, arm.l[2], arm.l[0], arm.l[1]);
  c2 = 1.0 - 2.0 * h;
  s2 = select(value_of(cp) >= L(0.0), T(2.0), T(-2.0)) * sqrt_of(h * (1.0 - h));
}

}  // namespace ks
