#pragma once
// Minimise a motion problem (motion/motion_problem.hpp) with NLopt's SLSQP: the exact-to-rounding
// gradients of the objective and of the windowed constraints, the variables boxed by
// MotionProblem::bounds. The global stage is a multistart: the first start is the initial point (the
// rest-to-rest cubic), each further start a deterministic random point around it (seeded), and the best
// feasible end wins. It stands in for seed 002's tunneling (restarts from perturbations of the local
// minimum, accepted when lower): with gradients and a smooth objective, independent SLSQP runs from
// spread starts probe the same basins at a known cost and without the tunneling function's pole.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "motion/motion_problem.hpp"

namespace ks::motion {

/// How the solve ended (the best start's outcome).
enum class MotionTermination {
  converged,        ///< a tolerance was met (ftol_rel or xtol_rel)
  roundoff_limited, ///< SLSQP stopped on rounding: usually a useful result
  max_evaluations,  ///< the evaluation budget ran out
  infeasible,       ///< no start ended within the constraint tolerance
  failure,          ///< NLopt failed (its message in Summary::message)
};
std::string_view to_string(MotionTermination t);

struct MotionSolveOptions {
  int max_evaluations = 1000;        ///< SLSQP evaluations per start (> 0)
  double ftol_rel = 1e-12;           ///< relative objective change that stops (>= 0)
  double xtol_rel = 1e-10;           ///< relative variable change that stops (>= 0)
  double constraint_tolerance = 1e-9;  ///< a constraint value <= this counts as satisfied (>= 0)
  double control_pad = 1.0;          ///< controls within this of [min, max](start, goal) [rad or m] (> 0)
  int starts = 1;                    ///< SLSQP runs: the initial point, then starts - 1 perturbed ones (>= 1)
  double start_spread = 0.2;         ///< perturbation, as a fraction of each variable's bound range (in (0, 1])
  std::uint64_t seed = 1;            ///< of the perturbations

  /// False, with the first broken rule in *why, when a field is outside its stated domain.
  bool IsValid(std::string* why = nullptr) const;
};

struct MotionSummary {
  MotionTermination termination = MotionTermination::failure;
  std::string message;               ///< what stopped the best start (NLopt's result or exception)
  int evaluations = 0;               ///< over every start
  int best_start = 0;                ///< which start won (0: the initial point)
  std::vector<double> x;             ///< the best point (MotionProblem's variables)
  Criteria initial{}, final{};       ///< the criteria at the initial and the best point
  double initial_objective = 0.0, final_objective = 0.0;
  double max_constraint = 0.0;       ///< the largest constraint value at x (<= tolerance: feasible)
  bool feasible = false;
};

/// Minimise `problem` from x0 (empty: problem.initial_point()). Throws std::invalid_argument when
/// !options.IsValid() or x0 has the wrong size.
MotionSummary solve_motion(const MotionProblem& problem, const MotionSolveOptions& options = {},
                           std::span<const double> x0 = {});

}  // namespace ks::motion
