// minimise_slsqp (methods/global_solve.hpp).
#include "methods/global_solve.hpp"

#include <nlopt.hpp>

namespace ks {

RunStatus minimise_slsqp(const SlsqpSpec& spec, std::vector<double>& x) {
  nlopt::opt opt(nlopt::LD_SLSQP, static_cast<unsigned>(x.size()));
  opt.set_lower_bounds(-spec.bound);
  opt.set_upper_bounds(spec.bound);
  opt.set_ftol_rel(spec.tolerance);
  opt.set_maxeval(static_cast<int>(spec.max_evaluations));
  opt.set_min_objective(
      [](const std::vector<double>& x, std::vector<double>& grad, void* data) {
        return static_cast<const SlsqpSpec*>(data)->f(x.data(), grad.empty() ? nullptr : grad.data());
      },
      const_cast<SlsqpSpec*>(&spec));
  if (spec.constraints > 0)
    opt.add_inequality_mconstraint(
        [](unsigned, double* con, unsigned, const double* x, double* grad, void* data) {
          static_cast<const SlsqpSpec*>(data)->con(x, con, grad);
        },
        const_cast<SlsqpSpec*>(&spec), std::vector<double>(spec.constraints, 0.0));
  try {
    double f = 0.0;
    if (opt.optimize(x, f) == nlopt::MAXEVAL_REACHED) return RunStatus::max_evaluations;
  } catch (const nlopt::roundoff_limited&) {
    // the gradient norm the run reports says how useful the result is
  } catch (const std::exception&) {
    return RunStatus::not_converged;
  }
  return RunStatus::ok;
}

}  // namespace ks
