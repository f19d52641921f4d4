#pragma once
// A number as the tables print it: 6 significant digits (%.6g), "nan", "inf", "-inf".
#include <cmath>
#include <cstdio>
#include <string>

namespace ks {

inline std::string format_double(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace ks
