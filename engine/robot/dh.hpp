#pragma once
// A serial chain (model/chain.hpp) from a standard Denavit–Hartenberg table (the distal convention of
// Spong and Corke): row i places link frame i in link frame i - 1 by
//   T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i),
// joint i turning about (revolute: theta_i + q_i) or sliding along (prismatic: d_i + q_i) the z axis
// of frame i - 1. Frame 0 is the base frame, frame n the tip frame. Each link's mass properties are
// given in its own frame i (at the link's distal end, the next joint's axis).
#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "model/chain.hpp"

namespace ks {

/// One row of a standard DH table with the mass properties and limits of the link it moves.
struct DhLink {
  std::string name;                  ///< the joint's name ("joint<i>" when empty)
  JointType type = JointType::revolute;
  /// A row without a joint: its frame T_i(theta, d, a, alpha) is fixed in the previous link, which
  /// carries its mass (e.g. a wrist locked at its offsets). No limits.
  bool fixed = false;
  double a = 0.0;                    ///< along x_i [m]
  double alpha = 0.0;                ///< about x_i [rad]
  double d = 0.0;                    ///< along z_{i-1} [m]; a prismatic joint's offset (q = 0 at d)
  double theta = 0.0;                ///< about z_{i-1} [rad]; a revolute joint's offset (q = 0 at theta)
  double mass = 0.0;                 ///< [kg]
  Eigen::Vector3d com = Eigen::Vector3d::Zero();      ///< centre of mass, link frame i [m]
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< about the centre of mass, frame i's axes [kg m^2]
  double lower = -std::numeric_limits<double>::infinity();  ///< position limits of q [rad or m]
  double upper = std::numeric_limits<double>::infinity();
  double velocity = std::numeric_limits<double>::infinity();  ///< |qd| limit [rad/s or m/s]
  double effort = std::numeric_limits<double>::infinity();    ///< |tau| limit [Nm or N]
};

/// The chain of the DH table `links` (base to tip; 1 .. kMaxJoints rows), with `gravity` [m/s^2,
/// base frame = DH frame 0], named `name`, source `source`. Joint i's chain frame is frame i - 1
/// turned by theta_i (and, prismatic, moved by d_i) about its z axis, the joint axis +z; the rest of
/// the row, Tz(d_i) (revolute) Tx(a_i) Rx(alpha_i), becomes the next joint's origin (the tip frame
/// after the last row), and the link's mass properties are moved from frame i into the joint frame.
/// A fixed row adds no joint: its frame is composed into the next joint's origin (or the tip frame)
/// and its mass properties are added to the body of the joint before it (the base's, which does not
/// move, when none is). At least one row must be a joint.
/// No check: the caller validates the values (Chain::IsValid, robot/inertia_check.hpp). prepare()d.
Chain dh_chain(const std::vector<DhLink>& links, const Eigen::Vector3d& gravity, std::string name, std::string source);

/// T_i = Rz(theta) Tz(d) Tx(a) Rx(alpha) as a frame (rotation, translation).
Frame dh_frame(double a, double alpha, double d, double theta);

}  // namespace ks
