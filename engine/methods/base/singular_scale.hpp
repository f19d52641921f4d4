#pragma once
// The singularity test of a run relative to its arm's size. TrajectoryOptions::singular_tolerance is
// the tolerance of arms reaching 1 m or more; a smaller arm's is scaled by (reach / 1 m)^p, as the
// measure it bounds scales with the arm's lengths: sqrt(det(J J^T)) of p position rows and |det J3|
// of the seed's arm (p = 2) are [m^p]. An arm scaled down to micrometres then ends as the metre-size
// arm does instead of `singular` at once, and every arm reaching 1 m or more keeps the tolerance as
// given (bitwise the same runs).
#include <cmath>

#include "model/arm.hpp"
#include "model/chain.hpp"

namespace ks {

/// The factor on singular_tolerance of an arm reaching `reach` [m] with `position_rows` (2 planar,
/// 3 spatial) task position rows: 1 from 1 m on, (reach / 1 m)^position_rows below; 1 when the reach
/// is not a positive number.
inline double singular_scale(double reach, int position_rows) {
  if (!(reach > 0.0) || reach >= 1.0) return 1.0;
  return std::pow(reach, position_rows);
}

/// The reach of the seed's arm: l1 + l2 + l3 [m].
inline double arm_reach(const PlanarArm3& arm) { return arm.l[0] + arm.l[1] + arm.l[2]; }

/// A bound on a chain's reach: the lengths of the offsets from the first joint to the tip, each
/// joint's origin after the first and the tip frame's, summed [m] (prismatic travels not counted).
inline double chain_reach(const Chain& chain) {
  double r = chain.tip.p.norm();
  for (std::size_t j = 1; j < chain.joints.size(); ++j) r += chain.joints[j].origin.p.norm();
  return r;
}

}  // namespace ks
