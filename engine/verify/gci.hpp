#pragma once
// Solution verification of one quantity against its grid (Roache 1998; Celik et al. 2008, the
// procedure ASME V&V 20 adopts): the quantity computed on three grids of a constant refinement ratio
// r (time steps dt, dt/2, dt/4; or spline knots K, 2K, 4K) gives its observed order of convergence,
// a Richardson extrapolation of the grid-converged value, and the grid convergence index (GCI), an
// error band that contains the grid-converged value with about 95 % confidence.
#include <string>
#include <string_view>

#include "common/domain.hpp"

namespace ks {

/// How three grid values behave, from the ratio R = (f2 - f1) / (f3 - f2) of their changes.
enum class Convergence {
  monotone,     ///< 0 <= R < 1: the changes shrink without changing sign; order, value and GCI are given
  unchanged,    ///< the three values are equal: the quantity does not depend on the grid (GCI 0)
  oscillatory,  ///< R < 0: the changes alternate in sign; no order, no extrapolation, no GCI
  divergent,    ///< R >= 1: the changes do not shrink; no order, no extrapolation, no GCI
  not_enough,   ///< a value is missing or not finite (a refined run failed), or r <= 1
};
std::string_view to_string(Convergence c);
bool parse(std::string_view name, Convergence& out);

/// Options of the grid convergence index.
struct GciOptions {
  /// Roache's factor of safety for a study of three grids with an observed order.
  double safety_factor = 1.25;
  static constexpr Domain safety_factor_rule = Domain::at_least(1.0);
  bool IsValid(std::string* why = nullptr) const {
    return fields_valid({{"safety_factor", safety_factor, safety_factor_rule}}, why);
  }
};

/// The grid study of one quantity. Grid 1 is the finest (dt/4 or 4K), grid 3 the coarsest (the run
/// as stored: dt or K). NaN wherever `convergence` says the figure does not exist.
struct GciResult {
  Convergence convergence = Convergence::not_enough;
  double ratio = 0.0;  ///< R = (f2 - f1) / (f3 - f2) (NaN when both changes are 0 or a value is missing)
  double order = 0.0;  ///< observed order p = ln((f3 - f2) / (f2 - f1)) / ln r (monotone; +inf when f1 = f2)
  /// Richardson extrapolation f1 + (f1 - f2) / (r^p - 1) [the quantity's unit] (monotone, unchanged)
  double extrapolated = 0.0;
  /// Fine-grid GCI: Fs |(f1 - f2) / f1| / (r^p - 1), relative (0.01 = 1 %): the band about f1
  double gci_fine = 0.0;
  /// The GCI of the coarsest grid, the run's own: Fs |(f3 - f2) / f3| r^p / (r^p - 1), relative:
  /// the band about f3 that the grid-converged value lies in
  double gci_coarse = 0.0;
};

/// The grid study of values f1 (finest grid), f2, f3 (coarsest) computed on grids refined by the
/// constant ratio r > 1 (f3's grid is r times f2's, which is r times f1's). Never throws; a value
/// that is not finite, or r <= 1, gives not_enough. A relative GCI of a value 0 is +inf.
GciResult grid_convergence(double f1, double f2, double f3, double r, const GciOptions& options = {});

}  // namespace ks
