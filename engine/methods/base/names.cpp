// Names of methods, integrators and statuses: the one table shared by the CLI, study files and HDF5.
#include "common/name_table.hpp"

#include "methods/base/trajectory.hpp"

#include <cmath>

namespace ks {
namespace {
constexpr NameTable<TrajectoryMethod, 4> kMethods{{{TrajectoryMethod::local_weighted, "local_weighted"},
                                               {TrajectoryMethod::local_unweighted, "local_unweighted"},
                                               {TrajectoryMethod::vertex_alpha, "vertex_alpha"},
                                               {TrajectoryMethod::global_spline, "global_spline"}}};
constexpr NameTable<Integrator, 2> kIntegrators{
    {{Integrator::semi_implicit_euler, "semi_implicit_euler"}, {Integrator::rk4, "rk4"}}};
constexpr NameTable<RunStatus, 13> kStatuses{{{RunStatus::ok, "ok"},
                                         {RunStatus::unreachable_start, "unreachable_start"},
                                         {RunStatus::singular, "singular"},
                                         {RunStatus::diverged, "diverged"},
                                         {RunStatus::undersampled, "undersampled"},
                                         {RunStatus::off_path, "off_path"},
                                         {RunStatus::out_of_limits, "out_of_limits"},
                                         {RunStatus::max_evaluations, "max_evaluations"},
                                         {RunStatus::not_converged, "not_converged"},
                                         {RunStatus::infeasible, "infeasible"},
                                         {RunStatus::singular_extension, "singular_extension"},
                                         {RunStatus::out_of_reach, "out_of_reach"},
                                         {RunStatus::interrupted, "interrupted"}}};
constexpr NameTable<GlobalObjective, 4> kObjectives{{{GlobalObjective::E, "E"},
                                                     {GlobalObjective::E_M, "E_M"},
                                                     {GlobalObjective::torque_sq_integral, "torque_sq_integral"},
                                                     {GlobalObjective::kinetic_energy, "kinetic_energy"}}};
constexpr NameTable<AlphaSpline, 2> kSplines{
    {{AlphaSpline::cubic, "cubic"}, {AlphaSpline::vertex_quintic, "vertex_quintic"}}};
constexpr NameTable<GlobalStart, 3> kStarts{
    {{GlobalStart::local, "local"}, {GlobalStart::vertex, "vertex"}, {GlobalStart::random, "random"}}};
constexpr NameTable<StartMethod, 2> kStartMethods{
    {{StartMethod::local_unweighted, "local_unweighted"}, {StartMethod::local_weighted, "local_weighted"}}};
constexpr NameTable<Extension, 3> kExtensions{
    {{Extension::alpha, "alpha"}, {Extension::self_motion, "self_motion"}, {Extension::joints, "joints"}}};
constexpr NameTable<EndState, 2> kEnds{{{EndState::rest, "rest"}, {EndState::free, "free"}}};
constexpr NameTable<StartPosture, 2> kPostures{{{StartPosture::fixed, "fixed"}, {StartPosture::free, "free"}}};
constexpr NameTable<Elbow, 2> kElbows{{{Elbow::positive, "elbow_down"}, {Elbow::negative, "elbow_up"}}};
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
std::string_view to_string(Elbow e) { return name_of(kElbows, e); }
bool parse(std::string_view n, Elbow& out) { return value_of(kElbows, n, out); }
bool parse(std::string_view n, OnViolation& out) { return value_of(kOnViolation, n, out); }
std::string_view to_string(GlobalObjective v) { return name_of(kObjectives, v); }
std::string_view to_string(AlphaSpline v) { return name_of(kSplines, v); }
std::string_view to_string(GlobalStart v) { return name_of(kStarts, v); }
std::string_view to_string(StartPosture v) { return name_of(kPostures, v); }
bool parse(std::string_view n, GlobalObjective& out) { return value_of(kObjectives, n, out); }
bool parse(std::string_view n, AlphaSpline& out) { return value_of(kSplines, n, out); }
bool parse(std::string_view n, GlobalStart& out) { return value_of(kStarts, n, out); }
bool parse(std::string_view n, StartPosture& out) { return value_of(kPostures, n, out); }
std::string_view to_string(EndState v) { return name_of(kEnds, v); }
bool parse(std::string_view n, EndState& out) { return value_of(kEnds, n, out); }
std::string_view to_string(Extension v) { return name_of(kExtensions, v); }
bool parse(std::string_view n, Extension& out) { return value_of(kExtensions, n, out); }
std::string_view to_string(StartMethod v) { return name_of(kStartMethods, v); }
bool parse(std::string_view n, StartMethod& out) { return value_of(kStartMethods, n, out); }

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
                     {"orientation_bound", orientation_bound, bound_rule},
                     {"end_window", end_window, end_window_rule},
                     {"end_gain", end_gain, end_gain_rule}},
                    why))
    return false;
  if (method == TrajectoryMethod::global_spline && !global.IsValid(why)) return false;
  for (double a : vertex_alpha)
    if (!std::isfinite(a)) {
      if (why) *why = "vertex_alpha has a value that is not finite; expected finite angles [rad]";
      return false;
    }
  return true;
}

}  // namespace ks
