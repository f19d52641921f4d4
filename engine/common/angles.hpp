#pragma once
// Angle helpers: degrees to radians (the one conversion of study files, presets and defaults; stored
// angles are rad) and wrapping to (-pi, pi].
#include <cmath>
#include <numbers>

namespace ks {
inline constexpr double kDeg = std::numbers::pi / 180.0;

/// x wrapped to (-pi, pi] (exact: x itself when already inside, else std::remainder).
inline double wrap_angle(double x) {
  constexpr double kPi = std::numbers::pi;
  if (x > -kPi && x <= kPi) return x;  // the common case, without a libm call
  const double r = std::remainder(x, 2.0 * kPi);  // exact, in [-pi, pi]
  return r == -kPi ? kPi : r;
}

/// std::remainder(x, 2 pi): x wrapped to [-pi, pi] (either end possible, unlike wrap_angle).
inline double remainder_2pi(double x) { return std::remainder(x, 2.0 * std::numbers::pi); }
}  // namespace ks
