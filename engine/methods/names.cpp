// Names of methods, integrators and statuses: the one table shared by the CLI, study files and HDF5.
#include "common/name_table.hpp"

#include "methods/trajectory.hpp"

#include <cmath>

namespace ks {
namespace {
constexpr NameTable<TrajectoryMethod, 3> kMethods{{{TrajectoryMethod::local_weighted, "local_weighted"},
                                               {TrajectoryMethod::local_unweighted, "local_unweighted"},
                                               {TrajectoryMethod::vertex_alpha, "vertex_alpha"}}};
constexpr NameTable<Integrator, 2> kIntegrators{
    {{Integrator::semi_implicit_euler, "semi_implicit_euler"}, {Integrator::rk4, "rk4"}}};
constexpr NameTable<RunStatus, 7> kStatuses{{{RunStatus::ok, "ok"},
                                         {RunStatus::unreachable_start, "unreachable_start"},
                                         {RunStatus::singular, "singular"},
                                         {RunStatus::diverged, "diverged"},
                                         {RunStatus::undersampled, "undersampled"},
                                         {RunStatus::off_path, "off_path"},
                                         {RunStatus::out_of_limits, "out_of_limits"}}};
constexpr NameTable<OnViolation, 3> kOnViolation{
    {{OnViolation::mark, "mark"}, {OnViolation::stop, "stop"}, {OnViolation::ignore, "ignore"}}};

}  // namespace

std::string_view to_string(TrajectoryMethod m) { return name_of(kMethods, m); }
std::string_view to_string(Integrator i) { return name_of(kIntegrators, i); }
std::string_view to_string(RunStatus s) { return name_of(kStatuses, s); }
bool parse(std::string_view n, TrajectoryMethod& out) { return value_of(kMethods, n, out); }
bool parse(std::string_view n, Integrator& out) { return value_of(kIntegrators, n, out); }
bool parse(std::string_view n, RunStatus& out) { return value_of(kStatuses, n, out); }
std::string_view to_string(OnViolation v) { return name_of(kOnViolation, v); }
bool parse(std::string_view n, OnViolation& out) { return value_of(kOnViolation, n, out); }

}  // namespace ks

namespace ks {

bool TrajectoryOptions::IsValid(std::string* why) const {
  if (!fields_valid({{"k", k, Domain::any()},
                     {"alpha1A", alpha1A, Domain::any()},
                     {"null_damping", null_damping, null_damping_rule},
                     {"limit_centring", limit_centring, limit_centring_rule},
                     {"dt", dt, dt_rule},
                     {"torque_bound", torque_bound, torque_bound_rule},
                     {"singular_tolerance", singular_tolerance, singular_tolerance_rule},
                     {"K_P", clik_kp, clik_gain_rule},
                     {"K_D", clik_kd, clik_gain_rule},
                     {"tracking_bound", tracking_bound, bound_rule},
                     {"orientation_bound", orientation_bound, bound_rule}},
                    why))
    return false;
  for (double a : vertex_alpha)
    if (!std::isfinite(a)) {
      if (why) *why = "vertex_alpha has a value that is not finite; expected finite angles [rad]";
      return false;
    }
  return true;
}

}  // namespace ks
