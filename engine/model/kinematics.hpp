#pragma once
// Kinematics of the planar 3R arm: forward kinematics, Jacobians and their time derivative,
// analytic inverse kinematics at a point for a prescribed orientation.
#include <Eigen/Core>
#include <optional>

#include "model/arm.hpp"
#include "model/lanes.hpp"
#include "model/trig.hpp"

namespace ks {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Mat23 = Eigen::Matrix<double, 2, 3>;

/// Positions [m] of joint 2, joint 3 and the end-effector, and the orientation alpha [rad].
struct ArmPose {
  Vec2 elbow;     ///< joint 2 (tip of link 1)
  Vec2 wrist;     ///< joint 3 (tip of link 2)
  Vec2 tip;       ///< end-effector (tip of link 3)
  double alpha;   ///< theta1 + theta2 + theta3 [rad]
};

/// End-effector position [m] from precomputed trig.
inline Vec2 end_effector(const PlanarArm3& a, const JointTrig& t) {
  return {a.l[0] * t.c1 + a.l[1] * t.c12 + a.l[2] * t.c123, a.l[0] * t.s1 + a.l[1] * t.s12 + a.l[2] * t.s123};
}

/// Forward kinematics. Input q [rad]. Output: every joint position and the orientation.
inline ArmPose forward_kinematics(const PlanarArm3& a, const Vec3& q) {
  const JointTrig t = joint_trig(q);
  ArmPose p;
  p.elbow = {a.l[0] * t.c1, a.l[0] * t.s1};
  p.wrist = p.elbow + Vec2(a.l[1] * t.c12, a.l[1] * t.s12);
  p.tip = p.wrist + Vec2(a.l[2] * t.c123, a.l[2] * t.s123);
  p.alpha = q[0] + q[1] + q[2];
  return p;
}

/// 2x3 position Jacobian d(tip)/dq [m/rad] (seed Eq. 24). T: double (an Eigen Mat23) or lanes.
template <class T>
inline Mat23Of<T> jacobian(const PlanarArm3& a, const JointTrigOf<T>& t) {
  const T x3 = a.l[2] * t.c123, y3 = a.l[2] * t.s123;
  const T x2 = a.l[1] * t.c12 + x3, y2 = a.l[1] * t.s12 + y3;
  const T x1 = a.l[0] * t.c1 + x2, y1 = a.l[0] * t.s1 + y2;
  Mat23Of<T> J;
  J(0, 0) = -y1, J(0, 1) = -y2, J(0, 2) = -y3;
  J(1, 0) = x1, J(1, 1) = x2, J(1, 2) = x3;
  return J;
}

/// 3x3 Jacobian of (tip, alpha): the position rows and the row (1, 1, 1) (seed Eq. 23).
inline Mat3 jacobian_with_alpha(const PlanarArm3& a, const JointTrig& t) {
  Mat3 J;
  J.topRows<2>() = jacobian(a, t);
  J.row(2).setOnes();
  return J;
}

/// Time derivative of the 2x3 position Jacobian [m/(rad s)], at joint velocities qd [rad/s].
inline Mat23 jacobian_dot(const PlanarArm3& a, const JointTrig& t, const Vec3& qd) {
  const double w1 = qd[0], w2 = w1 + qd[1], w3 = w2 + qd[2];  // absolute link angular rates
  const double x3 = a.l[2] * t.c123 * w3, y3 = a.l[2] * t.s123 * w3;
  const double x2 = a.l[1] * t.c12 * w2 + x3, y2 = a.l[1] * t.s12 * w2 + y3;
  const double x1 = a.l[0] * t.c1 * w1 + x2, y1 = a.l[0] * t.s1 * w1 + y2;
  Mat23 Jd;
  Jd << -x1, -x2, -x3, -y1, -y2, -y3;
  return Jd;
}

/// Jdot qd [m/s^2], the velocity-product part of the tip acceleration: (-sum l_j cos(phi_j) w_j^2,
/// -sum l_j sin(phi_j) w_j^2) with phi_j, w_j the absolute angle and rate of link j. Equals
/// jacobian_dot(a, t, qd) * qd at a third of the cost. T: double (Eigen vectors) or lanes.
template <class T>
inline Vec2Of<T> jacobian_dot_times_qd(const PlanarArm3& a, const JointTrigOf<T>& t, const Vec3Of<T>& qd) {
  const T w1 = qd[0], w2 = w1 + qd[1], w3 = w2 + qd[2];
  const T e1 = a.l[0] * w1 * w1, e2 = a.l[1] * w2 * w2, e3 = a.l[2] * w3 * w3;
  return {-(e1 * t.c1 + e2 * t.c12 + e3 * t.c123), -(e1 * t.s1 + e2 * t.s12 + e3 * t.s123)};
}

/// The end-effector position read off the Jacobian's first column (J = [-y1 ...; x1 ...]).
inline Vec2 end_effector_from_jacobian(const Mat23& J) { return {J(1, 0), -J(0, 0)}; }

/// Manipulability squared det(J J^T) of the 2x3 position Jacobian [m^4]; 0 at a singular configuration.
/// The row sums are taken as Eigen's squaredNorm() and dot() of a 3-vector take them: x0 + (x1 + x2).
template <class J23>
inline auto manipulability_squared(const J23& J) {
  const auto a = J(0, 0) * J(0, 0) + (J(0, 1) * J(0, 1) + J(0, 2) * J(0, 2));
  const auto b = J(0, 0) * J(1, 0) + (J(0, 1) * J(1, 1) + J(0, 2) * J(1, 2));
  const auto c = J(1, 0) * J(1, 0) + (J(1, 1) * J(1, 1) + J(1, 2) * J(1, 2));
  const auto d = a * c - b * b;
  return select(d > 0.0, d, decltype(d)(0.0));
}
/// Manipulability sqrt(det(J J^T)) [m^2].
inline double manipulability(const Mat23& J) { return std::sqrt(manipulability_squared(J)); }

/// Elbow branch of the analytic IK: sign of sin(theta2). The seed uses +1.
enum class Elbow : int { positive = 1, negative = -1 };

/// Analytic IK at point p [m] with orientation alpha [rad] (seed Appendix G).
/// Output: q [rad] on the requested elbow branch, or std::nullopt when no real solution exists
/// (|cos theta2| > 1: the wrist is out of reach of links 1 and 2).
inline std::optional<Vec3> inverse_kinematics(const PlanarArm3& a, const Vec2& p, double alpha,
                                              Elbow elbow = Elbow::positive) {
  const double x2 = p.x() - a.l[2] * std::cos(alpha);
  const double y2 = p.y() - a.l[2] * std::sin(alpha);
  const double d = x2 * x2 + y2 * y2;
  const double c2 = (d - a.l[0] * a.l[0] - a.l[1] * a.l[1]) / (2.0 * a.l[0] * a.l[1]);
  if (!(std::abs(c2) <= 1.0) || d == 0.0) return std::nullopt;
  const double s2 = static_cast<int>(elbow) * std::sqrt(1.0 - c2 * c2);
  const double c1 = ((a.l[0] + a.l[1] * c2) * x2 + a.l[1] * s2 * y2) / d;
  const double s1 = ((a.l[0] + a.l[1] * c2) * y2 - a.l[1] * s2 * x2) / d;
  const double t1 = std::atan2(s1, c1);
  const double t2 = std::atan2(s2, c2);
  return Vec3(t1, t2, alpha - t1 - t2);
}

}  // namespace ks
