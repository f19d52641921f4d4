// minimise_slsqp (methods/path_global/slsqp.hpp).
#include "methods/path_global/slsqp.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <nlopt.hpp>
#include <stdexcept>
#include <string>

namespace ks {

double kkt_residual(const std::vector<double>& grad, const std::vector<double>& jac, std::size_t rows) {
  const auto n = static_cast<Eigen::Index>(grad.size()), m = static_cast<Eigen::Index>(rows);
  if (n == 0) return 0.0;  // no free variable: nothing to move, stationary
  if (jac.size() != grad.size() * rows)
    throw std::invalid_argument("kkt_residual: " + std::to_string(jac.size()) + " Jacobian entries for " +
                                std::to_string(rows) + " rows of " + std::to_string(n) + " variables");
  const auto finite = [](double v) { return std::isfinite(v); };
  if (!std::ranges::all_of(grad, finite) || !std::ranges::all_of(jac, finite))
    return std::numeric_limits<double>::quiet_NaN();
  const Eigen::Map<const Eigen::VectorXd> g(grad.data(), n);
  if (m == 0) return g.cwiseAbs().maxCoeff();
  // min ||A lambda - g|| over lambda >= 0 with A = -jac^T
  const Eigen::MatrixXd A = -Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
                                 jac.data(), m, n).transpose();
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(m);
  std::vector<bool> passive(static_cast<std::size_t>(m), false);
  const double tiny = 1e-12 * std::max(1.0, g.cwiseAbs().maxCoeff()) * std::max(1.0, A.cwiseAbs().maxCoeff());
  for (Eigen::Index outer = 0; outer < 3 * m + 10; ++outer) {
    const Eigen::VectorXd w = A.transpose() * (g - A * lambda);
    Eigen::Index t = -1;
    double best = tiny;
    for (Eigen::Index j = 0; j < m; ++j)
      if (!passive[j] && w[j] > best) best = w[j], t = j;
    if (t < 0) break;
    passive[t] = true;
    for (Eigen::Index inner = 0; inner < 3 * m + 10; ++inner) {
      std::vector<Eigen::Index> P;
      for (Eigen::Index j = 0; j < m; ++j)
        if (passive[j]) P.push_back(j);
      if (P.empty()) break;  // every multiplier dropped back to zero
      Eigen::MatrixXd AP(n, static_cast<Eigen::Index>(P.size()));
      for (std::size_t k = 0; k < P.size(); ++k) AP.col(static_cast<Eigen::Index>(k)) = A.col(P[k]);
      const Eigen::VectorXd zP = AP.colPivHouseholderQr().solve(g);
      Eigen::VectorXd z = Eigen::VectorXd::Zero(m);
      for (std::size_t k = 0; k < P.size(); ++k) z[P[k]] = zP[static_cast<Eigen::Index>(k)];
      double step = 1.0;
      for (Eigen::Index j : P)
        if (z[j] <= 0.0) step = std::min(step, lambda[j] / (lambda[j] - z[j]));
      if (step >= 1.0) {
        lambda = z;
        break;
      }
      lambda += step * (z - lambda);
      for (Eigen::Index j : P)
        if (lambda[j] <= tiny) passive[j] = false, lambda[j] = 0.0;
    }
  }
  return (g - A * lambda).cwiseAbs().maxCoeff();
}

namespace {
std::atomic<const std::atomic<bool>*> g_stop_flag{nullptr};
}  // namespace

void set_optimiser_stop_flag(const std::atomic<bool>* flag) { g_stop_flag.store(flag); }

RunStatus minimise_slsqp(const SlsqpSpec& spec, std::vector<double>& x) {
  nlopt::opt opt(nlopt::LD_SLSQP, static_cast<unsigned>(x.size()));
  opt.set_lower_bounds(-spec.bound);
  opt.set_upper_bounds(spec.bound);
  opt.set_ftol_rel(spec.tolerance);
  opt.set_maxeval(static_cast<int>(spec.max_evaluations));
  opt.set_min_objective(
      [](const std::vector<double>& x, std::vector<double>& grad, void* data) {
        if (const std::atomic<bool>* stop = g_stop_flag.load(std::memory_order_relaxed);
            stop && stop->load(std::memory_order_relaxed))
          throw nlopt::forced_stop();
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
  } catch (const nlopt::forced_stop&) {
    return RunStatus::interrupted;
  } catch (const nlopt::roundoff_limited&) {
    // the gradient norm the run reports says how useful the result is
  } catch (const std::exception&) {
    return RunStatus::not_converged;
  }
  return RunStatus::ok;
}

}  // namespace ks
