#pragma once
// The optimiser of the path-global method: NLopt's SLSQP (gradient-based, local) on box-bounded
// coefficients, with optional inequality constraints, and its outcome as a run status.
#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "methods/base/trajectory.hpp"

namespace ks {

struct SlsqpSpec {
  /// f(x, grad): the objective at x; its gradient into grad (size of x) when grad is not null.
  std::function<double(const double* x, double* grad)> f;
  /// con(x, con, jac): `constraints` values con(x) <= 0 and, when jac is not null, their gradients
  /// (row-major, constraints x size of x). None when constraints = 0.
  unsigned constraints = 0;
  std::function<void(const double* x, double* con, double* jac)> con;
  double bound = 0;                   ///< every coefficient within [-bound, bound]
  double tolerance = 1e-10;           ///< relative change of the objective that stops SLSQP
  std::int64_t max_evaluations = 1;   ///< objective evaluations allowed
};

/// The KKT residual at a point with active inequality constraints: min over lambda >= 0 of the
/// infinity norm of grad + jac^T lambda (non-negative least squares, Lawson and Hanson's active set
/// method), per variable. \param[in] grad (n), jac (rows x n, row-major: the active constraints'
/// gradients). Without rows: the infinity norm of grad; without variables (n = 0: every variable held
/// by a bound): 0; a non-finite entry in grad or jac: NaN. Rows of zeros change nothing. Throws
/// std::invalid_argument when jac does not hold rows x n entries.
double kkt_residual(const std::vector<double>& grad, const std::vector<double>& jac, std::size_t rows);

/// The flag that asks the process to stop (set by its SIGINT / SIGTERM handler; null: none), checked
/// by minimise_slsqp at every objective evaluation. Process-wide; thread-safe.
void set_optimiser_stop_flag(const std::atomic<bool>* flag);

/// Minimise from x (updated in place to the last point SLSQP returns). Status: ok (a tolerance was
/// met, or SLSQP stopped on roundoff: NLopt's "typically useful result"), max_evaluations,
/// not_converged (any other NLopt failure), or interrupted (the stop flag was set: SLSQP ended at
/// the next objective evaluation; x is then of no use).
RunStatus minimise_slsqp(const SlsqpSpec& spec, std::vector<double>& x);

}  // namespace ks
