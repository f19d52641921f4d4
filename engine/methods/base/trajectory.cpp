// The functions every method's run shares (methods/base/trajectory.hpp).
#include "methods/base/trajectory.hpp"

#include <limits>

namespace ks {

bool samples_path(const std::vector<double>& durations, double dt) {
  for (double d : durations)
    if (!(d / dt >= kMinSamplesPerSegment * (1 - 1e-12))) return false;
  return true;
}

TrajectoryMetrics not_simulated(RunStatus status, int joints) {
  TrajectoryMetrics out;
  out.status = status;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.E = out.E_M = out.min_manipulability = out.torque_sq_integral = out.power_sq_integral = nan;
  out.max_tracking_error = out.mean_tracking_error = out.final_alpha = out.max_orientation_error = nan;
  out.max_q_limit_ratio = out.max_qd_limit_ratio = out.max_tau_limit_ratio = out.E_force = nan;
  out.tau_inf.setConstant(joints, nan);
  return out;
}

void TrajectoryHistory::prepare(std::size_t samples) {
  const Eigen::Index n = static_cast<Eigen::Index>((samples + stride - 1) / stride + 1);
  if (t.size() < n) {
    t.resize(n);
    q.resize(3, n);
    qd.resize(3, n);
    qdd.resize(3, n);
    tau.resize(3, n);
    x.resize(2, n);
    alpha.resize(n);
  }
  size = 0;
}

}  // namespace ks
