#pragma once
// Test chains for chain IK, built by hand: a 7-DOF S-R-S arm, chains with prismatic joints.
#include <Eigen/Geometry>
#include <numbers>

#include "model/chain.hpp"

namespace ks::test {

inline ChainJoint ik_joint(JointType type, const Eigen::Vector3d& origin, const Eigen::Vector3d& axis,
                           double limit = std::numeric_limits<double>::infinity(),
                           const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
  ChainJoint j;
  j.type = type;
  j.origin.p = origin;
  j.origin.R = R;
  j.axis = axis;
  j.lower = -limit;
  j.upper = limit;
  j.mass = 1.0;
  j.inertia = 0.01 * Eigen::Matrix3d::Identity();
  return j;
}

/// 7-DOF S-R-S arm: axes z, y, z, y, z, y, z; shoulder 0.34 m above the base, upper arm 0.40,
/// forearm 0.40, flange 0.126; limits +-170, 120, 170, 120, 170, 120, 175 deg (or none).
inline Chain srs7_chain(bool limits = true) {
  constexpr double d = std::numbers::pi / 180.0;
  const double inf = std::numeric_limits<double>::infinity();
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ(), y = Eigen::Vector3d::UnitY();
  const double lim[7] = {170 * d, 120 * d, 170 * d, 120 * d, 170 * d, 120 * d, 175 * d};
  auto L = [&](int i) { return limits ? lim[i] : inf; };
  Chain c;
  c.name = "srs7";
  c.source = "test";
  c.gravity = {0.0, 0.0, -9.81};
  c.joints = {ik_joint(JointType::revolute, {0, 0, 0.34}, z, L(0)), ik_joint(JointType::revolute, {0, 0, 0}, y, L(1)),
              ik_joint(JointType::revolute, {0, 0, 0.20}, z, L(2)), ik_joint(JointType::revolute, {0, 0, 0.20}, y, L(3)),
              ik_joint(JointType::revolute, {0, 0, 0.20}, z, L(4)), ik_joint(JointType::revolute, {0, 0, 0.20}, y, L(5)),
              ik_joint(JointType::revolute, {0, 0, 0}, z, L(6))};
  c.tip.p = {0, 0, 0.126};
  c.prepare();
  return c;
}

/// A spatial 5-joint chain with a prismatic joint and tilted frames: R(z) P(x) R(y) R(z) R(x).
inline Chain prismatic_spatial_chain() {
  Chain c;
  c.name = "rprrr";
  c.source = "test";
  c.gravity = {0.0, 0.0, -9.81};
  const Eigen::Matrix3d tilt = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  c.joints = {ik_joint(JointType::revolute, {0, 0, 0.3}, Eigen::Vector3d::UnitZ()),
              ik_joint(JointType::prismatic, {0.1, 0, 0.05}, Eigen::Vector3d::UnitX(), 0.5),
              ik_joint(JointType::revolute, {0.2, 0, 0}, Eigen::Vector3d::UnitY(), std::numeric_limits<double>::infinity(), tilt),
              ik_joint(JointType::revolute, {0.3, 0.05, 0}, Eigen::Vector3d::UnitZ()),
              ik_joint(JointType::revolute, {0.2, 0, 0}, Eigen::Vector3d(0.6, 0.0, 0.8))};
  c.tip.p = {0.1, 0.02, 0.05};
  c.tip.R = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  c.prepare();
  return c;
}

/// A planar R P R chain in the xy plane: revolute z, prismatic along x, revolute z (axis -z), tip.
inline Chain prismatic_planar_chain() {
  Chain c;
  c.name = "rpr";
  c.source = "test";
  const Eigen::Matrix3d rz = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  c.joints = {ik_joint(JointType::revolute, {0, 0, 0}, Eigen::Vector3d::UnitZ()),
              ik_joint(JointType::prismatic, {0.3, 0, 0}, Eigen::Vector3d::UnitX(), 0.4),
              ik_joint(JointType::revolute, {0.3, 0, 0}, -Eigen::Vector3d::UnitZ(), std::numeric_limits<double>::infinity(), rz)};
  c.tip.p = {0.4, 0, 0};
  c.prepare();
  return c;
}

}  // namespace ks::test
