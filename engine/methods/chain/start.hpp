#pragma once
// The start of a chain's run: the tip placed on the path's first vertex by a small deterministic
// damped Newton iteration from an initial guess q0 (minimum-norm steps when the chain is redundant
// for the start's rows). Depends on nothing but its arguments: the same inputs give the same bits on
// every thread.
#include <optional>

#include "model/chain.hpp"

namespace ks {

/// What the start places: three rows. Planar chains: the tip's x, y and its angle about z
/// (PlanarAngle). Spatial: the tip's x, y, z.
struct StartTarget {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< [m] (planar: z ignored)
  bool planar = true;
  double angle = 0.0;  ///< planar only [rad]
};

/// Settings of the start solve. Plain values; the defaults are the engine's.
struct StartSolveOptions {
  double tolerance = 1e-13;  ///< converged when the residual's 2-norm [m, rad mixed] is at most this
  int max_iterations = 200;  ///< attempted steps, accepted or not
  /// when the solution lies outside the chain's position limits: revolute joints shifted by 2 pi
  /// into them, then null-space steps towards them (limit_steps at most), then the solve again
  bool respect_limits = true;
  int limit_steps = 200;
  /// when neither the solution nor the middle of the limits leads within them: guesses spread over
  /// the limits (this many), each solved as the middle is; another branch of the inverse kinematics
  /// (an elbow bent the other way) with the same tip pose may lie within the limits
  int restarts = 64;
};

/// Solve for q with the tip on `target`, starting from q0 (n = chain.dof() values [rad or m]).
/// Each step is dq = J^T (J J^T + lambda^2 I)^-1 e with e the residual and J the target rows of the tip
/// Jacobian: for a square J and lambda = 0, Newton's step; for more joints than rows, the
/// minimum-norm step. lambda^2 starts at 0; while a step does not reduce |e| it is set to 1e-6, then
/// grows tenfold; after each accepted step it shrinks tenfold (to 0 below 1e-12). Once |e| <= tolerance, up to two more
/// steps are taken while they reduce |e| (the last bits of a quadratic convergence).
/// Joint position limits (options.respect_limits): a solution within them is returned as found (so a
/// chain without limits, or a start already within them, is unaffected). Otherwise, for spatial
/// targets each revolute joint outside them is first moved by the multiple of 2 pi nearest to their
/// middle (the same pose); then null-space steps dq = J^+ e - (I - J^+ J) v pull every violating joint
/// towards 2 % inside its range (v = its violation of that inner range) while the tip stays on the
/// target (planar targets: these steps only, as their angle row counts turns); each candidate is put
/// back on the target by the iteration above and kept when within the limits; else the same from the
/// middle of the limits as the guess; else the same from each of options.restarts guesses spread over
/// the limits (a Halton sequence over each joint's range, [q0 - pi, q0 + pi] for a revolute joint
/// without both limits, deterministic); else the first solution (spatial: 2 pi-shifted, on the
/// target), whose run then reports its limit ratios. Every q returned is on the target to the tolerance.
/// Output: q, or std::nullopt when |e| > tolerance after max_iterations (out of reach, or a guess
/// that does not lead there).
///
/// For the seed arm (n = 3, planar) the solution is the analytic IK's branch nearest
/// q0 in Newton's sense; from planar_start_guess(3) it is the positive-elbow one for every start of
/// the seed's square (alpha1A from -30 to 30 deg).
std::optional<VecN> solve_start(const Chain& chain, const StartTarget& target, const VecN& q0,
                                const StartSolveOptions& options = {});

/// A default guess for planar chains: joint 1 at 0.5 rad, the others at 1.0 rad, alternating in sign
/// from joint 3 on (0.5, 1.0, -1.0, 1.0, ...). For the seed arm this leads to the positive elbow
/// (sin theta2 > 0) at the seed's first vertex. Output: n values [rad].
VecN planar_start_guess(int n);

}  // namespace ks
