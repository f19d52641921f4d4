#pragma once
// A point-to-point motion of a chain as an optimisation problem: the joint splines of
// motion/joint_spline.hpp (their control values and, optionally, the duration T are the variables),
// evaluated at samples evenly spaced in time with the chain's inverse dynamics at each; the criteria
// of the motion, the objective (their weighted, optionally normalised sum) and the constraints (the
// joint limits and the clearance from obstacles), each with its gradient in the variables.
//
// Sampling: N samples at u_s = s / (N - 1) (t_s = u_s T), N the least count >= MotionSpec::samples
// with N - 1 a multiple of K + 1, so that every spline node is a sample.
// Integrals: the trapezoidal rule on those samples, ∫_0^T g dt = T Σ_s c_s g(u_s), c_s = 1 / (N - 1)
// (half at both ends); the jerk term exactly (the jerk is constant on each spline segment).
// Derivatives: the spline's are exact (its weights, the chain rule in T at fixed u: q̇ ∝ 1/T,
// q̈ ∝ 1/T², jerk ∝ 1/T³). Of the torques, per sample: ∂τ/∂q̈ = M(q) exactly (CRBA); ∂τ/∂q̇ by central
// differences of the RNEA, exact to rounding since τ is quadratic in q̇ (a central difference of a
// quadratic has no truncation error); ∂τ/∂q by central differences of the RNEA with step
// 6e-6 max(1, |q_j|) (truncation and rounding errors near 1e-10 relative). Manipulability: central
// differences in q at its minimising sample; clearance: geometry::min_clearance's exact gradient,
// and for moving obstacles its share in T: u_s (d clearance / d translation) . v_j at fixed u.
#include <array>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "geometry/link_capsules.hpp"
#include "model/chain.hpp"
#include "model/chain_dynamics.hpp"
#include "motion/joint_spline.hpp"

namespace ks::motion {

/// The criteria of a motion (indices into Criteria).
enum class Criterion {
  duration,            ///< T [s]
  torque_sq,           ///< f5 = ∫ Σ τ_i² dt [N²m²s] (accumulated torque, seed 002 Eq. 2.38)
  power_sq,            ///< f6 = ∫ Σ (τ_i q̇_i)² dt [W²s] (mechanical power squared, Eq. 2.39)
  peak_torque,         ///< max over samples and joints of |τ_i| [Nm or N]
  jerk_sq,             ///< ∫ Σ jerk_i² dt [rad²/s⁵]
  min_manipulability,  ///< min over samples of sqrt(det(J_p J_pᵀ)), J_p the tip Jacobian's position rows [m^rows]
  min_clearance,       ///< min over samples of the links' clearance from the obstacles [m] (+inf: none)
};
inline constexpr int kCriteria = 7;
using Criteria = std::array<double, kCriteria>;
std::string_view to_string(Criterion c);
/// +1 for the criteria the objective lowers, -1 for those it raises (manipulability, clearance).
double sense(Criterion c);
inline double& at(Criteria& c, Criterion k) { return c[static_cast<int>(k)]; }
inline double at(const Criteria& c, Criterion k) { return c[static_cast<int>(k)]; }

/// Everything that defines a motion problem.
struct MotionSpec {
  Chain chain;                 ///< the robot (its joint limits are the constraints' limits)
  VecN q_start, q_goal;        ///< rest to rest [rad or m] (dim chain.dof())
  int controls = 1;            ///< K control values per joint, 0 .. kMaxControls
  double duration = 1.0;       ///< T [s]; the start value when vary_duration
  bool vary_controls = true;   ///< the n K control values are variables (else fixed_controls)
  bool vary_duration = false;  ///< T is a variable (the last one), within [min_duration, max_duration]
  double min_duration = 1e-3, max_duration = 1e4;  ///< [s]
  std::vector<double> fixed_controls;  ///< the controls when !vary_controls (n K, joint-major; empty: the cubic's)
  int samples = 201;           ///< at least this many samples (>= 2); see the header for the rule

  Criteria weights{};          ///< the objective's weight of each criterion (>= 0)
  bool normalise = false;      ///< divide each term by its reference value (reference(): the initial cubic's)
  /// Evaluate the initial point as the reference (reference()); false leaves the reference NaN (a
  /// problem only evaluated at given points, such as a dense check; normalise needs it).
  bool evaluate_reference = true;

  bool position_limits = true, velocity_limits = true, effort_limits = true;  ///< the chain's finite limits as constraints
  double limit_margin = 0.0;   ///< a limited ratio must stay <= 1 - limit_margin
  int windows = 0;             ///< constraint windows (0: one per spline segment, K + 1; at most the samples)

  std::vector<geometry::Obstacle> obstacles;  ///< in the base frame at t = 0 (none: no clearance constraint)
  /// One velocity per obstacle [m/s] (empty: all fixed): obstacle j at time t is obstacles[j]
  /// translated by t obstacle_velocities[j], so the clearance at a sample depends on T too.
  std::vector<geometry::Vec3> obstacle_velocities;
  std::vector<double> radii;   ///< one per link [m] (needed with obstacles)
  double clearance_margin = 0.0;  ///< clearance >= this [m], per window

  /// False (with the reason in *why) when the chain is invalid, sizes disagree, K or the samples are
  /// out of range, a duration bound is not 0 < min <= duration <= max, a weight is negative or not
  /// finite, no variable is free, the clearance weight is set without obstacles, radii are missing or
  /// negative, obstacle_velocities is neither empty nor one finite velocity per obstacle, or a
  /// margin is out of range (limit_margin in [0, 1), clearance_margin finite).
  bool IsValid(std::string* why = nullptr) const;
};

/// What one evaluation returns. Gradients have one entry per variable; the constraint Jacobian is
/// row-major (constraints x variables). Sized by MotionProblem::evaluate (no allocation once sized).
struct MotionEvaluation {
  Criteria criteria{};
  double objective = 0.0;
  std::vector<double> constraints;                 ///< each <= 0 when satisfied
  std::vector<double> objective_gradient;          ///< (only when gradients were asked for)
  std::array<std::vector<double>, kCriteria> criterion_gradients;  ///< d criterion / dx (0 for +inf criteria)
  std::vector<double> constraint_jacobian;
};

/// One constraint: a limited quantity of a joint, or the clearance, over one window of samples.
struct MotionConstraint {
  enum class Kind { position, velocity, effort, clearance } kind;
  int joint = -1;   ///< -1 for the clearance
  int window = 0;
};

/// The samples of a motion of `controls` control values per joint asked for at least `samples`: the
/// least N >= samples with N - 1 a multiple of controls + 1 (every spline node a sample).
int motion_sample_count(int samples, int controls);

/// The motion problem. The variables x: the control values (n K, joint-major) when vary_controls,
/// then T when vary_duration. evaluate() uses the problem's own workspace: one thread at a time.
class MotionProblem {
 public:
  /// Samples the motion and evaluates the initial point (reference(), when spec.evaluate_reference). Throws std::invalid_argument
  /// when !spec.IsValid(), or when spec.normalise meets a weighted criterion whose reference value is
  /// 0 or not finite (e.g. the manipulability of a motion that starts at a singularity).
  explicit MotionProblem(MotionSpec spec);

  const MotionSpec& spec() const { return spec_; }
  int joints() const { return n_; }
  int variables() const { return variables_; }
  int samples() const { return static_cast<int>(u_.size()); }
  int windows() const { return windows_; }
  const std::vector<MotionConstraint>& constraint_list() const { return constraints_; }
  int constraints() const { return static_cast<int>(constraints_.size()); }

  /// The initial point: the rest-to-rest cubic's controls (or the fixed ones) and spec.duration.
  std::vector<double> initial_point() const;
  /// The criteria of the initial point (the normalisation's reference values).
  const Criteria& reference() const { return reference_; }
  /// Bounds of the variables: each control within the joint's limits and within `pad` [rad or m] of
  /// the interval between its start and goal; T within [min_duration, max_duration].
  void bounds(double pad, std::vector<double>& lower, std::vector<double>& upper) const;

  /// Evaluate at x (variables()): criteria, objective, constraints and, when `gradients`, all their
  /// gradients. Throws std::invalid_argument when x has the wrong size.
  void evaluate(std::span<const double> x, bool gradients, MotionEvaluation& out) const;
  /// The splines at x (for reading the motion: positions, velocities at any t).
  JointSpline spline_at(std::span<const double> x) const;
  /// The joint torques at every sample of the last evaluate() (samples() x n, sample-major) [Nm or N].
  const std::vector<VecN>& last_torques() const { return tau_; }
  /// The sample times of x's duration: u_s T [s].
  double sample_time(int s, double T) const { return u_[static_cast<std::size_t>(s)] * T; }

 private:
  // Adds scale times the gradient in x of a scalar of sample s to g (variables()), from its partials
  // a_q, a_qd, a_qdd with respect to the sample's q, q̇, q̈ (dim n): the spline weights and, for T,
  // dq̇/dT = -q̇/T, dq̈/dT = -2 q̈/T at fixed u.
  void project(int s, const VecN& a_q, const VecN& a_qd, const VecN& a_qdd, double scale, double* g) const;
  // The node matrix and T of x (variables()) into the workspace; throws on a wrong size.
  void set_nodes(std::span<const double> x) const;
  // sqrt(det(J_p J_pᵀ)) at q [m^rows]: J_p the tip Jacobian's first rows_ rows (2 planar, 3 spatial).
  double manipulability(const VecN& q) const;

  MotionSpec spec_;
  int n_ = 0, K_ = 0, variables_ = 0, windows_ = 0, rows_ = 3;
  SplineBasis basis_;
  std::vector<double> u_, c_;                       // sample u and trapezoid weights (in u)
  std::vector<int> window_of_;                      // each sample's window
  std::vector<std::array<NodeVec, 3>> w_;           // per sample: weights of s, s', s''
  std::vector<NodeVec> jerk_w_;                     // per segment: weights of s'''
  std::vector<MotionConstraint> constraints_;
  std::vector<double> mid_, inv_half_, inv_velocity_, inv_effort_;
  Criteria reference_{}, scale_{};

  // workspace
  mutable NodeMat nodes_;
  mutable double T_ = 1.0;
  mutable ChainData data_;
  mutable geometry::ClearanceWorkspace clear_ws_;
  mutable std::vector<VecN> q_, qd_, qdd_, tau_;
  mutable std::vector<MatN> dtau_dq_, dtau_dqd_, M_;
  mutable std::vector<VecN> clear_grad_;
  mutable std::vector<double> clear_;
  mutable std::vector<double> clear_dT_;              // d clearance / dT at each sample (moving obstacles)
  mutable std::vector<geometry::Obstacle> moved_;     // the obstacles at a sample's time
  mutable std::vector<int> top_sample_;              // each constraint's largest sample
};

}  // namespace ks::motion
