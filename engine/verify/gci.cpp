// Roache's grid convergence index of three grid values (see gci.hpp).
#include "verify/gci.hpp"

#include <array>
#include <cmath>
#include <limits>

namespace ks {

namespace {
constexpr std::array<std::string_view, 5> kNames{"monotone", "unchanged", "oscillatory", "divergent", "not_enough"};
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// |a / b|, +inf when b is 0 and a is not.
double relative(double a, double b) { return a == 0.0 ? 0.0 : b == 0.0 ? kInf : std::abs(a / b); }
}  // namespace

std::string_view to_string(Convergence c) { return kNames[static_cast<std::size_t>(c)]; }

bool parse(std::string_view name, Convergence& out) {
  for (std::size_t i = 0; i < kNames.size(); ++i)
    if (kNames[i] == name) {
      out = static_cast<Convergence>(i);
      return true;
    }
  return false;
}

GciResult grid_convergence(double f1, double f2, double f3, double r, const GciOptions& options) {
  GciResult g;
  g.ratio = g.order = g.extrapolated = g.gci_fine = g.gci_coarse = kNaN;
  if (!std::isfinite(f1) || !std::isfinite(f2) || !std::isfinite(f3) || !(r > 1.0) || !std::isfinite(r) ||
      !options.IsValid())
    return g;
  const double e21 = f2 - f1, e32 = f3 - f2;
  if (e21 == 0.0 && e32 == 0.0) {
    g.convergence = Convergence::unchanged;
    g.extrapolated = f1;
    g.gci_fine = g.gci_coarse = 0.0;
    return g;
  }
  if (e32 == 0.0) {  // the coarse pair agrees, the fine pair does not: the changes do not shrink
    g.convergence = Convergence::divergent;
    return g;
  }
  g.ratio = e21 / e32;
  if (g.ratio < 0.0) {
    g.convergence = Convergence::oscillatory;
    return g;
  }
  if (g.ratio >= 1.0) {
    g.convergence = Convergence::divergent;
    return g;
  }
  g.convergence = Convergence::monotone;
  const double fs = options.safety_factor;
  if (e21 == 0.0) {  // the fine pair agrees exactly: order +inf, r^p / (r^p - 1) -> 1
    g.order = kInf;
    g.extrapolated = f1;
    g.gci_fine = 0.0;
    g.gci_coarse = fs * relative(e32, f3);
    return g;
  }
  g.order = std::log(e32 / e21) / std::log(r);
  const double rp = std::pow(r, g.order);  // e32 / e21 up to rounding: > 1
  g.extrapolated = f1 + (f1 - f2) / (rp - 1.0);
  g.gci_fine = fs * relative(e21, f1) / (rp - 1.0);
  g.gci_coarse = fs * relative(e32, f3) * rp / (rp - 1.0);
  return g;
}

}  // namespace ks
