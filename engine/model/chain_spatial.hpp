#pragma once
// Internal helpers of the chain algorithms (model/chain_kinematics.cpp, model/chain_dynamics.cpp):
// joint motion, unit twists and spatial cross products, all in the base frame at the base origin.
// A motion vector is (angular w; linear v) with v the velocity of the body point at the base
// origin; a force vector is (force f; moment n about the base origin).
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/chain.hpp"
#include "model/chain_kinematics.hpp"
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

/// Joint frames of a planar chain (Chain::planar()): each frame is an angle about z, stored as its
/// cosine and sine, and an origin in the base xy plane [m]. The revolute joints turn by sigma q
/// about z, sigma = axis.z() = +-1; the prismatic ones slide along their in-plane axis.
struct PlanarPose {
  double c[kMaxJoints], s[kMaxJoints];  ///< cos, sin of joint i's frame angle
  double x[kMaxJoints], y[kMaxJoints];  ///< joint i's frame origin [m]
  double tc, ts, tx, ty;                ///< the tip frame, likewise
};

/// Planar forward kinematics: \param[in] q (dim chain.dof()). \param[out] P the frames.
inline void planar_pose(const Chain& chain, const VecN& q, PlanarPose& P) {
  const int n = chain.dof();
  double sq[kMaxJoints], cq[kMaxJoints];
  for (int i = 0; i < n; ++i)  // independent calls first: they overlap in the pipeline
    if (chain.joints[i].type == JointType::revolute) fast_sincos(q[i], sq[i], cq[i]);
  double c = 1.0, s = 0.0, x = 0.0, y = 0.0;
  for (int i = 0; i < n; ++i) {
    const ChainJoint& j = chain.joints[i];
    const double px = j.origin.p.x(), py = j.origin.p.y();
    x += c * px - s * py;
    y += s * px + c * py;
    const double oc = j.origin.R(0, 0), os = j.origin.R(1, 0);
    const double c0 = c * oc - s * os, s0 = s * oc + c * os;
    if (j.type == JointType::revolute) {
      const double qs = j.axis.z() * sq[i], qc = cq[i];
      c = c0 * qc - s0 * qs;
      s = s0 * qc + c0 * qs;
    } else {
      c = c0;
      s = s0;
      x += (c * j.axis.x() - s * j.axis.y()) * q[i];
      y += (s * j.axis.x() + c * j.axis.y()) * q[i];
    }
    P.c[i] = c, P.s[i] = s, P.x[i] = x, P.y[i] = y;
  }
  const Frame& t = chain.tip;
  P.tx = x + c * t.p.x() - s * t.p.y();
  P.ty = y + s * t.p.x() + c * t.p.y();
  P.tc = c * t.R(0, 0) - s * t.R(1, 0);
  P.ts = s * t.R(0, 0) + c * t.R(1, 0);
}

/// A frame at angle (c, s) about z and origin (x, y, 0).
inline void planar_frame(double c, double s, double x, double y, Frame& f) {
  f.R << c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0;
  f.p = V3(x, y, 0.0);
}

/// Writes the frames of P and the joint axes into data (what forward_kinematics computes).
inline void store_planar_pose(const Chain& chain, const PlanarPose& P, ChainData& data) {
  for (int i = 0; i < chain.dof(); ++i) {
    const ChainJoint& j = chain.joints[i];
    planar_frame(P.c[i], P.s[i], P.x[i], P.y[i], data.joint[i]);
    if (j.type == JointType::revolute)
      data.axis[i] = V3(0.0, 0.0, j.axis.z());
    else
      data.axis[i] = V3(P.c[i] * j.axis.x() - P.s[i] * j.axis.y(), P.s[i] * j.axis.x() + P.c[i] * j.axis.y(), 0.0);
  }
  planar_frame(P.tc, P.ts, P.tx, P.ty, data.tip);
}

}  // namespace ks::detail
