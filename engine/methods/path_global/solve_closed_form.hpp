#pragma once
// The path-global method (global_spline) on the seed's planar 3R arm: alpha(t) over the whole path
// minimising options.global.objective, solved by NLopt's SLSQP (gradient-based, local) with the
// chain-rule gradient of methods/path_global/closed_form.hpp, from the start options.global.start names.
#include <vector>

#include "methods/base/trajectory.hpp"

namespace ks {

/// Run one global_spline run. Inputs: arm constants, the path sampled at options.dt, options (method
/// global_spline; alpha1A is alpha at the start, fixed or the free start's first guess). Output:
/// metrics of the optimum (the trajectory kind's, plus opt_*), its history when given. Status: ok
/// (converged, on the path, within the bounds), max_evaluations, not_converged, infeasible,
/// singular_extension, unreachable_start (the start's local run or alpha1A cannot reach the first
/// vertex), or the bound statuses of any run. `coefficients`, when given, receives the optimum's
/// spline coefficients (of vertex_quintic_basis or cubic_spline_basis, in the chart of
/// options.global.extension). Throws std::invalid_argument when options.IsValid() fails or the method
/// is not global_spline.
TrajectoryMetrics solve_global_spline(const PlanarArm3& arm, const SampledPath& path, const TrajectoryOptions& options,
                                      TrajectoryHistory* history = nullptr, std::vector<double>* coefficients = nullptr);

}  // namespace ks
