#pragma once
// Options of the path-global method (global_spline): the tip angle alpha(t) over the whole path chosen
// by a gradient-based optimiser (NLopt SLSQP), the joint path by exact inverse kinematics at every
// sample, the torques by inverse dynamics (methods/path_global/closed_form.hpp).
#include <cstdint>
#include <string>
#include <string_view>

#include "common/domain.hpp"

namespace ks {

/// What the path-global method minimises over alpha(t).
enum class GlobalObjective {
  E,                   ///< mean over samples of sqrt(tau^T tau) [Nm] (seed Eq. 60; case 4's objective)
  E_M,                 ///< mean over samples of sqrt(tau^T M^-1 tau) (case 3's objective)
  torque_sq_integral,  ///< trapezoidal integral of tau^T tau [N^2 m^2 s]
  kinetic_energy,      ///< trapezoidal integral of the kinetic energy qd^T M qd / 2 [J s]
};

/// How alpha(t) is represented (methods/path_global/alpha_basis.hpp).
enum class AlphaSpline {
  cubic,           ///< clamped uniform cubic B-spline with `knots` breakpoints, at rest at both ends (C2)
  vertex_quintic,  ///< alpha at the path's vertices, a quintic per segment (seed cases 3-5's family)
};

/// The redundant coordinates the splines describe (cubic splines; vertex_quintic is always alpha). The
/// seed's arm and planar revolute chains take any; other chains joints.
enum class Extension {
  alpha,        ///< the tip angle alpha on the start's elbow branch; singular where theta2 = 0 (stretched)
  self_motion,  ///< the angle psi along the arm's self-motion circle at the tip: alpha = phi + beta sin psi,
                ///< elbow branch = sign(cos psi) (phi: the tip's direction, beta: half the reachable alpha
                ///< arc), so a path may cross elbow branches through the stretched arm
  joints,       ///< r of the robot's joint angles; the other m (as many as the task has rows) are solved on
                ///< the tip position by Newton's method, singular where their task Jacobian is (any chain)
};

/// Where the optimiser starts.
enum class GlobalStart {
  local,   ///< alpha(t) of the run's local method (start_method, alpha1A, k, K_N) fitted by the spline
  vertex,  ///< alpha(t) of vertex_alpha at the run's alpha1A and vertex_alpha_i, fitted by the spline
  random,  ///< alpha1A plus independent uniform draws in [-0.5, 0.5] rad per coefficient (start_seed)
};

/// The local method whose run is the start when start = local.
enum class StartMethod { local_unweighted, local_weighted };

/// Whether alpha at the start is the run's alpha1A or a free variable.
enum class StartPosture { fixed, free };

/// Whether the arm ends at rest (zero self-motion rate at the last vertex, as it starts) or may still
/// move in its self-motion there, as a local method's run may.
enum class EndState { rest, free };

std::string_view to_string(GlobalObjective v);
std::string_view to_string(AlphaSpline v);
std::string_view to_string(GlobalStart v);
std::string_view to_string(StartPosture v);
std::string_view to_string(StartMethod v);
std::string_view to_string(Extension v);
std::string_view to_string(EndState v);
bool parse(std::string_view name, GlobalObjective& out);
bool parse(std::string_view name, AlphaSpline& out);
bool parse(std::string_view name, GlobalStart& out);
bool parse(std::string_view name, StartPosture& out);
bool parse(std::string_view name, StartMethod& out);
bool parse(std::string_view name, Extension& out);
bool parse(std::string_view name, EndState& out);

struct PathGlobalOptions {
  AlphaSpline spline = AlphaSpline::cubic;
  std::int64_t knots = 20;               ///< cubic: breakpoints, evenly spaced in time (= coefficients)
  Extension extension = Extension::self_motion;  ///< cubic: the coordinate the spline describes
  GlobalObjective objective = GlobalObjective::E;
  GlobalStart start = GlobalStart::local;
  StartMethod start_method = StartMethod::local_unweighted;  ///< start = local
  StartPosture posture = StartPosture::fixed;
  EndState end = EndState::rest;         ///< cubic: the self-motion rate at the end
  std::int64_t start_seed = 0;           ///< start = random
  double tolerance = 1e-10;              ///< relative change of the objective that stops the optimiser
  std::int64_t max_evaluations = 3000;   ///< objective evaluations (each with its gradient)
  /// Verification between samples (methods/path_global/verify.hpp): the optimum is evaluated again at
  /// dt / verify_factor and dt / verify_factor^2 (1: not verified); a relative departure of its
  /// figures above verify_tolerance makes the optimiser solve again from its start on the grid of
  /// step dt / verify_factor^level (level = 1 .. refinements, each solve with max_evaluations), and a
  /// run still departing ends `undersampled`. The run's metrics stay those at its samples (step dt).
  std::int64_t verify_factor = 4;
  double verify_tolerance = 0.01;
  std::int64_t refinements = 0;

  static constexpr Domain knots_rule = Domain::within(2, 2000);
  static constexpr Domain tolerance_rule = Domain::positive();
  static constexpr Domain max_evaluations_rule = Domain::within(1, 1e7);
  static constexpr Domain verify_factor_rule = Domain::within(1, 64);
  static constexpr Domain verify_tolerance_rule = Domain::positive();
  static constexpr Domain refinements_rule = Domain::within(0, 3);

  bool IsValid(std::string* why = nullptr) const {
    return fields_valid({{"knots", static_cast<double>(knots), knots_rule},
                         {"opt_tolerance", tolerance, tolerance_rule},
                         {"max_evaluations", static_cast<double>(max_evaluations), max_evaluations_rule},
                         {"verify_factor", static_cast<double>(verify_factor), verify_factor_rule},
                         {"verify_tolerance", verify_tolerance, verify_tolerance_rule},
                         {"refinements", static_cast<double>(refinements), refinements_rule}},
                        why);
  }
};

}  // namespace ks
