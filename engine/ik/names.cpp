// Names of the IK methods and statuses (the CLI, study-file and HDF5 names).
#include <array>
#include <utility>

#include "ik/solve.hpp"

namespace ks::ik {
namespace {
template <class E, std::size_t N>
using Table = std::array<std::pair<E, std::string_view>, N>;

constexpr Table<Method, 6> kMethods{{{Method::newton, "newton"},
                                     {Method::lm, "lm"},
                                     {Method::lm_adaptive, "lm_adaptive"},
                                     {Method::halley_thesis, "halley_thesis"},
                                     {Method::halley, "halley"},
                                     {Method::analytic, "analytic"}}};
constexpr Table<Status, 8> kStatuses{{{Status::converged, "converged"},
                                      {Status::stalled, "stalled"},
                                      {Status::singular, "singular"},
                                      {Status::max_iter, "max_iter"},
                                      {Status::cycle, "cycle"},
                                      {Status::diverged, "diverged"},
                                      {Status::unsupported, "unsupported"},
                                      {Status::no_solution, "no_solution"}}};

template <class E, std::size_t N>
std::string_view name_of(const Table<E, N>& t, E e) {
  for (const auto& [v, n] : t)
    if (v == e) return n;
  return "?";
}
template <class E, std::size_t N>
bool value_of(const Table<E, N>& t, std::string_view name, E& out) {
  for (const auto& [v, n] : t)
    if (n == name) {
      out = v;
      return true;
    }
  return false;
}
}  // namespace

std::string_view to_string(Method m) { return name_of(kMethods, m); }
std::string_view to_string(Status s) { return name_of(kStatuses, s); }
bool parse(std::string_view n, Method& out) { return value_of(kMethods, n, out); }
bool parse(std::string_view n, Status& out) { return value_of(kStatuses, n, out); }

}  // namespace ks::ik
