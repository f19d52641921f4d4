#pragma once
// The joint whose range a second run widens most over a first one (path-global limit tests).
#include <tuple>

#include "methods/chain/trajectory.hpp"

/// The joint whose largest |q| over history `wide` exceeds its largest over `base` the most, with
/// those two largest values [rad]: {joint, base's, wide's}.
inline std::tuple<int, double, double> widest_raise(const ks::ChainHistory& base, const ks::ChainHistory& wide,
                                                    int joints) {
  int j = 0;
  double base_max = 0, wide_max = -1;
  for (int i = 0; i < joints; ++i) {
    const double l = base.q.row(i).head(base.size).cwiseAbs().maxCoeff();
    const double f = wide.q.row(i).head(wide.size).cwiseAbs().maxCoeff();
    if (f - l > wide_max - base_max) j = i, base_max = l, wide_max = f;
  }
  return {j, base_max, wide_max};
}
