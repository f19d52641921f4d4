#pragma once
// A redundant coordinate of the path-global method (the tip angle alpha of a planar arm on a position
// task) as a linear function of a few coefficients, sampled at the path's sample times: at sample i,
// alpha, its rate and its acceleration are weighted sums of at most kBasisWidth consecutive
// coefficients. Two families share this form, so one evaluator serves both:
// - vertex_quintic: the coefficients are alpha at the path's vertices, each segment a quintic between
//   them with zero rate and acceleration at the vertices (seed 000's cases 3-5, TaskPath<1>);
// - cubic: a clamped uniform cubic B-spline over the whole path (C2), `knots` breakpoints evenly spaced
//   in time, at rest at the start (zero rate) and, unless asked otherwise, at the end; its coefficients
//   are the B-spline's control points with the first two (and the last two) tied, so there are exactly
//   `knots` of them (knots + 1 with a free end).
#include <cstddef>
#include <vector>

#include "task/sampled_path.hpp"

namespace ks {

inline constexpr int kBasisWidth = 4;

/// The weights of one sample: alpha^(d) = sum_k w[d][k] c[first + k], d = 0, 1, 2 (value [rad], rate
/// [rad/s], acceleration [rad/s^2] per radian of coefficient); k beyond the last coefficient has w = 0.
struct BasisRow {
  int first = 0;
  double w[3][kBasisWidth] = {};
};

struct AlphaBasis {
  int coefficients = 0;        ///< number of coefficients [rad each]
  std::vector<BasisRow> rows;  ///< one per sample of the path

  /// alpha, rate and acceleration at sample i for coefficients c (size `coefficients`).
  void at(std::size_t i, const double* c, double& a, double& ad, double& add) const {
    const BasisRow& r = rows[i];
    a = ad = add = 0.0;
    if (r.first + kBasisWidth <= coefficients) {  // every row but the last few: a fixed-size loop
      for (int k = 0; k < kBasisWidth; ++k) {
        const double x = c[r.first + k];
        a += r.w[0][k] * x;
        ad += r.w[1][k] * x;
        add += r.w[2][k] * x;
      }
      return;
    }
    for (int k = 0; k < kBasisWidth && r.first + k < coefficients; ++k) {
      const double x = c[r.first + k];
      a += r.w[0][k] * x;
      ad += r.w[1][k] * x;
      add += r.w[2][k] * x;
    }
  }
  /// grad[first_i + k] += partial[d][i] w_i[d][k] over the samples i in order and d = 0, 1, 2 (the
  /// chain rule of per-sample terms whose partials with respect to alpha, its rate and acceleration
  /// are partial[d][i]). The running sums of a row's coefficients stay in registers while consecutive
  /// rows share their first coefficient: the same additions in the same order as through memory.
  void add_gradients(const double* const partial[3], double* grad) const {
    int first = -1, width = 0;
    double g[kBasisWidth] = {};
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const BasisRow& r = rows[i];
      if (r.first != first) {
        for (int k = 0; k < width; ++k) grad[first + k] = g[k];
        first = r.first;
        width = first + kBasisWidth <= coefficients ? kBasisWidth : coefficients - first;
        for (int k = 0; k < width; ++k) g[k] = grad[first + k];
      }
      if (width == kBasisWidth) {
        for (int d = 0; d < 3; ++d)
          for (int k = 0; k < kBasisWidth; ++k) g[k] += partial[d][i] * r.w[d][k];
      } else {
        for (int d = 0; d < 3; ++d)
          for (int k = 0; k < width; ++k) g[k] += partial[d][i] * r.w[d][k];
      }
    }
    for (int k = 0; k < width; ++k) grad[first + k] = g[k];
  }
};

/// The vertex-quintic family on `path`'s samples: coefficients = alpha at vertices 1..n (n = vertices).
AlphaBasis vertex_quintic_basis(const SampledPath& path);
/// The clamped cubic B-spline with `knots` >= 2 breakpoints over [0, duration] at rest at the start
/// and, when `rest_at_end`, at the end (then `knots` coefficients, else knots + 1), on `path`'s
/// samples (std::invalid_argument for knots < 2).
AlphaBasis cubic_spline_basis(const SampledPath& path, int knots, bool rest_at_end = true);
/// The same on `samples` samples t_i = i dt [s] of a path of `duration` [s] (any sampled path).
AlphaBasis cubic_spline_basis(std::size_t samples, double dt, double duration, int knots, bool rest_at_end = true);

/// Least-squares coefficients of `basis` for the samples alpha[0 .. count) [rad] (count <= rows);
/// coefficients with no weight on those samples keep the last fitted value before them.
std::vector<double> fit_basis(const AlphaBasis& basis, const double* alpha, std::size_t count);

}  // namespace ks
