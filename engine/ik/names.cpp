// Names of the IK methods and statuses (the CLI, study-file and HDF5 names).
#include "common/name_table.hpp"

#include "ik/solve.hpp"

namespace ks::ik {
namespace {
constexpr NameTable<Method, 6> kMethods{{{Method::newton, "newton"},
                                     {Method::lm, "lm"},
                                     {Method::lm_adaptive, "lm_adaptive"},
                                     {Method::halley_thesis, "halley_thesis"},
                                     {Method::halley, "halley"},
                                     {Method::analytic, "analytic"}}};
constexpr NameTable<Status, 9> kStatuses{{{Status::converged, "converged"},
                                      {Status::stalled, "stalled"},
                                      {Status::singular, "singular"},
                                      {Status::max_iter, "max_iter"},
                                      {Status::cycle, "cycle"},
                                      {Status::diverged, "diverged"},
                                      {Status::unsupported, "unsupported"},
                                      {Status::no_solution, "no_solution"},
                                      {Status::out_of_limits, "out_of_limits"}}};
constexpr NameTable<JointLimits, 3> kJointLimits{{{JointLimits::none, "none"},
                                              {JointLimits::clamp, "clamp"},
                                              {JointLimits::reject, "reject"}}};

}  // namespace

std::string_view to_string(Method m) { return name_of(kMethods, m); }
std::string_view to_string(Status s) { return name_of(kStatuses, s); }
std::string_view to_string(JointLimits l) { return name_of(kJointLimits, l); }
bool parse(std::string_view n, Method& out) { return value_of(kMethods, n, out); }
bool parse(std::string_view n, Status& out) { return value_of(kStatuses, n, out); }
bool parse(std::string_view n, JointLimits& out) { return value_of(kJointLimits, n, out); }

}  // namespace ks::ik
