#pragma once
// First-order and total Sobol' indices from the runs of a Saltelli design (space.hpp:
// saltelli_draws), with bootstrap confidence intervals.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace ks {

/// How sobol_indices estimates its intervals. Defaults written once here.
struct SobolOptions {
  int bootstrap = 1000;       ///< resamples of the N sample rows (0: no intervals)
  double confidence = 0.95;   ///< the intervals' level, in (0, 1)
  std::uint64_t seed = 1;     ///< of the resampling
  bool IsValid(std::string* why) const;
};

/// Indices of d factors, each with its [lo, hi] percentile bootstrap interval.
struct SobolIndices {
  std::vector<double> first, first_lo, first_hi;  ///< S_i (Saltelli 2010: mean of (f(B) - m)(f(AB_i) - f(A)) / V, m the mean over A and B)
  std::vector<double> total, total_lo, total_hi;  ///< S_Ti (Jansen: mean of (f(A) - f(AB_i))^2 / 2 / V)
  double variance = 0.0;                          ///< V: the output's variance over A and B
  std::uint64_t samples = 0;   ///< sample rows used (all of their d + 2 values finite)
  std::uint64_t dropped = 0;   ///< sample rows left out: a value of the row is not finite (a failed run)
};

/// The indices of the d = ab.size() factors from the outputs of a Saltelli design's N sample rows:
/// a[j] = f(A_j), b[j] = f(B_j), ab[i][j] = f(AB_i,j) (each of length N). A row with a non-finite
/// value anywhere (a run with a failed status is passed as NaN) is dropped and counted in `dropped`.
/// Throws std::invalid_argument for invalid options or lengths that differ.
SobolIndices sobol_indices(std::span<const double> a, std::span<const double> b,
                           const std::vector<std::span<const double>>& ab, const SobolOptions& options = {});

}  // namespace ks
