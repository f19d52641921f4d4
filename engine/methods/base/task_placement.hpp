#pragma once
// Where and how fast a task is done: a rigid placement of the whole task (a rotation beta about the
// base's z axis, then a translation dx, dy, dz; seed 002 Eq. 2.21) and a time scale of its durations,
// applied to a run's task by the runner (runner/placed_task.hpp) before the run.
// A planar robot's task lives in its plane's coordinates: there beta turns about the plane's normal and
// dx, dy move along the plane's axes (the base z and x, y for the seed's arm and the n-link arms).
#include <Eigen/Core>
#include <cmath>
#include <numbers>

#include "common/domain.hpp"

namespace ks {

struct TaskPlacement {
  double rotation = 0.0;    ///< beta: rotation about the base z axis (a planar robot: its plane's normal) [rad]
  double dx = 0.0;          ///< translation along x [m]
  double dy = 0.0;          ///< translation along y [m]
  double dz = 0.0;          ///< translation along z [m] (spatial robots only)
  double time_scale = 1.0;  ///< every segment duration multiplied by this [-] (2: the task done twice as slowly)
  /// Set for the runs of a block that has placement parameters: the run measures seed 002's inverse-
  /// kinematics error at the placed task's vertices (TrajectoryMetrics::ik_error) and ends out_of_reach
  /// when it is not 0. Not a parameter: it follows from the block's table.
  bool measured = false;

  static constexpr Domain rotation_rule = Domain::within(-1000.0, 1000.0);
  static constexpr Domain translation_rule = Domain::within(-1000.0, 1000.0);
  static constexpr Domain time_scale_rule = Domain::within(0.01, 100.0);

  /// True when the placement leaves the task as it is (0 rad, 0 m, time scale 1; -0 counts as 0).
  bool identity() const {
    return rotation == 0.0 && dx == 0.0 && dy == 0.0 && dz == 0.0 && time_scale == 1.0;
  }
  /// The same transform (measured aside).
  bool same_transform(const TaskPlacement& o) const {
    return rotation == o.rotation && dx == o.dx && dy == o.dy && dz == o.dz && time_scale == o.time_scale;
  }

  /// cos and sin of `rotation`, with the angle reduced by quarter turns first: beta = k pi/2 + r, r =
  /// beta - k (pi/2) with pi/2 the double nearest it, cos and sin of r then exchanged and negated by
  /// the quadrant k. A rotation by the double nearest a multiple of pi/2 is then exact (r = 0: the
  /// points' coordinates are swapped and negated, no rounding), so a task turned by a quarter turn
  /// equals, bit for bit, the same task written out there. Output: {cos, sin} [-].
  std::pair<double, double> cos_sin() const {
    constexpr double quarter = std::numbers::pi / 2.0;
    const double k = std::nearbyint(rotation / quarter);
    const double r = rotation - k * quarter;
    const double c = std::cos(r), s = std::sin(r);
    const long q = static_cast<long>(std::fmod(k, 4.0) + 4.0) % 4;
    switch (q) {
      case 1: return {-s, c};
      case 2: return {-c, -s};
      case 3: return {s, -c};
      default: return {c, s};
    }
  }
  /// A point of the task at its new place: Rz(beta) p + (dx, dy, dz). Input and output [m].
  Eigen::Vector3d place(const Eigen::Vector3d& p) const {
    const auto [c, s] = cos_sin();
    return {c * p.x() - s * p.y() + dx, s * p.x() + c * p.y() + dy, p.z() + dz};
  }
  /// A planar task's point (its plane's coordinates) at its new place: the rotation about the plane's
  /// normal, then dx, dy. Input and output [m].
  Eigen::Vector2d place(const Eigen::Vector2d& p) const {
    const auto [c, s] = cos_sin();
    return {c * p.x() - s * p.y() + dx, s * p.x() + c * p.y() + dy};
  }
};

}  // namespace ks
