#pragma once
// The running sums behind a trajectory run's metrics, shared by the closed-form run and the chains'.
#include <cmath>
#include <cstddef>

#include "methods/base/trajectory.hpp"

namespace ks {

/// The square roots and divisions of E and E_M, taken a block of samples at a time: in the step they
/// would compete for the divider with the step's own division and hold the out-of-order window
/// behind them; a block runs back to back, vectorised. The sums are taken in sample order, so the
/// result is the same as summing sample by sample.
class RootSums {
 public:
  RootSums() {
    for (double& d : det_) d = 1.0;  // the unfilled tail of a last, partial block stays harmless
  }
  /// tt = tau^T tau; qf / det = tau^T M^-1 tau (det = 1 when qf is the form itself: x / 1 is exact).
  void add(double tt, double qf, double det = 1.0) {
    tt_[n_] = tt;
    qf_[n_] = qf;
    det_[n_] = det;
    if (++n_ == kBlock) flush();
  }
  void flush() {
    alignas(32) double e[kBlock], em[kBlock];
    for (int j = 0; j < kBlock; ++j) {  // whole block: fixed trip count, vectorised
      e[j] = std::sqrt(tt_[j]);
      em[j] = std::sqrt(qf_[j] / det_[j]);
    }
    for (int j = 0; j < n_; ++j) {
      sumE += e[j];
      sumEM += em[j];
    }
    n_ = 0;
  }
  double sumE = 0, sumEM = 0;

 private:
  static constexpr int kBlock = 32;
  alignas(32) double tt_[kBlock] = {}, qf_[kBlock] = {}, det_[kBlock];
  int n_ = 0;
};

/// Trapezoidal integrals of sum tau_i^2 and sum (tau_i qd_i)^2 over the samples (seed 002's f5, f6):
/// the sums of every sample, half of the first and the last taken off at the end.
struct TrapezoidSums {
  double f5 = 0, f6 = 0, first5 = 0, first6 = 0, last5 = 0, last6 = 0;
  /// Sample i's tau^T tau and sum (tau_i qd_i)^2.
  void add(std::size_t i, double tt, double p6) {
    f5 += tt;
    f6 += p6;
    if (i == 0) {
      first5 = tt;
      first6 = p6;
    }
    last5 = tt;
    last6 = p6;
  }
  double torque(double dt) const { return dt * (f5 - 0.5 * (first5 + last5)); }  ///< [N^2 m^2 s]
  double power(double dt) const { return dt * (f6 - 0.5 * (first6 + last6)); }   ///< [W^2 s]
};

}  // namespace ks
