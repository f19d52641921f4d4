#pragma once
// LDL^T factor of a symmetric positive-definite matrix of compile-time size N, in plain loops over
// fixed-size arrays that the compiler unrolls completely: the factor of a chain's inertia matrix M
// (N x N) and of the task-space matrix A = J W^-1 J^T (m x m) in the planar chain kernel
// (methods/chain/planar_run.hpp). N divisions per factor, one per pivot; the solves multiply by the
// pivots' reciprocals.
#include <limits>

namespace ks {

/// A = L D L^T with L unit lower triangular. A pivot that is not positive (or not finite) becomes
/// NaN, which every solve carries to its output.
template <int N>
struct FixedLdlt {
  double L[N][N];   ///< strictly lower triangle: L[i][j] for j < i (unit diagonal, not stored)
  double d[N];      ///< D_i
  double inv_d[N];  ///< 1 / D_i

  /// Factor A, read through its lower triangle A[i][j], j <= i.
  [[gnu::always_inline]] void compute(const double (&A)[N][N]) {
    for (int j = 0; j < N; ++j) {
      double LD[N];  // L[j][k] D_k of row j
      double dj = A[j][j];
      for (int k = 0; k < j; ++k) {
        LD[k] = L[j][k] * d[k];
        dj -= L[j][k] * LD[k];
      }
      d[j] = dj;
      inv_d[j] = dj > 0.0 ? 1.0 / dj : std::numeric_limits<double>::quiet_NaN();
      for (int i = j + 1; i < N; ++i) {
        double s = A[i][j];
        for (int k = 0; k < j; ++k) s -= L[i][k] * LD[k];
        L[i][j] = s * inv_d[j];
      }
    }
  }
  /// x <- L^-1 x (N values).
  [[gnu::always_inline]] void forward(double* x) const {
    for (int i = 1; i < N; ++i) {
      double s = x[i];
      for (int k = 0; k < i; ++k) s -= L[i][k] * x[k];
      x[i] = s;
    }
  }
  /// x <- L^-T x.
  [[gnu::always_inline]] void backward(double* x) const {
    for (int i = N - 2; i >= 0; --i) {
      double s = x[i];
      for (int k = i + 1; k < N; ++k) s -= L[k][i] * x[k];
      x[i] = s;
    }
  }
  /// x <- A^-1 x.
  [[gnu::always_inline]] void solve(double* x) const {
    forward(x);
    for (int i = 0; i < N; ++i) x[i] *= inv_d[i];
    backward(x);
  }
  /// x^T A^-1 x; x is overwritten with L^-1 x.
  [[gnu::always_inline]] double inverse_quadratic_form(double* x) const {
    forward(x);
    double q = 0;
    for (int i = 0; i < N; ++i) q += x[i] * x[i] * inv_d[i];
    return q;
  }
};

}  // namespace ks
