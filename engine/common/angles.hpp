#pragma once
// Degrees to radians: the one conversion of study files, presets and defaults (stored angles are rad).
#include <numbers>

namespace ks {
inline constexpr double kDeg = std::numbers::pi / 180.0;
}  // namespace ks
