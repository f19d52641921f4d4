#pragma once
// The plane a planar chain moves in, whatever plane of its base frame that is, and the chain
// re-expressed in that plane's frame so that the planar algorithms (Chain::planar(): motion in the
// base xy plane) apply to it unchanged.
//
// A chain moves in a plane when every revolute joint axis, expressed in the base frame at q = 0, is
// parallel to one direction n and every prismatic axis is perpendicular to n: rotations about axes
// parallel to n keep them parallel for every q, so every point of every body moves in a plane
// normal to n, and the tip in the plane through its position at q = 0.
#include <Eigen/Core>
#include <optional>

#include "model/chain.hpp"

namespace ks {

/// A plane in a chain's base frame: `frame` maps plane coordinates to base coordinates. Its columns
/// R.col(0), R.col(1) are the in-plane axes e1, e2 (unit, orthogonal), R.col(2) = e1 x e2 is the
/// normal n; p is the plane's origin [m]. Plane coordinates (u, v) are the base point p + u e1 + v e2.
struct ChainPlane {
  Frame frame;

  Eigen::Vector3d origin() const { return frame.p; }
  Eigen::Vector3d e1() const { return frame.R.col(0); }
  Eigen::Vector3d e2() const { return frame.R.col(1); }
  Eigen::Vector3d normal() const { return frame.R.col(2); }
  /// The base xy plane itself: R = I and p = 0, exactly (plane coordinates are then base x, y).
  bool is_base_xy() const { return frame.R == Eigen::Matrix3d::Identity() && frame.p == Eigen::Vector3d::Zero(); }
  /// Plane coordinates of the base point x [m]; `off` (when given) receives its signed distance from
  /// the plane along n [m].
  Eigen::Vector2d to_plane(const Eigen::Vector3d& x, double* off = nullptr) const;
  /// The base point at plane coordinates u [m].
  Eigen::Vector3d to_base(const Eigen::Vector2d& u) const { return frame.p + frame.R.leftCols<2>() * u; }
  /// The component of the base vector g in the plane, in plane coordinates (its component along n
  /// dropped).
  Eigen::Vector2d project(const Eigen::Vector3d& g) const { return frame.R.leftCols<2>().transpose() * g; }
};

/// Two directions are parallel when the sine of the angle between them is below this [-].
inline constexpr double kParallelTol = 1e-9;

/// The plane `chain` moves in, or nullopt when it is spatial (two revolute axes not parallel, or a
/// prismatic axis not normal to the revolute ones).
///  - a chain already in its base xy plane (Chain::planar() but for gravity) gets the base xy plane
///    exactly: R = I, p = 0; a chain of prismatic joints only is planar in that case alone;
///  - otherwise e1 is the first base axis (x, y, z in that order) whose projection on the plane is
///    at least 0.5 long, projected and normalised; e2 the first other base axis whose projection,
///    made perpendicular to e1, is at least 0.5 long, likewise; n = e1 x e2 (parallel or
///    antiparallel to the revolute axes). An arm in the base xz plane gets e1 = x, e2 = z, n = -y;
///  - the origin is the base origin projected along n on the plane of the tip's motion.
std::optional<ChainPlane> motion_plane(const Chain& chain);

/// `chain` (with motion_plane(chain) = `plane`) expressed in the plane's frame: its base frame is the
/// plane frame, every joint frame is turned to the plane frame's axes (rotations of the origins
/// about z only; revolute axes exactly +z or -z, prismatic axes in xy) and slid along n into the
/// plane (z = 0), each body's centre of mass and inertia expressed in its turned joint frame, and
/// gravity the in-plane part of chain.gravity, in plane coordinates (z = 0). The tip frame keeps
/// its position and its angle about n: its x axis' direction in the plane (its y axis' less 90 deg
/// when x is within 30 deg of n). The result is planar() and prepare()d.
///
/// Exact for the joint-space dynamics and the in-plane tip kinematics: for joint i, tau_i is the
/// moment about an axis parallel to n (revolute) or the force along an in-plane direction
/// (prismatic); a force along n (gravity's normal part, or the reaction to a body's offset along n)
/// has no moment about a line parallel to n and no component in the plane, and sliding a body along
/// n changes neither its in-plane motion nor its inertia about axes parallel to n. So M(q), c(q, qd),
/// g(q) and the tip's in-plane position, Jacobian and angle are those of `chain`, in plane
/// coordinates; gravity normal to the plane (a horizontal arm) gives g(q) = 0.
/// A chain already in its base xy plane (plane.is_base_xy() and Chain::planar() but for gravity) is
/// returned bit for bit as it is, with gravity.z() set to 0: the shipped planar arms are unchanged.
Chain in_plane_frame(const Chain& chain, const ChainPlane& plane);

}  // namespace ks
