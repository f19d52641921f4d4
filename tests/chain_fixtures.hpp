#pragma once
// Chains and random states for the chain tests.
#include <Eigen/Geometry>
#include <random>

#include "model/chain.hpp"

namespace ks::test {

inline Eigen::Matrix3d rpy(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

/// A 3-D chain exercising every general case: prismatic joints, oblique axes, joint origins offset
/// and rotated in all three axes, centres of mass off the axes, non-diagonal inertias (principal
/// moments rotated into the joint frame), a rotated tip frame and an oblique gravity vector.
inline Chain test_chain_prismatic() {
  struct Spec {
    JointType type;
    Eigen::Vector3d axis, p, rpy, com, principal, inertia_rpy;
    double mass;
  };
  const Spec specs[] = {
      {JointType::revolute, {0, 0, 1}, {0, 0, 0.3}, {0.1, -0.2, 0.3}, {0.02, -0.01, 0.12}, {0.05, 0.06, 0.03}, {0.2, 0.1, -0.3}, 2.5},
      {JointType::prismatic, {1, -2, 2}, {0.2, 0.1, 0.05}, {0.5, 0.2, -0.4}, {0.1, 0.03, -0.02}, {0.02, 0.03, 0.04}, {-0.4, 0.6, 0.2}, 1.7},
      {JointType::revolute, {0.3, 0.9, -0.2}, {0.4, -0.1, 0.2}, {-0.3, 0.7, 0.1}, {0.0, 0.15, 0.05}, {0.03, 0.02, 0.025}, {0.9, -0.2, 0.4}, 1.2},
      {JointType::revolute, {1, 0, 0}, {0.1, 0.3, 0.0}, {1.2, 0.0, 0.2}, {0.05, 0.0, 0.1}, {0.01, 0.012, 0.008}, {0.3, 0.3, 0.3}, 0.8},
      {JointType::prismatic, {0, 1, 0}, {0.0, 0.05, 0.25}, {0.0, -0.5, 0.9}, {-0.03, 0.04, 0.02}, {0.004, 0.003, 0.005}, {0.1, -0.7, 0.5}, 0.4},
  };
  Chain c;
  c.name = "test_prismatic";
  c.source = "test";
  int k = 0;
  for (const Spec& s : specs) {
    ChainJoint j;
    j.name = "j" + std::to_string(++k);
    j.type = s.type;
    j.axis = s.axis.normalized();
    j.origin.p = s.p;
    j.origin.R = rpy(s.rpy.x(), s.rpy.y(), s.rpy.z());
    j.mass = s.mass;
    j.com = s.com;
    const Eigen::Matrix3d Q = rpy(s.inertia_rpy.x(), s.inertia_rpy.y(), s.inertia_rpy.z());
    j.inertia = Q * s.principal.asDiagonal() * Q.transpose();
    j.inertia = (0.5 * (j.inertia + j.inertia.transpose())).eval();
    c.joints.push_back(j);
  }
  c.tip.p = Eigen::Vector3d(0.05, 0.02, 0.1);
  c.tip.R = rpy(0.2, 0.3, 0.4);
  c.gravity = Eigen::Vector3d(0.5, -1.0, -9.7);
  c.prepare();
  return c;
}

/// Seeded random joint vectors of any size.
struct RandomJoints {
  std::mt19937_64 rng{20240611};
  VecN uniform(int n, double range) {
    std::uniform_real_distribution<double> d(-range, range);
    VecN v(n);
    for (int i = 0; i < n; ++i) v[i] = d(rng);
    return v;
  }
  VecN q(int n) { return uniform(n, 3.0); }
  VecN v(int n) { return uniform(n, 3.0); }
  VecN a(int n) { return uniform(n, 10.0); }
};

}  // namespace ks::test
