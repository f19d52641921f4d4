#pragma once
// Typed runs: what one run of each kind is (its parameters as the typed options of the method that
// executes it) and what it returns (its metrics and an enum status). Names only appear at the edges:
// the parameter and metric tables (schema/params.hpp) convert to and from /runs cells.
#include <Eigen/Core>
#include <limits>
#include <numbers>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "common/angles.hpp"
#include "ik/solve.hpp"
#include "methods/base/trajectory.hpp"
#include "model/arm.hpp"
#include "model/chain.hpp"
#include "store/record.hpp"
#include "methods/base/task_placement.hpp"

namespace ks {

/// The kinds of run a study block holds.
enum class BlockKind { trajectory, ik, motion };
std::string_view to_string(BlockKind k);
bool parse(std::string_view name, BlockKind& out);
std::string_view to_string(InertiaForm f);
bool parse(std::string_view name, InertiaForm& out);

/// One redundancy-resolution run along the study's path.
struct TrajectoryRun {
  std::string preset;                            ///< seed 000 Table 4 row ("" when none)
  TrajectoryOptions options;                     ///< method, k, alpha1A, K_N, vertex_alpha, integrator, dt, ...
  InertiaForm inertia = InertiaForm::physical;   ///< closed form of M(q) (the seed's 3R only)
  /// Chains: the initial guess of the start configuration, placed on the first vertex by an IK
  /// solve [rad or m per joint]. Unused by the seed's closed-form 3R (its start is analytic).
  VecN q0 = VecN::Zero(3);
  /// The task's placement and time scale (identity by default: the study's task as written).
  TaskPlacement placement;
};

/// The IK problems of seed 001 (SCARA, lengths in mm) and the planar 3R arm (m, rad).
/// `position` and `pose` are the study robot's chain (any arm; the seed's 3R as a chain by default):
/// tip position (x, y, or x, y, z), or position and orientation (alpha, or roll-pitch-yaw).
enum class IkProblem { scara, planar3r_pose, planar3r_position, position, pose };
std::string_view to_string(IkProblem p);
bool parse(std::string_view name, IkProblem& out);
/// The SCARA's z residual; `unset` for the planar problems (stored as "").
enum class ZMode { unset, thesis, physical };
std::string_view to_string(ZMode z);
bool parse(std::string_view name, ZMode& out);

/// One numerical IK solve from an initial guess. Defaults: seed 001's SCARA problem; the planar 3R
/// problems start from planar_defaults().
struct IkRun {
  IkProblem problem = IkProblem::scara;
  ik::Options options;                    ///< method, lambda, tol, max_iter, ...
  /// initial guess: theta1, theta2 [rad], then d [mm] (scara) or theta3 [rad]; chains: one per joint
  VecN q0 = joint_vector({60.0 * kDeg, 45.0 * kDeg, 50.0});
  /// target x, y, z [mm] (scara) or x, y [m] (planar; z unused: NaN)
  Eigen::Vector3d target{50.0, -80.0, 10.0};
  double target_alpha = std::numeric_limits<double>::quiet_NaN();  ///< planar pose: orientation [rad]
  /// spatial pose: the tip orientation as roll, pitch, yaw about the base x, y, z axes (R = Rz Ry Rx) [rad]
  Eigen::Vector3d target_rpy = Eigen::Vector3d::Zero();
  ZMode z_mode = ZMode::thesis;
  /// Seed of the random restarts (ik::Options::restarts); the solve's generator is seeded with it
  /// mixed with the run's start and target (restart_seed_of in runner/execute.cpp).
  int restart_seed = 0;
  static constexpr Domain restart_seed_rule = Domain::within(0, 2147483647);

  /// The defaults of the planar 3R problems (the seed arm reaching (1.5, 1.5) m, alpha 0, from
  /// (0, 90, -90) deg).
  static IkRun planar_defaults();
  /// The defaults of the chain problems for a robot of `joints` joints: position of the tip at
  /// `target` (the path's first vertex) from q0 = 30 deg at every revolute joint, 0 m at every
  /// prismatic one.
  /// `limited`: the robot has position limits; chain problems then enforce them by default
  /// (joint_limits = clamp), else joint_limits = none.
  static IkRun chain_defaults(const std::vector<bool>& prismatic, int joints, const Eigen::Vector3d& target,
                              bool limited = false);
  bool scara() const { return problem == IkProblem::scara; }
  bool chain() const { return problem == IkProblem::position || problem == IkProblem::pose; }
};

/// One point-to-point motion of a chain robot (seed 002 Chapter 7): rest to rest from `start` to
/// `goal` in `duration`, each joint a clamped cubic spline through `controls` values
/// (motion/motion_problem.hpp), the weighted criteria minimised by motion::solve_motion, or only
/// evaluated on the initial rest-to-rest cubic when !solve.
struct MotionRun {
  VecN start = VecN::Zero(3);           ///< start configuration [rad or m per joint]
  VecN goal = VecN::Zero(3);            ///< goal configuration [rad or m per joint]
  double duration = 1.0;                ///< T [s]; the start value when vary_duration
  bool vary_duration = false;           ///< T is a variable within [min_duration, max_duration]
  double min_duration = 0.1, max_duration = 100.0;  ///< [s]
  int controls = 3;                     ///< K control values per joint (0: the cubic alone)
  int samples = 201;                    ///< at least this many samples (motion_problem.hpp's rule)
  /// Objective weights of f5 (torque_sq), f6 (power_sq), T, peak torque, jerk, manipulability, clearance.
  double w_torque = 1.0, w_power = 0.0, w_time = 0.0, w_peak = 0.0, w_jerk = 0.0, w_manipulability = 0.0,
         w_clearance = 0.0;
  bool normalise = true;                ///< each term divided by the initial cubic's value (seed 002 Eq. 7.1)
  bool solve = true;                    ///< false: evaluate the initial cubic only
  int starts = 1;                       ///< SLSQP starts (the cubic, then seeded perturbations)
  int max_evaluations = 500;            ///< SLSQP evaluations per start
  double clearance_margin = 1e-3;       ///< clearance >= this at every window [m] (with obstacles)
  double limit_margin = 0.0;            ///< each limited ratio (|q - mid| / half range, |qd| / v, |tau| / effort) <= 1 - this
  int check_factor = 8;                 ///< the end is re-evaluated at check_factor times as dense samples
  static constexpr Domain controls_rule = Domain::within(0, 30);
  static constexpr Domain samples_rule = Domain::within(2, 100000);
  static constexpr Domain starts_rule = Domain::within(1, 1000);
  static constexpr Domain evaluations_rule = Domain::within(1, 100000000);
  static constexpr Domain check_factor_rule = Domain::within(2, 256);

  /// The defaults for a robot of `joints` joints: from 0 to 30 deg at every revolute joint (0 m at
  /// a prismatic one) in 1 s.
  static MotionRun defaults(const std::vector<bool>& prismatic, int joints);
};

using RunSpec = std::variant<TrajectoryRun, IkRun, MotionRun>;

/// How a motion run ended: ok (converged, within every limit and clear of the obstacles at the
/// samples and at the check_factor times denser check samples between them), infeasible (a limit or
/// the clearance margin violated at the samples, or a limit exceeded between them), collision (least
/// clearance < 0 at the samples or between them),
/// max_evaluations (the budget ran out on a feasible point), failure (NLopt failed, the problem could
/// not be set up, or a criterion is not finite).
enum class MotionStatus { ok, infeasible, collision, max_evaluations, failure };
std::string_view to_string(MotionStatus s);

/// What a motion run returns to the store (NaN where not measured).
struct MotionResult {
  MotionStatus status = MotionStatus::failure;
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double duration = kNaN, torque_sq = kNaN, power_sq = kNaN, peak_torque = kNaN, jerk_sq = kNaN,
         min_manipulability = kNaN, min_clearance = kNaN;  ///< at the end (see motion::Criterion)
  double torque_sq_0 = kNaN, power_sq_0 = kNaN;            ///< the initial cubic's f5, f6
  double objective = kNaN, max_constraint = kNaN;
  int evaluations = 0;
  /// The end re-evaluated at the dense check samples: their count, the least clearance (NaN: no
  /// obstacles), the largest limit constraint (<= 0: every limit kept between the samples too) and the
  /// relative change of f5 and f6 from the samples' trapezoidal rule to the dense one's.
  int check_samples = 0;
  double check_min_clearance = kNaN, check_max_limit = kNaN, check_torque_sq_change = kNaN,
         check_power_sq_change = kNaN;
};

/// What an IK solve returns to the store (the Summary less its history).
struct IkResult {
  ik::Status status = ik::Status::max_iter;
  int iterations = 0, rejected = 0, solution = -1;
  double error = 0.0, min_rcond = 1.0;
  VecN q = VecN::Zero(3);  ///< final iterate (one per joint)
  int restarts_used = 0;   ///< random restarts made
};

/// The outcome of one run: its metrics with an enum status, and its history (empty when off).
struct RunOutcome {
  std::variant<TrajectoryMetrics, IkResult, MotionResult> result;
  RunHistory history;

  /// ok (trajectory, motion) or converged (ik)
  bool good() const;
  /// The status name stored in /runs.
  std::string_view status() const;
};

}  // namespace ks
