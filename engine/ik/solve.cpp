// The engine's IK problems, compiled once (see ik/solve.hpp).
#include "ik/solve_impl.hpp"

namespace ks::ik {

template void solve(const ScaraPosition&, const Vec<3>&, const Options&, Summary<3, 3>&);
template void solve(const PlanarPose&, const Vec<3>&, const Options&, Summary<3, 3>&);
template void solve(const PlanarPosition&, const Vec<3>&, const Options&, Summary<3, 2>&);
template struct Summary<3, 3>;
template struct Summary<3, 2>;
template std::ostream& operator<<(std::ostream&, const Summary<3, 3>&);
template std::ostream& operator<<(std::ostream&, const Summary<3, 2>&);

}  // namespace ks::ik

namespace ks::ik {

bool Options::IsValid(std::string* why) const {
  if (!fields_valid({{"tolerance", tolerance, tolerance_rule},
                     {"max_iter", double(max_iter), max_iter_rule},
                     {"step_floor", step_floor, step_floor_rule},
                     {"lambda", lambda, lambda_rule},
                     {"lambda_scale", lambda_scale, lambda_scale_rule},
                     {"rcond_min", rcond_min, rcond_min_rule},
                     {"divergence_bound", divergence_bound, divergence_bound_rule},
                     {"cycle_tolerance", cycle_tolerance, cycle_tolerance_rule},
                     {"match_tolerance", match_tolerance, match_tolerance_rule},
                     {"restarts", double(restarts), restarts_rule},
                     {"stall_window", double(stall_window), stall_window_rule}},
                    why))
    return false;
  if (!(cycle_window >= 0 && cycle_window <= max_cycle_window)) {
    if (why)
      *why = "cycle_window = " + std::to_string(cycle_window) + "; expected cycle_window within [0, " +
             std::to_string(max_cycle_window) + "]";
    return false;
  }
  if (joint_limits != JointLimits::none && joint_limits != JointLimits::clamp && joint_limits != JointLimits::reject) {
    if (why)
      *why = "joint_limits = " + std::to_string(static_cast<int>(joint_limits)) +
             "; expected joint_limits one of none, clamp, reject";
    return false;
  }
  return true;
}

}  // namespace ks::ik
