#pragma once
// A serial chain's links as capsules and their clearance from obstacles, with its gradient in
// joint space: the distance a motion planner keeps positive and the direction that grows it.
//
// Link k of an n-joint chain (model/chain.hpp) is the capsule of the segment from joint k's frame
// origin to joint k + 1's (the tip frame's origin for k = n - 1) with radius radii[k]: n capsules,
// their endpoints from forward_kinematics (ChainData::joint[k].p, ChainData::tip.p). A link whose
// two origins coincide (intersecting axes, a spherical wrist) is a sphere. Lengths in metres,
// joint positions in rad (revolute) or m (prismatic), everything in the chain's base frame.
#include <array>
#include <span>
#include <variant>

#include "geometry/distance.hpp"
#include "model/chain.hpp"
#include "model/chain_kinematics.hpp"

namespace ks::geometry {

/// An obstacle at one instant (a moving one is passed at its current pose): a sphere, an oriented
/// box or a capsule, in the chain's base frame.
using Obstacle = std::variant<Sphere, Box, Capsule>;

/// The surface distance from a capsule (first) to an obstacle (second): capsule_sphere,
/// capsule_box or capsule_capsule (geometry/distance.hpp, its conventions).
ClosestPoints capsule_obstacle(const Capsule& link, const Obstacle& obstacle);
/// The obstacle moved by `by` [m] (a sphere's or box's centre, both ends of a capsule).
Obstacle translated(const Obstacle& obstacle, const Vec3& by);

/// Fixed-size per-call workspace of min_clearance: no allocation.
struct ClearanceWorkspace {
  ChainData chain;                             ///< forward kinematics at q
  std::array<Capsule, kMaxJoints> links;       ///< the link capsules at q
};

/// The least clearance between a chain's links and the obstacles, and its derivative.
struct Clearance {
  double distance = 0.0;  ///< [m] min over links k and obstacles j of capsule_obstacle; +inf: no obstacle
  int link = -1;          ///< k of the least pair (-1: no obstacle)
  int obstacle = -1;      ///< j of the least pair
  ClosestPoints closest;  ///< that pair's witnesses (the link first)
  /// d distance / d q [m/rad or m/m] (dim chain.dof()): the pair's endpoint gradient
  /// (first_segment_gradient) through the Jacobians of the link's two frame origins, d_a^T J_a +
  /// d_b^T J_b. Exact where the least pair is unique and its distance differentiable (see
  /// first_segment_gradient); at a switch of the least pair it is the current pair's. (Translating
  /// the obstacle by dx changes the distance by closest.normal . dx: a moving obstacle's share.)
  VecN gradient;
  /// d distance / d(translation of the least pair's obstacle) [m/m]: -(d_a + d_b), moving the
  /// obstacle by dx being moving the link by -dx (zero without an obstacle).
  Vec3 obstacle_gradient = Vec3::Zero();
};

/// The link capsules of `chain` at the frames of the last forward_kinematics(chain, data, q).
/// \param radii one per link (chain.dof()) [m]. \param[out] links the first chain.dof() entries.
void link_capsules(const Chain& chain, const ChainData& data, std::span<const double> radii,
                   std::array<Capsule, kMaxJoints>& links);

/// The Jacobian of frame k's origin (k in 0 .. dof; k = dof: the tip frame) at the frames of the
/// last forward_kinematics: column i maps q̇_i to the origin's velocity [m/s per rad/s or m/s]:
/// axis_i x (p_k - o_i) for a revolute joint i, axis_i for a prismatic one, for joints i <= k
/// (i < dof for the tip); 0 for the joints after it (a revolute joint does not move its own
/// frame's origin, a prismatic one does). \param[out] J (3 x dof).
void frame_origin_jacobian(const Chain& chain, const ChainData& data, int k,
                           Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kMaxJoints>& J);

/// The least clearance of the chain at q: forward kinematics, the link capsules (radii: one per
/// link [m]), every link against every obstacle, then the least pair's gradient in q.
/// Throws std::invalid_argument when radii.size() != chain.dof() or q.size() != chain.dof().
Clearance min_clearance(const Chain& chain, const VecN& q, std::span<const double> radii,
                        std::span<const Obstacle> obstacles, ClearanceWorkspace& ws);

}  // namespace ks::geometry
