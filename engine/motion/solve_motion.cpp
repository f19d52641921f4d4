// solve_motion (motion/solve_motion.hpp): SLSQP from one or more starts.
#include "motion/solve_motion.hpp"

#include <algorithm>
#include <cmath>
#include <nlopt.hpp>
#include <random>
#include <stdexcept>

namespace ks::motion {
namespace {

bool refuse(std::string* why, const std::string& text) {
  if (why) *why = text;
  return false;
}

// One SLSQP run's evaluations: the objective and the constraints share the last point's evaluation
// (SLSQP asks for both at the same x).
struct Run {
  const MotionProblem* problem;
  MotionEvaluation e;
  std::vector<double> last;
  int evaluations = 0;
  void at(const double* x) {
    const auto n = static_cast<std::size_t>(problem->variables());
    if (last.size() == n && std::equal(last.begin(), last.end(), x)) return;
    last.assign(x, x + n);
    problem->evaluate(last, true, e);
    ++evaluations;
  }
};

double largest(const std::vector<double>& c) { return c.empty() ? -1.0 : *std::max_element(c.begin(), c.end()); }

}  // namespace

std::string_view to_string(MotionTermination t) {
  switch (t) {
    case MotionTermination::converged: return "converged";
    case MotionTermination::roundoff_limited: return "roundoff_limited";
    case MotionTermination::max_evaluations: return "max_evaluations";
    case MotionTermination::infeasible: return "infeasible";
    case MotionTermination::failure: return "failure";
  }
  return "?";
}

bool MotionSolveOptions::IsValid(std::string* why) const {
  if (max_evaluations <= 0) return refuse(why, "max_evaluations must be > 0");
  if (!(ftol_rel >= 0.0) || !(xtol_rel >= 0.0)) return refuse(why, "ftol_rel and xtol_rel must be >= 0");
  if (!(constraint_tolerance >= 0.0)) return refuse(why, "constraint_tolerance must be >= 0");
  if (!(control_pad > 0.0) || !std::isfinite(control_pad)) return refuse(why, "control_pad must be finite and > 0");
  if (starts < 1) return refuse(why, "starts must be >= 1");
  if (!(start_spread > 0.0 && start_spread <= 1.0)) return refuse(why, "start_spread must be in (0, 1]");
  return true;
}

MotionSummary solve_motion(const MotionProblem& problem, const MotionSolveOptions& options, std::span<const double> x0) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("solve_motion: " + why);
  const int nv = problem.variables();
  std::vector<double> start = x0.empty() ? problem.initial_point() : std::vector<double>(x0.begin(), x0.end());
  if (static_cast<int>(start.size()) != nv) throw std::invalid_argument("solve_motion: x0 has the wrong size");
  std::vector<double> lower, upper;
  problem.bounds(options.control_pad, lower, upper);
  for (int v = 0; v < nv; ++v) start[v] = std::clamp(start[v], lower[v], upper[v]);

  MotionSummary sum;
  MotionEvaluation e;
  problem.evaluate(start, false, e);
  sum.initial = e.criteria;
  sum.initial_objective = e.objective;
  sum.x = start;
  sum.final = e.criteria;
  sum.final_objective = e.objective;
  sum.max_constraint = largest(e.constraints);
  sum.feasible = sum.max_constraint <= options.constraint_tolerance;
  bool have = false;

  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int k = 0; k < options.starts; ++k) {
    std::vector<double> x = start;
    if (k > 0)
      for (int v = 0; v < nv; ++v)
        x[v] = std::clamp(start[v] + options.start_spread * (upper[v] - lower[v]) * unit(rng), lower[v], upper[v]);
    Run run{&problem, {}, {}, 0};
    nlopt::opt opt(nlopt::LD_SLSQP, static_cast<unsigned>(nv));
    opt.set_lower_bounds(lower);
    opt.set_upper_bounds(upper);
    opt.set_ftol_rel(options.ftol_rel);
    opt.set_xtol_rel(options.xtol_rel);
    opt.set_maxeval(options.max_evaluations);
    opt.set_min_objective(
        [](const std::vector<double>& x, std::vector<double>& grad, void* data) {
          Run& r = *static_cast<Run*>(data);
          r.at(x.data());
          if (!grad.empty()) std::copy(r.e.objective_gradient.begin(), r.e.objective_gradient.end(), grad.begin());
          return r.e.objective;
        },
        &run);
    const auto m = static_cast<unsigned>(problem.constraints());
    if (m > 0)
      opt.add_inequality_mconstraint(
          [](unsigned, double* con, unsigned n, const double* x, double* grad, void* data) {
            Run& r = *static_cast<Run*>(data);
            r.at(x);
            std::copy(r.e.constraints.begin(), r.e.constraints.end(), con);
            if (grad) std::copy(r.e.constraint_jacobian.begin(), r.e.constraint_jacobian.end(), grad);
            (void)n;
          },
          &run, std::vector<double>(m, options.constraint_tolerance));
    MotionTermination term = MotionTermination::failure;
    std::string message;
    try {
      double f = 0.0;
      const nlopt::result res = opt.optimize(x, f);
      term = res == nlopt::MAXEVAL_REACHED ? MotionTermination::max_evaluations : MotionTermination::converged;
      message = res == nlopt::FTOL_REACHED ? "ftol_rel reached"
                : res == nlopt::XTOL_REACHED ? "xtol_rel reached"
                : res == nlopt::MAXEVAL_REACHED ? "max_evaluations reached"
                                                 : "nlopt result " + std::to_string(static_cast<int>(res));
    } catch (const nlopt::roundoff_limited&) {
      term = MotionTermination::roundoff_limited;
      message = "roundoff limited";
    } catch (const std::exception& ex) {
      term = MotionTermination::failure;
      message = ex.what();
    }
    sum.evaluations += run.evaluations;
    if (term == MotionTermination::failure && !have) {
      sum.termination = term, sum.message = message;
      continue;
    }
    problem.evaluate(x, false, e);  // the point NLopt returned, evaluated afresh
    const double worst = largest(e.constraints);
    const bool feasible = worst <= options.constraint_tolerance && std::isfinite(e.objective);
    const bool better = !have || (feasible && !sum.feasible) ||
                        (feasible == sum.feasible && (feasible ? e.objective < sum.final_objective : worst < sum.max_constraint));
    if (!better || term == MotionTermination::failure) continue;
    have = true;
    sum.x = x;
    sum.final = e.criteria;
    sum.final_objective = e.objective;
    sum.max_constraint = worst;
    sum.feasible = feasible;
    sum.best_start = k;
    sum.termination = feasible ? term : MotionTermination::infeasible;
    sum.message = message;
  }
  return sum;
}

}  // namespace ks::motion
