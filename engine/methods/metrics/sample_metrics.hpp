#pragma once
// Trajectory metrics declared as a reduction over the samples of a run: one entry each, with its
// name, unit, description, display label, reduction and the line that computes its per-sample value from the sample
// state. The three trajectory loops (the closed-form 3R kernel over SIMD lanes, the chain loop, the
// fixed-size planar-chain loop) hand every sample's state to SampleSums (methods/metrics/sample_sums.hpp),
// which reduces each entry; finish_run stores the results in TrajectoryMetrics::sampled; the run
// table (schema/trajectory_table.cpp) makes each entry a /runs column. Adding such a metric is one
// entry below and nothing else.
//
// A value is computed for every lane at once (T: double or a lane type of model/lanes.hpp), so it
// uses only + - * /, vabs, vsqrt, vmin, vmax and select. The metrics that need more than one
// reduction of one value (E's blocked square roots, the trapezoidal integrals, the per-joint peaks,
// the limit ratios and the tracking bound) are written out in SampleSums.
#include <array>
#include <limits>
#include <string_view>
#include <tuple>
#include <utility>

#include "methods/base/trajectory.hpp"
#include "model/lanes.hpp"

namespace ks {

/// What one sample gives the sums, per lane (T: double or a lane type of model/lanes.hpp): the raw
/// state in the chain's joint coordinates and the values every loop derives on its way.
template <class T>
struct SampleValues {
  int n = 0;              ///< joints
  const T* q = nullptr;   ///< joint positions (n) [rad or m]
  const T* qd = nullptr;  ///< joint velocities (n) [rad/s or m/s]
  const T* tau = nullptr; ///< joint torques (revolute) and forces (prismatic) (n) [Nm or N]
  T tt;                   ///< tau^T tau over the revolute joints [N^2 m^2]
  T ff;                   ///< f^T f over the prismatic joints [N^2] (0 when none)
  T qf, det;              ///< tau^T M^-1 tau = qf / det
  T p6;                   ///< sum (tau_i qd_i)^2 [W^2]
  T w2;                   ///< squared manipulability det(J J^T) [m^4]
  T err2;                 ///< squared tip position error [m^2]
  T orient;               ///< |orientation error| [rad] (0 for position tasks)
  T alpha;                ///< tip angle [rad] (NaN for spatial tasks)
  T ke;                   ///< kinetic energy qd^T M(q) qd / 2 [J]
};

/// How the per-sample values of a metric become the run's value (an empty run: NaN).
enum class Reduce {
  mean,  ///< sum / samples
  max,   ///< largest (std::max semantics: a NaN value is skipped)
  min,   ///< smallest (std::min semantics)
  last,  ///< the value at the last sample computed (the run's end state)
};

/// One metric: what /runs shows (name, unit, description, display label, whether landscapes grid
/// it), how the samples reduce, and `value(v)` the value of sample v (SampleValues).
template <class F>
struct SampleMetric {
  std::string_view name, unit, description, label;
  bool gridded;
  Reduce reduce;
  F value;
};
template <class F>
SampleMetric(std::string_view, std::string_view, std::string_view, std::string_view, bool, Reduce, F) -> SampleMetric<F>;

/// The table. Values must be written for any T (see the header comment).
inline constexpr auto kSampleMetrics = std::tuple{
    SampleMetric{"peak_joint_power", "W", "max over samples and joints of |tau_i qd_i| (actuator power)",
                 "peak joint power", true,
                 Reduce::max,
                 [](const auto& s) {
                   auto p = vabs(s.tau[0] * s.qd[0]);
                   for (int j = 1; j < s.n; ++j) p = vmax(p, vabs(s.tau[j] * s.qd[j]));
                   return p;
                 }},
    SampleMetric{"end_qd_max", "rad/s", "max over joints of |qd_i| at the last sample (the arm's motion at the end)",
                 "end joint rate", false, Reduce::last,
                 [](const auto& s) {
                   auto m = vabs(s.qd[0]);
                   for (int j = 1; j < s.n; ++j) m = vmax(m, vabs(s.qd[j]));
                   return m;
                 }},
    SampleMetric{"end_kinetic_energy", "J", "kinetic energy qd^T M qd / 2 at the last sample", "end kinetic energy",
                 false, Reduce::last, [](const auto& s) { return s.ke; }},
};

inline constexpr int kSampleMetricCount = static_cast<int>(std::tuple_size_v<decltype(kSampleMetrics)>);
static_assert(kSampleMetricCount <= kMaxSampleMetrics, "raise kMaxSampleMetrics (methods/base/trajectory.hpp)");

/// Calls f(entry, index) for every entry, in table order.
template <class F>
constexpr void for_each_sample_metric(F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (f(std::get<I>(kSampleMetrics), static_cast<int>(I)), ...);
  }(std::make_index_sequence<kSampleMetricCount>());
}

/// Index of the entry named `name` in the table, -1 when none.
constexpr int sample_metric_index(std::string_view name) {
  int found = -1;
  for_each_sample_metric([&](const auto& m, int i) {
    if (m.name == name) found = i;
  });
  return found;
}

/// The value a reduction starts from.
constexpr double reduce_start(Reduce r) {
  return r == Reduce::mean  ? 0.0
         : r == Reduce::max ? -std::numeric_limits<double>::infinity()
         : r == Reduce::min ? std::numeric_limits<double>::infinity()
                            : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace ks
