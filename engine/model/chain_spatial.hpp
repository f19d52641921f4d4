#pragma once
// Internal helpers of the chain algorithms (model/chain_kinematics.cpp, model/chain_dynamics.cpp):
// joint motion, unit twists and spatial cross products, all in the base frame at the base origin.
// A motion vector is (angular w; linear v) with v the velocity of the body point at the base
// origin; a force vector is (force f; moment n about the base origin).
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/chain.hpp"
#include "model/sincos.hpp"

namespace ks::detail {

using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

/// Rotation by angle q [rad] about the unit axis a (Rodrigues), given s = sin q, c = cos q.
inline M3 axis_rotation(const V3& a, double s, double c) {
  const double t = 1.0 - c;
  const double x = a.x(), y = a.y(), z = a.z();
  M3 R;
  R << c + t * x * x, t * x * y - s * z, t * x * z + s * y,  //
      t * x * y + s * z, c + t * y * y, t * y * z - s * x,   //
      t * x * z - s * y, t * y * z + s * x, c + t * z * z;
  return R;
}

/// Frame of joint j in the base frame from the previous joint's frame `prev` and q [rad or m]:
/// prev * origin * motion(q). Writes the frame and the joint axis in the base frame.
inline void joint_frame(const ChainJoint& j, const Frame& prev, double q, Frame& out, V3& axis) {
  const M3 R0 = prev.R * j.origin.R;
  const V3 p0 = prev.R * j.origin.p + prev.p;
  axis = R0 * j.axis;
  if (j.type == JointType::revolute) {
    double s, c;
    fast_sincos(q, s, c);
    out.R = R0 * axis_rotation(j.axis, s, c);
    out.p = p0;
  } else {
    out.R = R0;
    out.p = p0 + axis * q;
  }
}

/// Unit twist of joint j (axis a in the base frame, frame origin o): (a; o x a) for a revolute
/// joint, (0; a) for a prismatic one.
inline void joint_twist(JointType type, const V3& a, const V3& o, V3& w, V3& v) {
  if (type == JointType::revolute) {
    w = a;
    v = o.cross(a);
  } else {
    w.setZero();
    v = a;
  }
}

}  // namespace ks::detail
