#pragma once
// SCARA position IK of seed 001: unknowns q = (theta1, theta2, d) [rad, rad, mm], residual
// F(q) = FK(q) - target [mm], FK = (a1 c1 + a2 c12, a1 s1 + a2 s12, z(q3)).
#include <cmath>

#include "ik/problem.hpp"

namespace ks::ik {

/// How the third task coordinate depends on the prismatic joint q3.
enum class ScaraZ {
  thesis,    ///< z = q3, dz/dq3 = +1: what the seed computes (reproduces its Tables 3-7)
  physical,  ///< p_z = d1 - q3 - d3, dz/dq3 = -1 (the joint moves the tool down)
};

/// Constants of the seed's SCARA arm [mm] (seed 001, Table 2).
struct ScaraArm {
  double a1 = 200.0;  ///< link 1 length [mm]
  double a2 = 150.0;  ///< link 2 length [mm]
  double d1 = 100.0;  ///< base height to joint 2 [mm] (physical z mode only)
  double d3 = 40.0;   ///< tool offset [mm] (physical z mode only)
};

/// Position IK of the SCARA arm: 3 residuals [mm], 3 unknowns (theta1, theta2 [rad], d [mm]).
/// Known solutions (closed form): index 0 the elbow with sin(theta2) >= 0, index 1 the one with
/// sin(theta2) < 0; none when the (x, y) target is out of reach. Seed target: (50, -80, 10) mm.
struct ScaraPosition {
  static constexpr int unknowns = 3;
  static constexpr int residuals = 3;
  static constexpr std::array<bool, 3> revolute{true, true, false};

  ScaraArm arm{};
  Vec<3> target{50.0, -80.0, 10.0};  ///< [mm]
  ScaraZ z_mode = ScaraZ::thesis;

  /// z [mm] for joint value q3 [mm], and dz/dq3.
  double z_of(double q3) const { return z_mode == ScaraZ::thesis ? q3 : arm.d1 - q3 - arm.d3; }
  double dz() const { return z_mode == ScaraZ::thesis ? 1.0 : -1.0; }

  /// Forward kinematics [mm].
  Vec<3> forward(const Vec<3>& q) const {
    const double c1 = std::cos(q[0]), s1 = std::sin(q[0]);
    const double c12 = std::cos(q[0] + q[1]), s12 = std::sin(q[0] + q[1]);
    return {arm.a1 * c1 + arm.a2 * c12, arm.a1 * s1 + arm.a2 * s12, z_of(q[2])};
  }

  /// F = FK(q) - target [mm]; J = dF/dq (seed Eq. 35; its (3,3) entry is dz/dq3).
  void evaluate(const Vec<3>& q, Vec<3>& F, Mat<3, 3>& J) const {
    const double c1 = std::cos(q[0]), s1 = std::sin(q[0]);
    const double c12 = std::cos(q[0] + q[1]), s12 = std::sin(q[0] + q[1]);
    const double x2 = arm.a2 * c12, y2 = arm.a2 * s12;
    const double x = arm.a1 * c1 + x2, y = arm.a1 * s1 + y2;
    // Element-wise stores, not Eigen's comma initializer: GCC 12.2 at -O3 (ipa-modref) was seen to
    // lose comma-initialized stores to an output argument of an inlined-elsewhere evaluate().
    F[0] = x - target[0];
    F[1] = y - target[1];
    F[2] = z_of(q[2]) - target[2];
    J(0, 0) = -y, J(0, 1) = -y2, J(0, 2) = 0.0;
    J(1, 0) = x, J(1, 1) = x2, J(1, 2) = 0.0;
    J(2, 0) = 0.0, J(2, 1) = 0.0, J(2, 2) = dz();
  }

  /// d2F_i/dq_j dq_k [mm/rad^2]; the z residual is linear (zero matrix).
  SecondDerivatives<3, 3> second_derivatives(const Vec<3>& q) const {
    const double c1 = std::cos(q[0]), s1 = std::sin(q[0]);
    const double c12 = std::cos(q[0] + q[1]), s12 = std::sin(q[0] + q[1]);
    const double x2 = arm.a2 * c12, y2 = arm.a2 * s12;
    const double x = arm.a1 * c1 + x2, y = arm.a1 * s1 + y2;
    SecondDerivatives<3, 3> D;
    for (auto& m : D) m.setZero();
    D[0](0, 0) = -x, D[0](0, 1) = D[0](1, 0) = D[0](1, 1) = -x2;
    D[1](0, 0) = -y, D[1](0, 1) = D[1](1, 0) = D[1](1, 1) = -y2;
    return D;
  }

  /// Closed form: cos theta2 = (x^2 + y^2 - a1^2 - a2^2) / (2 a1 a2), theta1 = atan2(y, x) -
  /// atan2(a2 s2, a1 + a2 c2), q3 from z. Both elbow branches (see the struct comment).
  SolutionSet<3> known_solutions() const {
    SolutionSet<3> s;
    const double x = target[0], y = target[1];
    const double c2 = (x * x + y * y - arm.a1 * arm.a1 - arm.a2 * arm.a2) / (2.0 * arm.a1 * arm.a2);
    if (!(std::abs(c2) <= 1.0)) return s;
    const double q3 = z_mode == ScaraZ::thesis ? target[2] : arm.d1 - arm.d3 - target[2];
    for (const double sign : {1.0, -1.0}) {
      const double s2 = sign * std::sqrt(1.0 - c2 * c2);
      const double t1 = std::atan2(y, x) - std::atan2(arm.a2 * s2, arm.a1 + arm.a2 * c2);
      s.add(Vec<3>(wrap_angle(t1), std::atan2(s2, c2), q3));
    }
    return s;
  }
};

}  // namespace ks::ik
