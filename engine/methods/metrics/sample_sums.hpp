#pragma once
// The per-sample accumulator of every trajectory loop (the closed-form 3R kernel over SIMD lanes, the
// chain loop, the fixed-size planar-chain loop): each sample's values enter the run's sums here, the
// tracking bound and the joint limits are checked here, and finish_run turns the sums into
// TrajectoryMetrics. A metric that reduces one per-sample value is an entry of the table in
// methods/metrics/sample_metrics.hpp; the others are written out here: a field of RunSums, the line of
// SampleSums::add that updates it and the line of finish_run that reads it.
#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>

#include "methods/metrics/run_sums.hpp"
#include "methods/metrics/sample_metrics.hpp"
#include "methods/base/trajectory.hpp"
#include "model/chain.hpp"
#include "model/lanes.hpp"

namespace ks {

/// A run's joint limits as the loop checks them (built once per run from its chain): position limits
/// as a centre and a half range (joints with both limits finite; others half = inf), velocity and
/// effort limits (inf where none). `any_*` say whether the robot has such a limit at all.
struct LimitTable {
  int n = 0;
  double mid[kMaxJoints] = {}, inv_half[kMaxJoints] = {}, inv_velocity[kMaxJoints] = {}, inv_effort[kMaxJoints] = {};
  bool any_position = false, any_velocity = false, any_effort = false;
  bool any() const { return any_position || any_velocity || any_effort; }

  /// The limits of `chain`'s joints (continuous joints and one-sided limits: no position limit).
  static LimitTable of(const Chain& chain) {
    LimitTable L;
    L.n = chain.dof();
    for (int j = 0; j < L.n; ++j) {
      const ChainJoint& J = chain.joints[j];
      if (std::isfinite(J.lower) && std::isfinite(J.upper) && J.upper > J.lower) {
        L.mid[j] = 0.5 * (J.lower + J.upper);
        L.inv_half[j] = 2.0 / (J.upper - J.lower);
        L.any_position = true;
      }
      if (std::isfinite(J.velocity)) L.inv_velocity[j] = 1.0 / J.velocity, L.any_velocity = true;
      if (std::isfinite(J.effort)) L.inv_effort[j] = 1.0 / J.effort, L.any_effort = true;
    }
    return L;
  }
};

/// A lane's sums when its loop ends (one run's), in doubles.
struct RunSums {
  RunStatus status = RunStatus::ok;  ///< singular / diverged as the loop stopped it, or ok
  RunStatus crossed = RunStatus::ok;  ///< the first bound crossed: off_path, out_of_limits, or ok
  std::size_t done = 0;
  double sumE = 0, sumEM = 0, sumEF = 0, sum_err = 0;
  double inf[kMaxJoints] = {};
  double min_w2 = 0, max_err2 = 0, max_orient = 0, last_alpha = 0, last_t = 0;
  double ratio_q = 0, ratio_qd = 0, ratio_tau = 0;
  /// lanes: the lane stopped before adding a sample, so its Reduce::last entries are not taken yet
  /// (simulate_lanes replays the lane to take them)
  bool last_pending = false;
  TrapezoidSums trapezoid;
  double sampled[kSampleMetricCount > 0 ? kSampleMetricCount : 1] = {};  ///< the table's reductions
};

/// The running sums of a loop over the lanes of T, joints up to N. `keep(updated, old)` (the loop's)
/// gives a lane the updated value while it runs and keeps its old one once it has stopped.
template <class T, int N>
class SampleSums {
 public:
  using M = MaskOf<T>;
  static constexpr bool one = std::is_same_v<T, double>;
  /// The Reduce::last entries are taken at each lane's last sample only (take_last) at 8 lanes, whose
  /// step is bound by throughput; one lane and 4 lanes (bound by the latency of the step's chain) take
  /// them at every sample, in add(), where they cost less (tests/bench/README.md).
  static constexpr bool last_at_end = lanes_of<T> >= 8;

  /// bound: tracking bound [m] and orientation bound [rad] per lane; limits: the run's (T = double
  /// only; null = none).
  SampleSums(const T& tracking_bound, const T& orientation_bound, const LimitTable* limits = nullptr)
      : bound_(tracking_bound), obound_(orientation_bound), limits_(limits) {
    for (T& x : inf) x = T(0.0);
    for_each_sample_metric([&](const auto& m, int k) { sampled_[k] = T(reduce_start(m.reduce)); });
  }

  /// Adds sample i at time t with per-joint |tau_j| in abs_tau (n joints); returns the lanes that
  /// cross the tracking bound at this sample: |tip - path| > bound, the distance itself compared (a
  /// distance equal to the bound is on the path; the limits' crossings: limits()). kForces false: the
  /// model has no prismatic joint (v.ff is 0), so E_force's sum (never read then) and the + 0 in
  /// tau^T tau + f^T f are skipped: the sums are those of ff = 0 bit for bit (tt >= +0, tt + 0 = tt).
  template <bool kForces = true, class Keep>
  M add(std::size_t i, double t, const SampleValues<T>& v, const T* abs_tau, int n, Keep&& keep) {
    T err;
    if constexpr (one) {
      roots_.add(v.tt, v.qf, v.det);
      err = std::sqrt(v.err2);
      sum_err_ += err;
    } else {
      err = vsqrt(v.err2);
      sumE = keep(sumE + vsqrt(v.tt), sumE);
      sumEM = keep(sumEM + vsqrt(v.qf / v.det), sumEM);
      sum_err_ = keep(sum_err_ + err, sum_err_);
    }
    if constexpr (kForces) sumEF = keep(sumEF + vsqrt(v.ff), sumEF);
    for (int j = 0; j < n; ++j) inf[j] = keep(vmax(inf[j], abs_tau[j]), inf[j]);
    min_w2 = keep(vmin(min_w2, v.w2), min_w2);
    max_err2 = keep(vmax(max_err2, v.err2), max_err2);
    max_orient = keep(vmax(max_orient, v.orient), max_orient);
    T tt = v.tt;
    if constexpr (kForces) tt = tt + v.ff;
    f5 = keep(f5 + tt, f5);
    f6 = keep(f6 + v.p6, f6);
    if (i == 0) {
      first5 = keep(tt, first5);
      first6 = keep(v.p6, first6);
    }
    last5 = keep(tt, last5);
    last6 = keep(v.p6, last6);
    last_t = keep(T(t), last_t);
    last_alpha = keep(v.alpha, last_alpha);
    done = keep(done + 1.0, done);
    for_each_sample_metric([&](const auto& m, int k) {
      if (last_at_end && m.reduce == Reduce::last) return;  // take_last(), at a lane's last sample only
      const T x = m.value(v);
      sampled_[k] = keep(m.reduce == Reduce::mean ? sampled_[k] + x
                         : m.reduce == Reduce::max ? vmax(sampled_[k], x)
                         : m.reduce == Reduce::min ? vmin(sampled_[k], x)
                                                   : x,
                         sampled_[k]);
    });
    return (err > bound_) | (v.orient > obound_);
  }

  /// last_at_end: the Reduce::last entries take sample i's values v in the lanes of `ending`, those for
  /// which sample i is the last added (otherwise add() takes them at every sample, as one lane does
  /// before the loop stops after its last). A lane that stops before its sample is added (singular, diverged) has already
  /// moved past its last one: stopped_before_sample() marks it, and its batch is replayed with
  /// replay_last_at() to take them there.
  /// `all`: every lane is in `ending`.
  void take_last(M ending, bool all, const SampleValues<T>& v) {
    static_assert(last_at_end);
    for_each_sample_metric([&](const auto& m, int k) {
      if (m.reduce == Reduce::last) sampled_[k] = all ? m.value(v) : select(ending, m.value(v), sampled_[k]);
    });
  }
  /// Lanes: the lanes whose last sample is sample i (the replay's; none outside a replay).
  M last_here(std::size_t i) const {
    if (!replay_) return M{};
    return T(static_cast<double>(i)) == last_at_;
  }
  bool replaying() const { return replay_; }
  /// Lanes: `lanes` stop at a sample before adding it, after having added at least one.
  void stopped_before_sample(M lanes) { pending_ = pending_ | lanes; }
  /// Lanes: a replay, in which lane l's last sample is index[l] (known from the first pass).
  void replay_last_at(const T& index) { last_at_ = index, replay_ = true; }

  /// T = double: the ratios of sample values q, qd, tau (n joints, actual joint coordinates) to the
  /// limits; true when one is beyond its limit (ratio > 1).
  bool limits(const double* q, const double* qd, const double* tau, int n) {
    static_assert(one);
    if (!limits_) return false;
    const LimitTable& L = *limits_;
    double rq = ratio_q, rv = ratio_qd, rt = ratio_tau;
    for (int j = 0; j < n; ++j) {
      rq = std::max(rq, std::abs(q[j] - L.mid[j]) * L.inv_half[j]);
      rv = std::max(rv, std::abs(qd[j]) * L.inv_velocity[j]);
      rt = std::max(rt, std::abs(tau[j]) * L.inv_effort[j]);
    }
    ratio_q = rq, ratio_qd = rv, ratio_tau = rt;
    return rq > 1.0 || rv > 1.0 || rt > 1.0;
  }

  /// Records the first bound crossed by each lane: `track` the lanes off the path at this sample,
  /// `limit` (T = double) whether a limit was crossed (the same sample: off_path first).
  void mark(M track, bool limit = false) {
    if constexpr (one) {
      if (crossed_ == RunStatus::ok) crossed_ = track ? RunStatus::off_path : limit ? RunStatus::out_of_limits : crossed_;
    } else {
      off_ = off_ | track;
    }
  }

  /// Lane l's sums (the loop's stop status in `status`).
  RunSums of_lane(int l, RunStatus status, int n) {
    if constexpr (one) {
      roots_.flush();
      sumE = roots_.sumE;
      sumEM = roots_.sumEM;
    }
    RunSums r;
    r.status = status;
    if constexpr (one) {
      r.crossed = crossed_;
    } else {
      r.crossed = (bits(off_) >> l & 1) ? RunStatus::off_path : RunStatus::ok;
      r.last_pending = (bits(pending_) >> l & 1) != 0;
    }
    r.done = static_cast<std::size_t>(lane(done, l));
    r.sumE = lane(sumE, l), r.sumEM = lane(sumEM, l), r.sumEF = lane(sumEF, l), r.sum_err = lane(sum_err_, l);
    for (int j = 0; j < n; ++j) r.inf[j] = lane(inf[j], l);
    r.min_w2 = lane(min_w2, l), r.max_err2 = lane(max_err2, l), r.max_orient = lane(max_orient, l);
    r.last_alpha = lane(last_alpha, l), r.last_t = lane(last_t, l);
    r.ratio_q = ratio_q, r.ratio_qd = ratio_qd, r.ratio_tau = ratio_tau;
    TrapezoidSums& z = r.trapezoid;
    z.f5 = lane(f5, l), z.f6 = lane(f6, l), z.first5 = lane(first5, l), z.first6 = lane(first6, l);
    z.last5 = lane(last5, l), z.last6 = lane(last6, l);
    for (int k = 0; k < kSampleMetricCount; ++k) r.sampled[k] = lane(sampled_[k], l);
    return r;
  }

  /// Sets the last tip angle: before any sample (the start's), or after the last one, for a caller
  /// that adds its samples with a placeholder angle and computes the last sample's only at the end.
  void start_alpha(const T& alpha) { last_alpha = alpha; }
  void set_last_alpha(const T& alpha) { last_alpha = alpha; }

 private:
  T sumE = 0.0, sumEM = 0.0, sumEF = 0.0, sum_err_ = 0.0;
  T inf[N];
  T min_w2 = std::numeric_limits<double>::infinity(), max_err2 = 0.0, max_orient = 0.0;
  T f5 = 0.0, f6 = 0.0, first5 = 0.0, first6 = 0.0, last5 = 0.0, last6 = 0.0;
  T done = 0.0, last_t = 0.0, last_alpha = 0.0;
  T sampled_[kSampleMetricCount > 0 ? kSampleMetricCount : 1];
  double ratio_q = 0, ratio_qd = 0, ratio_tau = 0;  // T = double only
  T bound_, obound_;
  const LimitTable* limits_;
  struct NoRoots {};
  std::conditional_t<one, RootSums, NoRoots> roots_;
  RunStatus crossed_ = RunStatus::ok;  // one lane
  M off_{};                            // lanes
  M pending_{};                        // lanes: the Reduce::last entries wait for a replay
  T last_at_ = 0.0;                    // lanes, in a replay: the index of each lane's last sample
  bool replay_ = false;
};

/// What finish_run needs to know of the run besides its sums.
struct RunShape {
  int joints = 3;
  bool orientation = false;  ///< the task prescribes an orientation (pose tasks, vertex_alpha)
  bool prismatic = false;    ///< some joint is prismatic (E_force is measured)
  const LimitTable* limits = nullptr;
};

/// The metrics of a run from its sums, after `done` samples at step dt [s], under `o`'s bound rule:
/// the status is the loop's stop status (singular, diverged), else the first bound crossed (unless
/// on_violation = ignore), else ok. Under on_violation = stop, a run ended by a bound has NaN metrics
/// but its samples and stop time; so has a run that stopped before its first sample (done = 0: no
/// metric computed; final_alpha NaN too).
TrajectoryMetrics finish_run(const RunSums& s, const RunShape& shape, const TrajectoryOptions& o);

}  // namespace ks
