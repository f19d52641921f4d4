#pragma once
// The 21 rows of Table 4 of seed 000: each case's parameters (the thesis' printed optimum for the
// optimised rows) and the thesis' own figures, for presets in study files and for comparison.
#include <array>
#include <span>
#include <string_view>

#include "methods/base/trajectory.hpp"

namespace ks {

struct SeedCase {
  std::string_view name;        ///< "1a" ... "5c"
  std::string_view situation;   ///< the thesis' description of the row
  TrajectoryMethod method;
  double k;                     ///< gravity weight
  double alpha1A_deg;           ///< start orientation [deg]
  std::array<double, 4> vertex_alpha_deg;  ///< alpha at vertices 2, 3, 4, 1 (vertex_alpha only) [deg]
  double E;                     ///< thesis: mean sqrt(tau^T tau) [Nm]
  std::array<double, 3> tau_inf;  ///< thesis: max |tau_i| [Nm]

  /// Run options of this case (seed defaults for everything else).
  TrajectoryOptions options() const;
  /// Largest relative deviation of (E, tau_inf) from this row's printed figures (0.01 = 1 %).
  double worst_deviation(double E_other, const double (&tau_other)[3]) const;
};

/// All 21 rows, in the thesis' order.
std::span<const SeedCase> seed_cases();
/// The row named `name`, or nullptr.
const SeedCase* find_seed_case(std::string_view name);

}  // namespace ks
