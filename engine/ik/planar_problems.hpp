#pragma once
// IK problems of the engine's planar 3R arm (model/kinematics.hpp): q = joint angles [rad].
#include <algorithm>

#include "ik/problem.hpp"
#include "model/kinematics.hpp"

namespace ks::ik {

namespace detail {
/// Tip position terms of the planar 3R arm: X[j] = sum_{i >= j} l_i cos(phi_i), Y likewise with
/// sin, phi_i = theta1 + ... + theta_i. Then dx/dq_j = -Y[j], d2x/dq_j dq_k = -X[max(j, k)].
struct PlanarSums {
  double X[3], Y[3];
};
inline PlanarSums planar_sums(const PlanarArm3& a, const JointTrig& t) {
  PlanarSums s;
  s.X[2] = a.l[2] * t.c123;
  s.Y[2] = a.l[2] * t.s123;
  s.X[1] = a.l[1] * t.c12 + s.X[2];
  s.Y[1] = a.l[1] * t.s12 + s.Y[2];
  s.X[0] = a.l[0] * t.c1 + s.X[1];
  s.Y[0] = a.l[0] * t.s1 + s.Y[1];
  return s;
}
inline void planar_position_hessians(const PlanarSums& s, Mat<3, 3>& Dx, Mat<3, 3>& Dy) {
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) {
      const int m = j > k ? j : k;
      Dx(j, k) = -s.X[m];
      Dy(j, k) = -s.Y[m];
    }
}
}  // namespace detail

/// Position + orientation IK of the planar 3R arm: a square 3x3 system.
/// F = (tip(q) - target [m], wrap(theta1 + theta2 + theta3 - alpha) [rad]); J = jacobian_with_alpha.
/// The orientation residual is wrapped to (-pi, pi], so alpha and alpha + 2 pi are the same target
/// (F is smooth except where the sum crosses alpha + pi). Known solutions: both elbow branches of
/// inverse_kinematics (index 0 Elbow::positive, 1 Elbow::negative); none when out of reach.
struct PlanarPose {
  static constexpr int unknowns = 3;
  static constexpr int residuals = 3;
  static constexpr std::array<bool, 3> revolute{true, true, true};

  PlanarArm3 arm{};
  Vec2 target = Vec2::Zero();  ///< tip position [m]
  double alpha = 0.0;          ///< orientation theta1 + theta2 + theta3 [rad]

  void evaluate(const Vec<3>& q, Vec<3>& F, Mat<3, 3>& J) const {
    const JointTrig t = joint_trig(q);
    const Vec2 p = end_effector(arm, t);
    F[0] = p.x() - target.x();  // element-wise: see ScaraPosition::evaluate
    F[1] = p.y() - target.y();
    F[2] = wrap_angle(q[0] + q[1] + q[2] - alpha);
    J = jacobian_with_alpha(arm, t);
  }

  /// d2F/dq2 [m/rad^2]; the orientation residual is linear (zero matrix).
  SecondDerivatives<3, 3> second_derivatives(const Vec<3>& q) const {
    SecondDerivatives<3, 3> D;
    detail::planar_position_hessians(detail::planar_sums(arm, joint_trig(q)), D[0], D[1]);
    D[2].setZero();
    return D;
  }

  SolutionSet<3> known_solutions() const {
    SolutionSet<3> s;
    for (const Elbow e : {Elbow::positive, Elbow::negative})
      if (const auto q = inverse_kinematics(arm, target, alpha, e)) s.add(*q);
    return s;
  }
};

/// Position-only IK of the planar 3R arm: 2 residuals, 3 unknowns (redundant by one).
/// F = tip(q) - target [m]; J = the 2x3 position Jacobian. Newton-type methods take minimum-norm
/// steps. The solutions form a continuum (a curve in joint space): no isolated known solutions.
struct PlanarPosition {
  static constexpr int unknowns = 3;
  static constexpr int residuals = 2;
  static constexpr std::array<bool, 3> revolute{true, true, true};

  PlanarArm3 arm{};
  Vec2 target = Vec2::Zero();  ///< tip position [m]

  void evaluate(const Vec<3>& q, Vec<2>& F, Mat<2, 3>& J) const {
    const JointTrig t = joint_trig(q);
    F = end_effector(arm, t) - target;
    J = jacobian(arm, t);
  }

  SecondDerivatives<2, 3> second_derivatives(const Vec<3>& q) const {
    SecondDerivatives<2, 3> D;
    detail::planar_position_hessians(detail::planar_sums(arm, joint_trig(q)), D[0], D[1]);
    return D;
  }

  /// No isolated solutions: continuum = true when the target is reachable (between the inner and
  /// outer workspace radii), false (and no solution) otherwise.
  SolutionSet<3> known_solutions() const {
    const double r = target.norm(), L = arm.l[0] + arm.l[1] + arm.l[2];
    double inner = 0.0;
    for (int i = 0; i < 3; ++i) inner = std::max(inner, 2.0 * arm.l[i] - L);
    SolutionSet<3> s;
    s.continuum = r <= L && r >= inner;
    return s;
  }
};

}  // namespace ks::ik
