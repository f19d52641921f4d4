#pragma once
// Redundancy resolution along a path for any serial chain (model/chain.hpp): the seed's run
// (methods/base/trajectory.hpp) with the tip of an n-joint chain following a path in a task space of
// dimension m (planar position or pose, spatial position or pose). Same options, metrics and
// statuses as the closed-form planar 3R; the per-joint quantities have n entries.
#include <Eigen/Core>

#include "methods/chain/start.hpp"
#include "methods/chain/task.hpp"

namespace ks {

/// Simulate one run of `chain` following `task` (seed Appendix F's loop, generalised).
/// Inputs:
/// - chain: a valid chain (Chain::IsValid; not checked here); planar tasks need chain.planar().
/// - task: the path sampled at options.dt, and the task space (dimension m).
/// - q0: the start solve's initial guess, chain.dof() values [rad or m] (see solve_start; for planar
///   chains planar_start_guess(n) gives the seed's positive elbow on the seed arm).
/// - options: method, k, null_damping, integrator, dt, torque_bound, singular_tolerance as for the
///   closed form; alpha1A [rad] is the start's tip angle for planar tasks (planar_position too: the
///   seed's alpha1A); vertex_alpha holds the tip angle at the later vertices for planar_pose. `elbow`
///   is not read: the start's branch is the one q0 leads to.
/// Methods: local_weighted and local_unweighted need n > m; vertex_alpha needs planar_pose and n = 3
/// (then J qdd = b is square). The start: planar tasks solve (x, y, alpha1A) at the first vertex
/// (minimum-norm steps for n > 3); spatial tasks solve (x, y, z), spatial_pose then holding the
/// orientation the start reaches. A failed start solve gives RunStatus::unreachable_start with NaN
/// metrics. Singular: sqrt(det(J J^T)) of the task rows below singular_tolerance (for vertex_alpha:
/// |det J|). Diverged: a non-finite torque or one above torque_bound.
/// Output: the metrics. tau_inf has n entries; min_manipulability is sqrt(det(Jp Jp^T)) of the task's
/// position rows Jp (x, y planar; x, y, z spatial) [m^2 or m^3 for revolute joints], so that it is
/// the closed form's figure for every seed method and has one unit whatever the orientation rows;
/// max_tracking_error is the tip position's; final_alpha is the tip angle (NaN for spatial tasks).
/// The history is filled when given. Never throws on bad numbers: trouble is a status.
/// Throws std::invalid_argument when options.IsValid() fails, task.path.dt() != options.dt, q0 has
/// the wrong size, the task and method do not fit the chain (see above), or planar_pose has the wrong number of vertex_alpha.
TrajectoryMetrics simulate(const Chain& chain, const ChainTask& task, const VecN& q0, const TrajectoryOptions& options,
                           ChainHistory* history = nullptr);
/// simulate() of the local and vertex methods on a chain (methods/chain/trajectory.cpp, the planar
/// fixed-size run among them); simulate() (methods/simulate.cpp) dispatches here or to the
/// path-global method's solve.
TrajectoryMetrics simulate_local(const Chain& chain, const ChainTask& task, const VecN& q0,
                                 const TrajectoryOptions& options, ChainHistory* history = nullptr);

}  // namespace ks
