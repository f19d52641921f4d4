#pragma once
// Orocos KDL model of any ks::Chain: the independent oracle of the chain tests (never used by the engine).
#include <kdl/chain.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/jntspaceinertiamatrix.hpp>

#include "model/chain.hpp"

namespace ks::test {

inline KDL::Vector kdl_vector(const Eigen::Vector3d& v) { return KDL::Vector(v.x(), v.y(), v.z()); }

inline KDL::JntArray kdl_array(const VecN& v) {
  KDL::JntArray a(v.size());
  for (int i = 0; i < v.size(); ++i) a(i) = v[i];
  return a;
}

// KDL's results copied element by element: its Eigen storage comes from a library built for a
// different vector width (16-byte alignment), so it must not meet our vectorised expressions.
inline VecN from_kdl(const KDL::JntArray& a) {
  VecN v(a.rows());
  for (unsigned i = 0; i < a.rows(); ++i) v[i] = a(i);
  return v;
}
inline MatN from_kdl(const KDL::JntSpaceInertiaMatrix& m) {
  MatN M(m.rows(), m.columns());
  for (unsigned i = 0; i < m.rows(); ++i)
    for (unsigned j = 0; j < m.columns(); ++j) M(i, j) = m(i, j);
  return M;
}
inline Mat6N from_kdl(const KDL::Jacobian& j) {
  Mat6N J(6, j.columns());
  for (unsigned r = 0; r < 6; ++r)
    for (unsigned c = 0; c < j.columns(); ++c) J(r, c) = j(r, c);
  return J;
}

inline KDL::Frame kdl_frame(const Frame& f) {
  const Eigen::Matrix3d& R = f.R;  // KDL::Rotation takes the elements row by row
  return KDL::Frame(KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)),
                    kdl_vector(f.p));
}

/// The chain as KDL segments: a fixed segment carrying joint 0's origin, then one segment per joint
/// whose joint moves about (or along) the axis through the segment's base and whose tip frame is
/// the next joint's origin (the chain's tip frame for the last joint). KDL expresses a segment's
/// inertia in its tip frame, so each body's inertia (given in its joint frame) is moved there by
/// the inverse of the segment's tip frame.
inline KDL::Chain kdl_chain(const Chain& c) {
  KDL::Chain k;
  k.addSegment(KDL::Segment("base_to_joint0", KDL::Joint("fixed", KDL::Joint::Fixed), kdl_frame(c.joints.at(0).origin)));
  for (int i = 0; i < c.dof(); ++i) {
    const ChainJoint& j = c.joints[i];
    const KDL::Joint joint(j.name, KDL::Vector::Zero(), kdl_vector(j.axis),
                           j.type == JointType::revolute ? KDL::Joint::RotAxis : KDL::Joint::TransAxis);
    const KDL::Frame f_tip = kdl_frame(i + 1 < c.dof() ? c.joints[i + 1].origin : c.tip);
    const Eigen::Matrix3d& I = j.inertia;
    const KDL::RigidBodyInertia in_joint(j.mass, kdl_vector(j.com),
                                         KDL::RotationalInertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)));
    k.addSegment(KDL::Segment(j.name, joint, f_tip, f_tip.Inverse() * in_joint));
  }
  return k;
}

}  // namespace ks::test
