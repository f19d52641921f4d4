#pragma once
// Verification between samples of a path-global run. Its trajectory is defined at every instant (the
// splines of its coordinates, the exact inverse kinematics of the path at that instant), so it can be
// evaluated on any grid: the run's figures at its samples (step dt) are compared with the same
// trajectory's figures at dt / F and dt / F^2. A trajectory cheap only at its samples (a joint that
// passes a singularity between two of them, a torque spike that no sample sees) shows as a departure.
#include <algorithm>
#include <cmath>
#include <limits>

#include "methods/base/trajectory.hpp"

namespace ks {

/// The relative departure of `dense` from `sampled` (both the same run's metrics on two grids): the
/// largest of |dE| / E, the rise of the peak torque over the sampled peak, the drop of the minimum
/// manipulability below the sampled minimum (relative to it), the rise of the tracking error above
/// max(sampled error, 1e-9 m) over the run's tracking bound, and the rise of the largest limit ratio.
/// +inf when the dense evaluation ended with another status than the sampled one (it stopped, or
/// crossed a bound or limit, where the sampled one did not).
inline double dense_departure(const TrajectoryMetrics& sampled, const TrajectoryMetrics& dense, double tracking_bound) {
  if (dense.status != sampled.status) return std::numeric_limits<double>::infinity();
  const auto peak = [](const VecN& v) { return v.size() ? v.maxCoeff() : 0.0; };
  const auto rise = [](double d, double s) {  // relative increase of d over s (0 when d <= s)
    return d > s ? (d - s) / std::max(std::abs(s), 1e-300) : 0.0;
  };
  double dep = std::abs(dense.E - sampled.E) / std::max(std::abs(sampled.E), 1e-300);
  dep = std::max(dep, rise(peak(dense.tau_inf), peak(sampled.tau_inf)));
  if (sampled.min_manipulability > 0.0)
    dep = std::max(dep, std::max(0.0, sampled.min_manipulability - dense.min_manipulability) / sampled.min_manipulability);
  const double track = std::max(sampled.max_tracking_error, 1e-9);
  if (tracking_bound > 0.0 && dense.max_tracking_error > track)
    dep = std::max(dep, (dense.max_tracking_error - track) / tracking_bound);
  for (auto [d, s] : {std::pair{dense.max_q_limit_ratio, sampled.max_q_limit_ratio},
                      std::pair{dense.max_qd_limit_ratio, sampled.max_qd_limit_ratio},
                      std::pair{dense.max_tau_limit_ratio, sampled.max_tau_limit_ratio}})
    if (std::isfinite(d) && std::isfinite(s)) dep = std::max(dep, rise(d, s));
  return std::isnan(dep) ? std::numeric_limits<double>::infinity() : dep;
}

/// Evaluates the run at dt / factor and dt / factor^2 and returns its dense figures (those of the
/// finer grid, the departure the larger of the two). \param[in] sampled the run's metrics at its
/// samples (step dt [s]); \param[in] measure_at a callable (double step [s]) -> TrajectoryMetrics
/// evaluating the same trajectory on the grid of that step. factor <= 1: nothing evaluated, NaN figures.
template <class MeasureAt>
TrajectoryMetrics::Dense verify_between_samples(const TrajectoryMetrics& sampled, double dt, int factor,
                                                double tracking_bound, MeasureAt&& measure_at) {
  TrajectoryMetrics::Dense out;
  if (factor <= 1) return out;
  double departure = 0.0;
  for (int level = 1; level <= 2; ++level) {
    const double step = dt / std::pow(static_cast<double>(factor), level);
    const TrajectoryMetrics d = measure_at(step);
    departure = std::max(departure, dense_departure(sampled, d, tracking_bound));
    if (level == 2 || d.status != sampled.status) {
      out.E = d.E;
      out.tau_inf = d.tau_inf.size() ? d.tau_inf.maxCoeff() : std::numeric_limits<double>::quiet_NaN();
      out.min_manipulability = d.min_manipulability;
      out.max_tracking_error = d.max_tracking_error;
      double lim = std::numeric_limits<double>::quiet_NaN();
      for (double r : {d.max_q_limit_ratio, d.max_qd_limit_ratio, d.max_tau_limit_ratio})
        if (std::isfinite(r)) lim = std::isnan(lim) ? r : std::max(lim, r);
      out.max_limit_ratio = lim;
      if (d.status != sampled.status) break;
    }
  }
  out.departure = departure;
  return out;
}

}  // namespace ks
