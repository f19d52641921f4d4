#include "methods/closed_form/seed_cases.hpp"

#include "common/angles.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ks {
namespace {
constexpr auto W = TrajectoryMethod::local_weighted;
constexpr auto U = TrajectoryMethod::local_unweighted;
constexpr auto V = TrajectoryMethod::vertex_alpha;
constexpr std::array<double, 4> none{0, 0, 0, 0};
constexpr std::array<double, 4> case5{60.0, 45.0, 22.5, 18.0};

// Table 4 of seed 000 (see ../shared/seeds/NOTES.md).
constexpr std::array<SeedCase, 21> kCases{{
    {"1a", "k = 0; alpha1A = 0", W, 0.0, 0.0, none, 51.03, {82.63, 32.31, 8.77}},
    {"1b", "k_opt = 0; alpha1A = 0", W, 0.0, 0.0, none, 51.03, {82.63, 32.31, 8.77}},
    {"1c", "k = 0; alpha1A = 15", W, 0.0, 15.0, none, 55.77, {79.09, 33.26, 8.41}},
    {"1d", "k_opt = 0.57; alpha1A = 15", W, 0.57, 15.0, none, 51.70, {627.76, 111.32, 12.21}},
    {"1e", "k = 0; alpha1A = 30", W, 0.0, 30.0, none, 62.27, {93.33, 42.30, 7.21}},
    {"1f", "k_opt = 0.16; alpha1A = 30", W, 0.16, 30.0, none, 54.32, {215.59, 50.28, 9.52}},
    {"1g", "k = 0; alpha1A_opt = -23.5", W, 0.0, -23.5, none, 38.63, {101.39, 45.40, 8.78}},
    {"1h", "k_opt = 0.13; alpha1A_opt = -24.1", W, 0.13, -24.1, none, 37.79, {109.44, 48.33, 8.79}},
    {"2a", "k = 0; alpha1A = 0", U, 0.0, 0.0, none, 48.63, {50.33, 30.00, 8.71}},
    {"2b", "k_opt = 0; alpha1A = 0", U, 0.0, 0.0, none, 48.63, {50.33, 30.00, 8.71}},
    {"2c", "k = 0; alpha1A = 15", U, 0.0, 15.0, none, 54.09, {57.32, 29.14, 8.61}},
    {"2d", "k_opt = 0.75; alpha1A = 15", U, 0.75, 15.0, none, 54.07, {5301.60, 2135.90, 263.50}},
    {"2e", "k = 0; alpha1A = 30", U, 0.0, 30.0, none, 61.04, {387.90, 153.58, 22.35}},
    {"2f", "k_opt = 0.18; alpha1A = 30", U, 0.18, 30.0, none, 54.83, {1076.50, 401.30, 49.40}},
    {"2g", "k = 0; alpha1A_opt = -20.1", U, 0.0, -20.1, none, 39.41, {59.77, 51.65, 8.95}},
    {"2h", "k_opt = 0.06; alpha1A_opt = -23.5", U, 0.06, -23.5, none, 37.41, {90.23, 60.75, 10.30}},
    {"3", "global, weighted; optimal vertex alpha", V, 0.0, -18.9, {9.2, 18.9, -10.9, -18.9}, 53.58,
     {139.75, 35.49, 8.56}},
    {"4", "global, unweighted; optimal vertex alpha", V, 0.0, -18.3, {18.3, 18.9, -10.3, -8.6}, 48.39,
     {116.40, 30.83, 8.58}},
    {"5a", "non-redundant; alpha1A = 0", V, 0.0, 0.0, case5, 66.65, {178.82, 28.20, 8.26}},
    {"5b", "non-redundant; alpha1A = 15", V, 0.0, 15.0, case5, 60.81, {121.11, 28.22, 8.26}},
    {"5c", "non-redundant; alpha1A = 30", V, 0.0, 30.0, case5, 60.05, {107.88, 28.23, 8.26}},
}};
}  // namespace

TrajectoryOptions SeedCase::options() const {
  TrajectoryOptions o;
  o.method = method;
  o.k = k;
  o.alpha1A = alpha1A_deg * kDeg;
  if (method == TrajectoryMethod::vertex_alpha)
    for (double a : vertex_alpha_deg) o.vertex_alpha.push_back(a * kDeg);
  return o;
}

double SeedCase::worst_deviation(double E_other, const double (&tau_other)[3]) const {
  double d = std::abs(E_other / E - 1.0);
  for (int i = 0; i < 3; ++i) d = std::max(d, std::abs(tau_other[i] / tau_inf[i] - 1.0));
  return d;
}

std::span<const SeedCase> seed_cases() { return kCases; }

const SeedCase* find_seed_case(std::string_view name) {
  for (const auto& c : kCases)
    if (c.name == name) return &c;
  return nullptr;
}

}  // namespace ks
