#pragma once
// The run of simulate() (methods/chain/trajectory.hpp) for a planar chain of revolute joints, on
// types of compile-time size: the joint count N is chosen once per run (planar_chain_run's switch),
// the task space and the method once per run inside. The loop body is element-wise arithmetic on
// fixed-size arrays (model/planar_chain_dynamics.hpp, methods/base/fixed_ldlt.hpp): no allocation, no
// branch on the robot, the task or the method per step. Instantiated for N = 3 .. kMaxJoints, the
// joint counts a planar task can use (planar_position needs N > 2).
#include <optional>

#include "methods/chain/start.hpp"
#include "methods/chain/task.hpp"
#include "task/task_path.hpp"

namespace ks {

/// One run from the start q_start at rest (the start already solved).
/// Inputs: chain with planar_revolute(chain) and chain.dof() == N; task with a planar task space;
/// q_start (N) [rad]; options o as for simulate() (method and task already checked to fit the chain);
/// alpha, the tip angle's profile for planar_pose (empty otherwise); history, prepared, or null.
/// Output: the metrics (the history filled when given), as simulate() documents them.
template <int N>
TrajectoryMetrics planar_chain_run_n(const Chain& chain, const ChainTask& task, const VecN& q_start,
                                     const TrajectoryOptions& o, const std::optional<Profile1>& alpha,
                                     ChainHistory* history);

extern template TrajectoryMetrics planar_chain_run_n<3>(const Chain&, const ChainTask&, const VecN&,
                                                        const TrajectoryOptions&, const std::optional<Profile1>&,
                                                        ChainHistory*);
extern template TrajectoryMetrics planar_chain_run_n<4>(const Chain&, const ChainTask&, const VecN&,
                                                        const TrajectoryOptions&, const std::optional<Profile1>&,
                                                        ChainHistory*);
extern template TrajectoryMetrics planar_chain_run_n<5>(const Chain&, const ChainTask&, const VecN&,
                                                        const TrajectoryOptions&, const std::optional<Profile1>&,
                                                        ChainHistory*);
extern template TrajectoryMetrics planar_chain_run_n<6>(const Chain&, const ChainTask&, const VecN&,
                                                        const TrajectoryOptions&, const std::optional<Profile1>&,
                                                        ChainHistory*);
extern template TrajectoryMetrics planar_chain_run_n<7>(const Chain&, const ChainTask&, const VecN&,
                                                        const TrajectoryOptions&, const std::optional<Profile1>&,
                                                        ChainHistory*);
extern template TrajectoryMetrics planar_chain_run_n<8>(const Chain&, const ChainTask&, const VecN&,
                                                        const TrajectoryOptions&, const std::optional<Profile1>&,
                                                        ChainHistory*);

/// planar_chain_run_n<chain.dof()>; the same inputs and output. Throws std::invalid_argument for a
/// joint count outside 3 .. kMaxJoints.
TrajectoryMetrics planar_chain_run(const Chain& chain, const ChainTask& task, const VecN& q_start,
                                   const TrajectoryOptions& o, const std::optional<Profile1>& alpha,
                                   ChainHistory* history);

}  // namespace ks
