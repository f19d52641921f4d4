#pragma once
// What a chain's run follows and what it records: the task (a path sampled at the run's step, in a
// task space) and the per-sample history. Shared by the general loop (methods/chain/trajectory.cpp),
// the fixed-size planar run (methods/chain/planar_run.hpp) and the path-global method on chains.
#include <Eigen/Core>

#include "methods/base/trajectory.hpp"
#include "methods/chain/resolution.hpp"
#include "task/sampled_path.hpp"

namespace ks {

/// What the tip follows: a path through vertices, one quintic per segment (the seed's timing), sampled
/// at the run's step, in a task space. Planar tasks read x and y and ignore z. For planar_pose the tip
/// angle follows a quintic through alpha1A and TrajectoryOptions::vertex_alpha (one per vertex after
/// the first); for spatial_pose the orientation is held at the start's. Sample it once and share it
/// read-only between the runs (and threads) of a sweep.
struct ChainTask {
  TaskSpace space = TaskSpace::planar_position;
  SampledPath3 path;

  /// path: tip positions [m] over time [s]; dt > 0 [s] (std::invalid_argument otherwise).
  ChainTask(TaskSpace space_, Path3 path_, double dt) : space(space_), path(std::move(path_), dt) {}
  /// A planar path (z = 0).
  ChainTask(TaskSpace space_, const Path2& path_, double dt) : ChainTask(space_, lift_to_3d(path_), dt) {}
};

/// Per-sample history of a chain's run, written in place by simulate() (no allocation per sample once
/// prepared). One column per stored sample; every `stride`-th sample is stored, and the last computed
/// one always is.
struct ChainHistory {
  int stride = 1;
  Eigen::VectorXd t;     ///< [s]
  Eigen::MatrixXd q;     ///< n rows [rad or m]
  Eigen::MatrixXd qd;    ///< n rows [rad/s or m/s]
  Eigen::MatrixXd qdd;   ///< n rows [rad/s^2 or m/s^2]
  Eigen::MatrixXd tau;   ///< n rows [Nm or N]
  Eigen::MatrixXd x;     ///< tip position: 2 rows (planar tasks) or 3 (spatial) [m]
  Eigen::VectorXd alpha; ///< tip angle about z (planar tasks; NaN for spatial ones) [rad]
  Eigen::Index size = 0; ///< columns filled

  /// Size the buffers for `samples` samples of a chain of `joints` joints with `position_rows` (2 or 3)
  /// tip coordinates; keeps the capacity when the shape is unchanged.
  void prepare(std::size_t samples, int joints, int position_rows);
};

}  // namespace ks
