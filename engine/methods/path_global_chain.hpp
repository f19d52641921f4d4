#pragma once
// The path-global method on a planar chain of n >= 3 revolute joints on a position path: r = n - 2
// redundant coordinates, the first n - 3 joint angles and one coordinate of the last three joints'
// self-motion (the tip angle alpha, or the angle psi along their self-motion circle as for the seed's
// arm, methods/path_global.hpp). Any planar revolute chain maps onto a canonical one: joint i+1 sits at
// distance L from joint i, in the direction of joint i's frame turned by a fixed delta; so the last
// three joints are a 3R arm of lengths L1, L2, L3 whose base moves with the first joints, and given
// the coordinates, the joint path is that 3R's closed-form inverse kinematics for the path point seen
// from its base (exact: tracking error at rounding), its rates and accelerations by differentiating
// the construction, and tau by the chain's inverse dynamics (model/chain_dynamics.hpp).
#include <cstddef>
#include <vector>

#include "methods/alpha_basis.hpp"
#include "methods/chain_trajectory.hpp"
#include "methods/path_global_options.hpp"
#include "model/chain_dynamics.hpp"

namespace ks {

/// One sample of a chain's joint path.
struct ChainGlobalSample {
  double violation = 0;  ///< how far the coordinates leave the chart or the reach (0: they do not)
  double det = 0;        ///< L1 L2 sin(theta2 - theta1) of the last three joints' wrist solve [m^2]
  VecN q, qd, qdd, tau;  ///< [rad], [rad/s], [rad/s^2], [Nm] (q wrapped to (-pi, pi])
  double alpha = 0;      ///< the tip angle [rad]
};

class ChainGlobalProblem {
 public:
  /// chain: planar, revolute joints only, n >= 3, positive L1, L2, L3 (std::invalid_argument
  /// otherwise); task: planar_position, sampled at the run's dt; elbow: the last three joints' branch
  /// (sign of sin(theta2 - theta1)) for Extension::alpha.
  ChainGlobalProblem(const Chain& chain, const ChainTask& task, Extension extension, Elbow elbow);

  int joints() const { return n_; }
  int coordinates() const { return n_ - 2; }
  std::size_t samples() const { return task_.path.size(); }

  /// Sample i for coordinate values z (coordinates() x 3: value, rate, acceleration each).
  void sample(std::size_t i, const double (*z)[3], ChainGlobalSample& s) const;
  /// The coordinates (value only) of configuration q at sample i; the last three joints' branch in elbow.
  void coordinates_of(std::size_t i, const VecN& q, double* z, Elbow& elbow) const;

  /// The objective at coefficients c (coordinate k's in c[k K .. (k + 1) K), K = basis.coefficients),
  /// plus 1e6 times each sample's squared violation; its gradient into grad when not null.
  double objective(const AlphaBasis& basis, const double* c, GlobalObjective objective, double* grad) const;

  /// The largest violation over the samples at coefficients c (0: every sample on the chart and in reach).
  double worst_violation(const AlphaBasis& basis, const double* c) const;

  /// The run's metrics at c (the trajectory kind's, through the per-sample accumulator, with the
  /// chain's limits), its history when given; q continued across (-pi, pi] from q_start. A sample
  /// off the chart or out of reach ends the run there, infeasible; a singular wrist solve (|det| <
  /// o.singular_tolerance, Extension::alpha), singular_extension.
  TrajectoryMetrics measure(const AlphaBasis& basis, const double* c, const VecN& q_start, const TrajectoryOptions& o,
                            ChainHistory* history) const;

 private:
  double cost(std::size_t i, const double (*z)[3], GlobalObjective objective) const;

  const Chain& chain_;
  const ChainTask& task_;
  Extension extension_;
  Elbow elbow_;
  int n_, a_;                        // joints; the first of the last three
  double ox_[kMaxJoints], oy_[kMaxJoints], beta_[kMaxJoints], sigma_[kMaxJoints];
  double L1_, L2_, L3_, d1_, d2_, d3_, tip_angle_;
  std::vector<Eigen::Vector2d> velocity_;  // the path's velocity at each sample [m/s]
  mutable ChainData data_;
  mutable ChainState state_;
};

/// Run one global_spline run on a planar revolute chain (the same contract as solve_global_spline;
/// q0: the start's initial guess as for simulate(chain, ...); the start is options.global.start's:
/// local or random, vertex is not defined for chains).
TrajectoryMetrics solve_global_spline_chain(const Chain& chain, const ChainTask& task, const VecN& q0,
                                            const TrajectoryOptions& options, ChainHistory* history = nullptr,
                                            std::vector<double>* coefficients = nullptr);

}  // namespace ks
