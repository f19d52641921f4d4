#pragma once
// The IK cycle check as it was written before ik/cycle_watch.hpp: the oracle of test_ik_cycle and the
// baseline of bench_ik_cycle. Kept verbatim; do not optimise it.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "ik/problem.hpp"

namespace ks::test {

using ik::Vec;

/// The cycle check as it was before ik/cycle_watch.hpp, verbatim: every lag within the window, the
/// 0.1 % error filter, then the wrapped distance's norm against tol and the path.
template <int N>
struct PlainCycleWatch {
  static constexpr int kCapacity = 17;
  std::array<Vec<N>, kCapacity> q;
  std::array<double, kCapacity> path;
  std::array<double, kCapacity> error;
  int window = 0;
  int newest = -1;
  long count = 0;
  double travelled = 0.0;
  double best_error = std::numeric_limits<double>::infinity();

  void push(const Vec<N>& qk, double step, double e) {
    travelled += step;
    newest = newest + 1 == kCapacity ? 0 : newest + 1;
    q[newest] = qk;
    path[newest] = travelled;
    error[newest] = e;
    ++count;
  }
  bool returned(const std::array<bool, N>& revolute, double tolerance) {
    const double e = error[newest];
    const bool progress = e < 0.5 * best_error;
    best_error = std::min(best_error, e);
    if (progress) return false;
    const Vec<N>& qk = q[newest];
    const double tol = tolerance * std::max(1.0, qk.norm());
    for (int p = 2; p <= window && p < count; ++p) {
      const int i = newest - p < 0 ? newest - p + kCapacity : newest - p;
      if (!(std::abs(e - error[i]) <= 1e-3 * error[i])) continue;
      const double d = ik::joint_difference<N>(qk, q[i], revolute).norm();
      if (d <= tol && travelled - path[i] > 1000.0 * d) return true;
    }
    return false;
  }
};

}  // namespace ks::test
