#pragma once
// What the 3R path-global tests and benchmarks start from: the thesis' case 4 alpha(t) (seed 000's
// printed vertex angles, a quintic per side) in a problem's coordinate, fitted by a basis. Within the
// arm's reach at every sample of the seed square.
#include <vector>

#include "methods/path_global/alpha_basis.hpp"
#include "methods/path_global/closed_form.hpp"

namespace ks {

/// The coefficients of `b` nearest (least squares) to case 4's alpha(t) in `problem`'s coordinate.
inline std::vector<double> case4_fit(const PathGlobalProblem& problem, const SampledPath& path, const AlphaBasis& b) {
  constexpr double deg = 3.14159265358979323846 / 180.0;
  const std::vector<double> thesis4{-18.3 * deg, 18.3 * deg, 18.9 * deg, -10.3 * deg, -8.6 * deg};
  const AlphaBasis v = vertex_quintic_basis(path);
  std::vector<double> x(path.size());
  for (std::size_t i = 0; i < path.size(); ++i) {
    double a, ad, add;
    v.at(i, thesis4.data(), a, ad, add);
    x[i] = problem.coordinate(i, a, Elbow::positive);
  }
  return fit_basis(b, x.data(), x.size());
}

}  // namespace ks
