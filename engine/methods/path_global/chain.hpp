#pragma once
// The path-global method on a chain robot (model/chain.hpp) on a position path: r redundant
// coordinates, each a spline over time (methods/path_global/alpha_basis.hpp), complete the task to a square system
// (an extended task); at every sample the joint path is the exact inverse kinematics of (path point,
// coordinates), its rates and accelerations solve the differentiated system, and tau is the chain's
// inverse dynamics (model/chain_dynamics.hpp). Two extensions:
// - the planar chart of planar revolute chains (methods/path_global/planar_chart.hpp): the first n - 3 joint
//   angles and the last three joints' self-motion angle or tip angle, in closed form;
// - joint coordinates for any chain (methods/path_global/joint_chart.hpp): r of its joint angles, the
//   other m solved by Newton's method on the tip position.
// This header holds what they share: the objective with its chain-rule gradient, the robot's joint
// limits as constraints of the optimiser, the run's metrics, and the run itself.
#include <array>
#include <cstddef>
#include <vector>

#include "methods/path_global/alpha_basis.hpp"
#include "methods/chain/trajectory.hpp"
#include "methods/base/path_global_options.hpp"
#include "methods/metrics/sample_sums.hpp"
#include "model/chain_dynamics.hpp"

namespace ks {

/// One sample of a chain's joint path.
struct ChainGlobalSample {
  double violation = 0;  ///< how far the coordinates leave the chart or the reach (0: they do not)
  double det = 0;        ///< determinant of the extension's solve (units of the extension; see singular())
  VecN q, qd, qdd, tau;  ///< [rad], [rad/s], [rad/s^2], [Nm]
  double alpha = 0;      ///< the tip angle [rad] (planar tasks; NaN for spatial ones)
};

/// One sample's exact partials with respect to its 3r inputs (r coordinates), input 3k + d for
/// coordinate k's value (d = 0), rate (1) and acceleration (2).
struct ChainSamplePartials {
  int inputs = 0;                          ///< 3r
  double cost[3 * kMaxJoints];             ///< of the sample's term of the objective
  double q[kMaxJoints][3 * kMaxJoints];    ///< of each joint's position
  double qd[kMaxJoints][3 * kMaxJoints];   ///< of each joint's rate
  double tau[kMaxJoints][3 * kMaxJoints];  ///< of each joint's torque or force
};

/// The robot's joint limits as inequality constraints of the optimiser. The samples are cut into
/// windows (as many as the spline has knots, in order); for each window and each limited quantity —
/// a joint's position (|q - middle| over half its range), velocity (|qd| over its limit) or effort
/// (|tau| over its limit) — the largest ratio over the window's samples minus (1 - margin) is <= 0.
/// The largest of a window is a max of smooth functions: its gradient is its sample's.
struct LimitConstraints {
  LimitTable table;
  std::vector<std::size_t> window_end;  ///< one past the last sample of each window
  std::vector<std::array<int, 2>> rows;  ///< the limited quantities: {0 position, 1 velocity, 2 effort; joint}
  /// each ratio is kept <= 1 - margin at the samples: room for the peaks between them (the dense check)
  double margin = 1e-3;
  /// > 0: no constraints; the objective gains penalty / samples times the sum over every sample and
  /// quantity of its excess over 1 - margin, squared (smooth: each sample's own ratio)
  double penalty = 0.0;

  unsigned count() const { return static_cast<unsigned>(window_end.size() * rows.size()); }
  /// The limits of `chain` over `samples` samples cut into `windows` windows (none: count() = 0).
  static LimitConstraints of(const Chain& chain, std::size_t samples, int windows);
};

/// A path-global problem on a chain: the coordinates -> joint path map of an extension, and the
/// objective, constraints and metrics computed from it.
class ChainGlobalProblem {
 public:
  virtual ~ChainGlobalProblem() = default;

  int joints() const { return n_; }
  virtual int coordinates() const = 0;
  std::size_t samples() const { return task_.path.size(); }

  /// Sample i for coordinate values z (coordinates() x 3: value, rate, acceleration each).
  virtual void sample(std::size_t i, const double (*z)[3], ChainGlobalSample& s) const = 0;
  /// The coordinates (value only) of configuration q at sample i; the planar chart's elbow branch in elbow.
  virtual void coordinates_of(std::size_t i, const VecN& q, double* z, Elbow& elbow) const = 0;
  /// Whether the extension is singular at s (|det| below tolerance, where the extension has one).
  virtual bool singular(const ChainGlobalSample& s, double tolerance) const = 0;
  /// Whether sample() returns joint angles wrapped to (-pi, pi] (else continuous along the path).
  virtual bool wraps_angles() const = 0;
  /// A pass over the samples in order begins (extensions solved by continuation restart from their start).
  virtual void begin_pass() const {}
  /// The exact partials of sample s = sample(i, z) (the last sample computed; state_ holds its
  /// dynamics) into out: of its term of the objective (weight: the term's factor, term_weight()) and
  /// of its positions, rates and torques. False when the extension has none: the objective then takes
  /// central differences of sample().
  virtual bool partials(std::size_t /*i*/, const double (*/*z*/)[3], const ChainGlobalSample& /*s*/,
                        GlobalObjective /*objective*/, double /*weight*/, ChainSamplePartials& /*out*/) const {
    return false;
  }
  /// Sample i at z was the pass's (continuation starts sample i + 1, and perturbations of i, from it).
  virtual void accept(std::size_t /*i*/, const double (*/*z*/)[3], const ChainGlobalSample& /*s*/) const {}

  /// The objective at coefficients c (coordinate k's in c[k K .. (k + 1) K), K = basis.coefficients),
  /// plus a floor and 1e6 times its squared violation for each sample off the chart; its gradient
  /// into grad when not null. With limits: the constraint values into con (limits->count()) and
  /// their gradients into jac (row-major, count x K r) when not null.
  double objective(const AlphaBasis& basis, const double* c, GlobalObjective objective, double* grad,
                   const LimitConstraints* limits = nullptr, double* con = nullptr, double* jac = nullptr) const;

  /// The largest violation over the samples at coefficients c (0: every sample on the chart and in reach).
  double worst_violation(const AlphaBasis& basis, const double* c) const;

  /// The run's metrics at c (the trajectory kind's, through the per-sample accumulator, with the
  /// chain's limits), its history when given; q continued across (-pi, pi] from q_start. A sample
  /// off the chart or out of reach ends the run there, infeasible; a singular extension
  /// (singular(s, o.singular_tolerance)), singular_extension.
  TrajectoryMetrics measure(const AlphaBasis& basis, const double* c, const VecN& q_start, const TrajectoryOptions& o,
                            ChainHistory* history) const;

 protected:
  /// task: a position path (planar_position or spatial_position), sampled at the run's dt.
  ChainGlobalProblem(const Chain& chain, const ChainTask& task);
  /// A sample off the chart or out of reach costs a floor plus this times its squared violation.
  static constexpr double kViolationPenalty = 1e6;
  /// The factor of sample i's term of the objective: 1 / samples (means) or the trapezoid's step (integrals).
  double term_weight(std::size_t i, GlobalObjective objective) const;
  /// Sample i's term of the objective (state_ holds s's dynamics).
  double cost(std::size_t i, const ChainGlobalSample& s, GlobalObjective objective) const;
  /// The ratio of limited quantity `row` ({quantity, joint}) at s to its limit.
  double ratio(const LimitConstraints& limits, const std::array<int, 2>& row, const ChainGlobalSample& s) const;
  /// Its partial with respect to input `input` of the sample, from the sample's partials d.
  double ratio_partial(const LimitConstraints& limits, const std::array<int, 2>& row, const ChainGlobalSample& s,
                       const ChainSamplePartials& d, int input) const;

  const Chain& chain_;
  const ChainTask& task_;
  int n_;
  int rows_;  // the task's position rows: 2 (planar) or 3 (spatial)
  class MeasureModel;  // measure()
  mutable ChainData data_;
  mutable ChainState state_;
};

/// Run one global_spline run on a chain on a position path (the same contract as solve_global_spline;
/// q0: the start's initial guess as for simulate(chain, ...); the start is options.global.start's:
/// local or random, vertex is not defined for chains). Planar revolute chains take the planar chart
/// (extension self_motion or alpha) or joint coordinates (joints); other chains joint coordinates,
/// the solved joints chosen along the start run (JointExtensionProblem::choose_solved).
TrajectoryMetrics solve_global_spline_chain(const Chain& chain, const ChainTask& task, const VecN& q0,
                                            const TrajectoryOptions& options, ChainHistory* history = nullptr,
                                            std::vector<double>* coefficients = nullptr);

}  // namespace ks
