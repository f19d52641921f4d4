// finish_run (methods/metrics/sample_sums.hpp): a run's metrics from its sums.
#include "methods/metrics/sample_sums.hpp"

namespace ks {

TrajectoryMetrics finish_run(const RunSums& s, const RunShape& shape, const TrajectoryOptions& o) {
  TrajectoryMetrics out;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.status = s.status;
  if (out.status == RunStatus::ok && o.on_violation != OnViolation::ignore) out.status = s.crossed;
  out.samples = s.done;
  out.final_alpha = s.last_alpha;
  out.stop_time = s.last_t;
  out.tau_inf.setZero(shape.joints);
  if (s.done > 0) {
    const double d = static_cast<double>(s.done);
    for (int j = 0; j < shape.joints; ++j) out.tau_inf[j] = s.inf[j];
    out.E = s.sumE / d;
    out.E_M = s.sumEM / d;
    if (shape.prismatic) out.E_force = s.sumEF / d;
    out.min_manipulability = std::sqrt(s.min_w2);
    out.torque_sq_integral = s.trapezoid.torque(o.dt);
    out.power_sq_integral = s.trapezoid.power(o.dt);
    out.max_tracking_error = std::sqrt(s.max_err2);
    out.mean_tracking_error = s.sum_err / d;
    if (shape.orientation) out.max_orientation_error = s.max_orient;
    for_each_sample_metric([&](const auto& m, int k) {
      out.sampled[k] = m.reduce == Reduce::mean ? s.sampled[k] / d : s.sampled[k];
    });
    if (const LimitTable* L = shape.limits) {
      if (L->any_position) out.max_q_limit_ratio = s.ratio_q;
      if (L->any_velocity) out.max_qd_limit_ratio = s.ratio_qd;
      if (L->any_effort) out.max_tau_limit_ratio = s.ratio_tau;
    }
  }
  const bool bounded_stop = o.on_violation == OnViolation::stop &&
                            (out.status == RunStatus::off_path || out.status == RunStatus::out_of_limits);
  if (bounded_stop || s.done == 0) {  // (no sample: no metric was computed)
    out.E = out.E_M = out.E_force = out.min_manipulability = out.torque_sq_integral = out.power_sq_integral = nan;
    out.max_tracking_error = out.mean_tracking_error = out.max_orientation_error = nan;
    out.max_q_limit_ratio = out.max_qd_limit_ratio = out.max_tau_limit_ratio = nan;
    out.final_alpha = nan;
    out.sampled.fill(nan);
    out.tau_inf.setConstant(shape.joints, nan);
  }
  return out;
}

}  // namespace ks
