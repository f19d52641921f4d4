#pragma once
// A serial chain of revolute and prismatic joints: any arm the engine studies beyond the seed's
// closed-form 3R (n-link planar arms, URDF robots). Pure data: constants of the robot only; the
// algorithms (model/chain_kinematics.hpp, model/chain_dynamics.hpp) take a ChainData workspace.
//
// Frames: joint i's frame is placed by `origin` in the frame of joint i - 1 (joint 0: in the base
// frame) at q_i = 0, and moves with q_i (a rotation by q_i about `axis`, or a translation by q_i
// along it). The body moved by joint i (every link rigidly attached to it, merged) has its mass
// properties in joint i's frame. Units: m, kg, kg m^2, rad (revolute) or m (prismatic).
#include <Eigen/Core>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

namespace ks {

/// The largest chain the engine handles: every per-joint vector and matrix has this fixed maximum
/// size, so a chain's computations never allocate.
inline constexpr int kMaxJoints = 8;

using VecN = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxJoints, 1>;                       ///< joint space
using MatN = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxJoints, kMaxJoints>;  ///< joint x joint
using Mat6N = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, kMaxJoints>;  ///< twist rows x joints
using Vec6 = Eigen::Matrix<double, 6, 1>;                                   ///< (linear; angular)

/// A joint vector from its values, e.g. joint_vector({0.1, 0.2, 0.3}).
inline VecN joint_vector(std::initializer_list<double> v) {
  VecN q(static_cast<Eigen::Index>(v.size()));
  Eigen::Index i = 0;
  for (double x : v) q[i++] = x;
  return q;
}

/// A rigid transform: a point x in the child frame is R x + p in the parent frame.
struct Frame {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< [m]
  Frame operator*(const Frame& b) const { return {R * b.R, R * b.p + p}; }
};

enum class JointType { revolute, prismatic };

struct ChainJoint {
  std::string name;
  JointType type = JointType::revolute;
  Frame origin;                                    ///< this joint's frame in the previous one's at q = 0
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ(); ///< unit axis in this joint's frame
  double lower = -std::numeric_limits<double>::infinity();  ///< position limits [rad or m]
  double upper = std::numeric_limits<double>::infinity();
  double velocity = std::numeric_limits<double>::infinity();  ///< |qd| limit [rad/s or m/s] (URDF <limit velocity>)
  double effort = std::numeric_limits<double>::infinity();    ///< |tau| limit [Nm or N] (URDF <limit effort>)
  double mass = 0.0;                               ///< of the body this joint moves [kg]
  Eigen::Vector3d com = Eigen::Vector3d::Zero();   ///< its centre of mass, joint frame [m]
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< about the centre of mass, joint frame axes [kg m^2]
  bool limited() const { return lower > -std::numeric_limits<double>::infinity() || upper < std::numeric_limits<double>::infinity(); }
};

/// A serial chain from a fixed base to a tip (tool) frame.
struct Chain {
  std::string name;                 ///< for messages and the store ("planar4r", the URDF robot name)
  std::string source;               ///< where it came from: "planar" or the URDF file path
  std::vector<ChainJoint> joints;   ///< base to tip; 1 .. kMaxJoints
  Frame tip;                        ///< the tip frame in the last joint's frame
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};  ///< gravitational acceleration, base frame [m/s^2]

  int dof() const { return static_cast<int>(joints.size()); }
  /// Every joint is revolute about the base z axis or prismatic in the base xy plane, every frame
  /// stays in the xy plane (origins with z = 0 and rotations about z only) and gravity lies in the
  /// plane: the tip then moves in the xy plane and its orientation is one angle about z.
  bool planar() const;
  /// True when the chain can be simulated: 1 .. kMaxJoints joints, unit axes, finite values,
  /// masses >= 0, symmetric positive semi-definite inertias, lower <= upper. Otherwise false, with
  /// `why` naming the joint and the rule.
  bool IsValid(std::string* why = nullptr) const;

  /// planar() as of the last prepare(): the dynamics (model/chain_dynamics.hpp) then take their
  /// 2-D specialisation, decided by this flag rather than by re-testing the geometry per call.
  /// planar_chain and load_urdf call prepare(); call it again after editing a chain by hand (a chain
  /// never prepared uses the general spatial algorithms, which are right for every chain).
  bool planar_fast_path = false;
  void prepare() { planar_fast_path = planar(); }
};

/// One link of an n-link planar arm: a revolute joint about z, then the link along its x axis.
struct PlanarLink {
  double l = 1.0;      ///< length [m] (the next joint sits at (l, 0) in this joint's frame)
  double m = 1.0;      ///< mass [kg]
  double lc = 0.5;     ///< joint-to-centre-of-mass distance along the link [m]
  double I = 0.0;      ///< rotational inertia about the centre of mass, about z [kg m^2]
  double lower = -std::numeric_limits<double>::infinity();  ///< joint limits [rad]
  double upper = std::numeric_limits<double>::infinity();
  double velocity = std::numeric_limits<double>::infinity();  ///< |qd| limit [rad/s]
  double effort = std::numeric_limits<double>::infinity();    ///< |tau| limit [Nm]
};

/// An n-link planar arm in the base xy plane with gravity g along -y [m/s^2]; the tip frame at the
/// end of the last link. Joint 0 sits at the base origin, joint i at (l_{i-1}, 0, 0) in joint i-1's
/// frame. Each body gets I as its z inertia and, so that the chain is a valid 3-D body, the
/// inertias about x and y of a bar of square section b x b with b^2 = max(0, 12 I / m - l^2): Ixx =
/// m b^2 / 6, Iyy = I (they never act in the plane). The chain is prepare()d.
Chain planar_chain(const std::vector<PlanarLink>& links, double g = 9.81, std::string name = "planar");
/// Uniform bars of thickness b [m]: lc = l / 2, I = m (l^2 + b^2) / 12 (the seed's arm: l = 1, m = (5, 2, 1), b = 0.1).
/// Throws std::invalid_argument when l and m differ in size.
std::vector<PlanarLink> planar_bars(const std::vector<double>& l, const std::vector<double>& m, double b);

}  // namespace ks
