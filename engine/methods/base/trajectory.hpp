#pragma once
// Redundancy resolution along a path (seed 000, chapter 3): one run = one simulation of the arm
// following the path from rest, with joint accelerations chosen by a method, integrated open loop.
#include <Eigen/Core>
#include <array>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "common/domain.hpp"
#include "model/arm.hpp"
#include "model/chain.hpp"
#include "model/kinematics.hpp"
#include "methods/base/path_global_options.hpp"
#include "task/task_path.hpp"
#include "task/sampled_path.hpp"

namespace ks {

/// The seed's cases. Names are the study-file, HDF5 and plot names.
enum class TrajectoryMethod {
  local_weighted,    ///< case 1, Eq. 51: inertia-weighted pseudo-inverse, minimises tau^T M^-1 tau
  local_unweighted,  ///< case 2, Eq. 56: M^-2-weighted pseudo-inverse, minimises tau^T tau
  vertex_alpha,      ///< cases 3-5: alpha prescribed at every vertex, quintic alpha(t), non-redundant
  /// path-global: alpha(t) over the whole path minimising an objective (methods/path_global/solve_closed_form.hpp),
  /// the joint path by exact IK at every sample (the seed's closed-form 3R arm)
  global_spline,
};

enum class Integrator {
  semi_implicit_euler,  ///< the seed's: qd += dt qdd; q += dt qd (new qd)
  rk4,                  ///< classic fourth-order Runge-Kutta on (q, qd)
};

/// Outcome of a run. Anything but ok stops the run early; the metrics then cover the samples done.
enum class RunStatus {
  ok,
  unreachable_start,  ///< no real analytic IK at the first vertex for alpha1A: nothing simulated
  singular,           ///< the Jacobian became singular (see TrajectoryOptions::singular_tolerance)
  diverged,           ///< a non-finite value, or a torque above TrajectoryOptions::torque_bound
  /// the sampling is too coarse for the motion: dt leaves fewer than kMinSamplesPerSegment samples on a
  /// segment (nothing simulated), or (global_spline) the trajectory between the samples departs from the
  /// sampled figures beyond verify_tolerance (the metrics kept, the dense figures beside them); a task
  /// time scale whose path would take more than 1e7 samples at dt ends so too (nothing simulated)
  undersampled,
  off_path,           ///< the tip left the path by more than tracking_bound (or orientation_bound)
  out_of_limits,      ///< a joint position, velocity or effort went beyond the robot's limits
  // global_spline: the optimiser's outcome (ok: converged, on the path, within the limits)
  max_evaluations,     ///< the optimiser used its evaluation budget; the metrics are at its best point
  not_converged,       ///< the optimiser stopped without meeting its tolerance (NLopt failure)
  infeasible,          ///< alpha(t) puts the wrist out of reach at a sample: the run ends there
  singular_extension,  ///< the extended task [tip; alpha] is singular at a sample: the run ends there
  /// a placed task (TaskPlacement::measured) has a vertex the robot cannot reach: seed 002's inverse-
  /// kinematics error (TrajectoryMetrics::ik_error) is not 0; nothing simulated, every other metric NaN
  out_of_reach,
  /// global_spline: the process was asked to stop (SIGINT, SIGTERM; set_optimiser_stop_flag in
  /// methods/path_global/slsqp.hpp) during the optimisation, which ended at once; metrics NaN. Never
  /// stored: the run is not written, and `run --resume` computes it.
  interrupted,
};

/// What a run does when a sample crosses its tracking bound or its robot's joint limits.
enum class OnViolation {
  mark,    ///< the run goes on to the end, every metric kept, and ends off_path / out_of_limits
  stop,    ///< the run ends at the first such sample, off_path / out_of_limits, metrics NaN
  ignore,  ///< the bounds only measure: the status is not changed
};


std::string_view to_string(TrajectoryMethod m);
std::string_view to_string(Integrator i);
std::string_view to_string(RunStatus s);
std::string_view to_string(OnViolation v);
/// The start posture's elbow branch by name: "elbow_down" (Elbow::positive, the seed's sin(theta2) >= 0: the
/// elbow on the clockwise side of the shoulder-to-wrist line, below it for the seed's square) and
/// "elbow_up" (Elbow::negative).
std::string_view to_string(Elbow e);
bool parse(std::string_view name, Elbow& out);
/// Parse a name; false when unknown.
bool parse(std::string_view name, TrajectoryMethod& out);
bool parse(std::string_view name, Integrator& out);
bool parse(std::string_view name, RunStatus& out);
bool parse(std::string_view name, OnViolation& out);

/// Options of one run. Defaults reproduce the seed.
struct TrajectoryOptions {
  TrajectoryMethod method = TrajectoryMethod::local_weighted;
  double k = 0.0;                     ///< gravity weight in the resolution (local methods), in [0, 1]
  double alpha1A = 0.0;               ///< orientation at the start (first vertex) [rad]
  std::vector<double> vertex_alpha;   ///< vertex_alpha: alpha at vertices 2..n [rad] (n - 1 values)
  double null_damping = 0.0;          ///< K_N [1/s]: adds -(I - J+ J) K_N qd to qdd (local methods)
  /// K_L [1/s^2]: adds -(I - J+ J) K_L (q - q_mid) to qdd (local methods), q_mid the middle of each
  /// joint's position limits (joints without both limits: no term); a null-space spring that keeps
  /// the joints away from their limits. 0: no term (bitwise the run without it).
  double limit_centring = 0.0;
  Integrator integrator = Integrator::semi_implicit_euler;
  double dt = 1e-3;                   ///< sample / integration step [s]
  Elbow elbow = Elbow::positive;      ///< branch of the start IK (the seed's sin(theta2) >= 0)
  double torque_bound = 1.0e6;        ///< |tau_i| above this [Nm] stops the run as diverged
  /// singular when sqrt(det(J J^T)) [m^2] (local methods) or |det J3| (vertex_alpha) falls below this,
  /// for arms reaching 1 m or more; below, relative to the arm's size (methods/base/singular_scale.hpp)
  double singular_tolerance = 1.0e-9;
  /// Closed-loop task feedback (CLIK): the commanded task acceleration is the path's plus
  /// K_D (xd_path - xd) + K_P (x_path - x), orientation rows included for pose tasks. 0 and 0 = the
  /// seeds' open loop (bitwise).
  double clik_kp = 0.0;               ///< K_P [1/s^2]
  double clik_kd = 0.0;               ///< K_D [1/s]
  double tracking_bound = 0.05;       ///< |tip - path| above this [m] is off the path
  double orientation_bound = 0.05;    ///< pose tasks: an orientation error above this [rad] is off the path
  OnViolation on_violation = OnViolation::mark;
  /// Local methods (seed arm): the arm's state at the path's end. free: the method's own motion to
  /// the end (the seed's; the arm may still move in its self-motion there). rest: a terminal feedback
  /// over the last end_window seconds: the method's null-space term (-(I - J+ J) (M^-1 (c + k g) +
  /// K_N qd)) blends into -(I - J+ J) K_S qd, K_S = end_gain, J+ the method's own weighted
  /// pseudo-inverse, with a weight s rising smoothly from 0 to 1 over the window (3 u^2 - 2 u^3), so
  /// the self-motion rate decays by about exp(-K_S end_window / 2); an open-loop run also feeds the
  /// tip's error back there (K_D = 2 K_S, K_P = K_S^2: critically damped; a closed-loop run keeps its
  /// own gains), so the tip holds the path, which ends at rest: the arm ends at rest up to the open
  /// loop's integration residual. The window's samples count in E like any other.
  EndState end = EndState::free;
  double end_window = 0.5;            ///< end = rest: the feedback's time before the path's end [s]
  double end_gain = 60.0;             ///< end = rest: K_S [1/s]
  PathGlobalOptions global;           ///< global_spline only

  /// The rules on the fields (checked by IsValid; the study schema reports them at the key).
  static constexpr Domain null_damping_rule = Domain::nonnegative();
  static constexpr Domain limit_centring_rule = Domain::nonnegative();
  static constexpr Domain dt_rule = Domain::positive();
  static constexpr Domain torque_bound_rule = Domain::positive();
  static constexpr Domain singular_tolerance_rule = Domain::nonnegative();
  static constexpr Domain clik_gain_rule = Domain::nonnegative();
  static constexpr Domain bound_rule = Domain::positive();
  static constexpr Domain end_window_rule = Domain::positive();
  static constexpr Domain end_gain_rule = Domain::positive();

  /// True when the run feeds the task error back (a gain is not 0).
  bool closed_loop() const { return clik_kp != 0.0 || clik_kd != 0.0; }

  /// True when every field is finite and within its rule; otherwise false, with `why` (when given)
  /// naming the field and the rule, e.g. "dt = -0.001; expected dt > 0".
  bool IsValid(std::string* why = nullptr) const;
};

/// Seed 002's epsilon of Eq. 2.24 (its Section 7.3 value): an IK residual below this counts as 0 [m].
inline constexpr double kIkErrorEpsilon = 1e-3;

/// Room in TrajectoryMetrics for the metrics of methods/metrics/sample_metrics.hpp's table.
inline constexpr int kMaxSampleMetrics = 8;

/// Figures of merit of one run (seed Eq. 60 and seed 002's measures).
struct TrajectoryMetrics {
  RunStatus status = RunStatus::ok;
  std::size_t samples = 0;            ///< samples computed (2001 for the seed's square at dt = 1 ms)
  double E = 0.0;                     ///< mean over samples of sqrt(tau^T tau) [Nm]
  double E_M = 0.0;                   ///< mean over samples of sqrt(tau^T M^-1 tau) [Nm / sqrt(kg m^2)]
  VecN tau_inf = VecN::Zero(3);       ///< max over samples of |tau_i| [Nm] (one per joint)
  double min_manipulability = 0.0;    ///< min over samples of sqrt(det(J J^T)) [m^2]
  double torque_sq_integral = 0.0;    ///< trapezoidal integral of sum tau_i^2 [N^2 m^2 s]
  double power_sq_integral = 0.0;     ///< trapezoidal integral of sum (tau_i qd_i)^2 [W^2 s]
  double max_tracking_error = 0.0;    ///< max over samples of |tip - path| [m] (open-loop drift)
  double mean_tracking_error = 0.0;   ///< mean over samples of |tip - path| [m]
  /// max over samples of the tip's orientation error [rad] (pose tasks and vertex_alpha; NaN otherwise)
  double max_orientation_error = std::numeric_limits<double>::quiet_NaN();
  /// max over samples and limited joints of |q - mid| / half range, |qd| / velocity limit and
  /// |tau| / effort limit (1 = at the limit); NaN when the robot has no such limit
  double max_q_limit_ratio = std::numeric_limits<double>::quiet_NaN();
  double max_qd_limit_ratio = std::numeric_limits<double>::quiet_NaN();
  double max_tau_limit_ratio = std::numeric_limits<double>::quiet_NaN();
  /// prismatic joints: mean over samples of sqrt(f^T f) of their forces [N] (E then covers the
  /// revolute joints' torques only); NaN for a chain without prismatic joints
  double E_force = std::numeric_limits<double>::quiet_NaN();
  double final_alpha = 0.0;           ///< alpha at the last sample [rad]
  double stop_time = 0.0;             ///< time of the last sample computed [s]
  /// Seed 002's inverse-kinematics error (Eqs. 2.24-2.25) of a placed task: over the task's vertices,
  /// the distance from each to the tip of the robot's position IK solution there, counted when it is
  /// kIkErrorEpsilon or more [m]; NaN when not measured (TaskPlacement::measured)
  double ik_error = std::numeric_limits<double>::quiet_NaN();
  /// global_spline (NaN for the other methods): the objective at the start and at the end (its
  /// units: see GlobalObjective), objective evaluations made, and the infinity norm of the objective's
  /// projected gradient at the end [objective units per rad]
  double opt_start_objective = std::numeric_limits<double>::quiet_NaN();
  double opt_objective = std::numeric_limits<double>::quiet_NaN();
  double opt_evaluations = std::numeric_limits<double>::quiet_NaN();
  double opt_gradient_norm = std::numeric_limits<double>::quiet_NaN();
  /// The joints the joints extension solved on the task, 1-based, as decimal digits (124: joints 1, 2
  /// and 4); NaN for the planar charts.
  double opt_solved_joints = std::numeric_limits<double>::quiet_NaN();
  /// Limit constraints (window x limited quantity) active at the optimum (ratio within 1e-4 of its
  /// bound); 0 when the robot has limits and none binds, NaN when it has none.
  double opt_active_limits = std::numeric_limits<double>::quiet_NaN();
  /// global_spline: the sample step [s] of the grid the optimiser last solved on (dt, or dt / 2^k
  /// after k refinements; see PathGlobalOptions::refinements)
  double opt_dt = std::numeric_limits<double>::quiet_NaN();
  /// global_spline: the run's trajectory evaluated between its samples (methods/path_global/verify.hpp)
  struct Dense {
    double E = std::numeric_limits<double>::quiet_NaN();                   ///< [Nm]
    double tau_inf = std::numeric_limits<double>::quiet_NaN();             ///< max over joints [Nm]
    double min_manipulability = std::numeric_limits<double>::quiet_NaN();  ///< [m^2]
    double max_tracking_error = std::numeric_limits<double>::quiet_NaN();  ///< [m]
    double max_limit_ratio = std::numeric_limits<double>::quiet_NaN();     ///< position, velocity, effort
    /// the largest relative departure of the dense figures from the sampled ones (inf: the dense
    /// evaluation stopped where the sampled one did not)
    double departure = std::numeric_limits<double>::quiet_NaN();
  } dense;
  /// the metrics of methods/metrics/sample_metrics.hpp's table, in its order (NaN: no sample, or not a metric)
  std::array<double, kMaxSampleMetrics> sampled = nan_array();

 private:
  static constexpr std::array<double, kMaxSampleMetrics> nan_array() {
    std::array<double, kMaxSampleMetrics> a{};
    a.fill(std::numeric_limits<double>::quiet_NaN());
    return a;
  }
};

/// The fewest samples per path segment (segment duration / dt) a run needs to follow its path: with
/// fewer, the quintic segments are sampled too coarsely to track them (and a dt above a segment's
/// duration skips it), and the metrics would describe another motion.
constexpr double kMinSamplesPerSegment = 10;
/// True when dt samples every segment of `durations` [s] at least kMinSamplesPerSegment times.
bool samples_path(const std::vector<double>& durations, double dt);
/// The metrics of a run that was not simulated: `status`, every figure NaN (`joints` torque bounds).
TrajectoryMetrics not_simulated(RunStatus status, int joints);

/// Per-sample history, written in place by simulate() (no copy per sample). One column per stored
/// sample; every `stride`-th sample is stored, and the last one computed always is.
struct TrajectoryHistory {
  int stride = 1;
  Eigen::VectorXd t;                             ///< [s]
  Eigen::Matrix<double, 3, Eigen::Dynamic> q;    ///< [rad]
  Eigen::Matrix<double, 3, Eigen::Dynamic> qd;   ///< [rad/s]
  Eigen::Matrix<double, 3, Eigen::Dynamic> qdd;  ///< [rad/s^2]
  Eigen::Matrix<double, 3, Eigen::Dynamic> tau;  ///< [Nm]
  Eigen::Matrix<double, 2, Eigen::Dynamic> x;    ///< end-effector position [m]
  Eigen::VectorXd alpha;                         ///< end-effector orientation [rad]
  Eigen::Index size = 0;                         ///< columns filled

  /// Size the buffers for a run of `samples` samples; does not shrink capacity between runs.
  void prepare(std::size_t samples);
};

/// Simulate one run. Inputs: arm constants, the path sampled at options.dt (see SampledPath: sample it
/// once and share it between the runs of a sweep), options. Output: metrics; the history is filled
/// when given. Never throws on bad numbers: trouble is a status. Throws std::invalid_argument when
/// options.IsValid() fails, path.dt() != options.dt or vertex_alpha has the wrong number of vertex
/// orientations.
TrajectoryMetrics simulate(const PlanarArm3& arm, const SampledPath& path, const TrajectoryOptions& options,
                           TrajectoryHistory* history = nullptr);
/// The same, sampling the path for this one run.
TrajectoryMetrics simulate(const PlanarArm3& arm, const Path2& path, const TrajectoryOptions& options,
                           TrajectoryHistory* history = nullptr);
/// simulate() of the local and vertex methods (every method but global_spline): the closed form's
/// per-sample loop (methods/closed_form/run.cpp). simulate() (methods/simulate.cpp) dispatches here
/// or to the path-global method's solve.
TrajectoryMetrics simulate_local(const PlanarArm3& arm, const SampledPath& path, const TrajectoryOptions& options,
                                 TrajectoryHistory* history = nullptr);

}  // namespace ks
