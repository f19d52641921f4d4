#pragma once
// The per-sample loop of a trajectory run, written once over a value type T and a model. T = double
// is one run; a SIMD lane type (model/lanes.hpp) runs one run per lane, each lane with the operations
// of its run alone in the same order (so with its bits): a lane that stops is masked — its sums stop
// where its run alone breaks, its state is parked at its start at rest so that it computes harmless
// values. The model is the arm's dynamics, the task space and the method, chosen once per run (the
// closed-form 3R over lanes, a chain of any joints, a planar chain of fixed size).
//
// The loop owns what every run shares: the state, the torques' bound, the accumulator of the run's
// metrics (methods/metrics/sample_sums.hpp), the joint limits, the stop rules and the integrator
// (semi-implicit Euler or RK4). It asks the model for what differs — the model provides:
//   static constexpr int max_joints;                compile-time bound on the joints
//   using Evaluation;                               one evaluation: .qdd (joints) and what the model reads
//   int joints() const; LoopShape shape() const;    samples, dt, integrator, stop rule
//   SampleSums<T, max_joints> sums() const;         the accumulator with the run's bounds and limits
//   MaskOf<T> start(T* q);                          the start (the loop's coordinates; qd = 0) and the
//                                                   lanes that run
//   T alpha(const T* q) const;                      the tip angle at q [rad] (NaN: spatial tasks)
//   T torque_bound() const;                         [Nm]
//   MaskOf<T> at_sample(i, t, q, qd, Evaluation& e);  the method at sample i (false: singular); a
//                                                   prescribed model (LoopShape) sets q and qd there and
//                                                   may return a RunStatus instead (not ok: it stops)
//   void torques(e, qd, T* tau);                    tau = M qdd + c + g (the model's order)
//   static constexpr bool prismatic_joints;        some joint may be prismatic: then bool prismatic(int j)
//   void values(e, i, q, qd, tau, SampleValues<T>& v);  every field but n, tt, ff and p6 (the loop's
//                                                   sums); v.q, v.qd, v.tau in the chain's coordinates
//   void record(i, t, e, q, qd, tau, MaskOf<T> active);  history rows (where the model keeps them)
//   void stages(double t, double dt);               RK4: the task at t + dt/2 and t + dt
//   MaskOf<T> stage(bool end, yq, yv, Evaluation& s);  RK4: the method at a stage's state
//   void moved(const T* q, const T* dq);            the state moved by dq (Euler) or to q (dq null)
// and optionally:
//   T squared_torque(const T* tau);                 tau^T tau in the model's own order
//   void finish(SampleSums<T, max_joints>& sums);   after the last sample
//   void last_values(e, qd, SampleValues<T>& v);    the fields only the Reduce::last entries read,
//                                                   which values() leaves out where the sums take them
//                                                   at a lane's last sample only (SampleSums::
//                                                   last_at_end): called there (that sample's e, qd)
#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>

#include "methods/metrics/sample_sums.hpp"

namespace ks {

/// What the loop needs of a run's options.
struct LoopShape {
  std::size_t samples = 0;
  double dt = 0;  ///< [s]
  Integrator integrator = Integrator::semi_implicit_euler;
  bool stop_on_violation = false;  ///< on_violation = stop: the tracking bound or a limit crossed stops
  /// the model sets the state at each sample (a path-global run's spline): nothing is integrated
  bool prescribed = false;
  /// lanes: the Reduce::last entries are taken at every sample, as one lane takes them, rather than at
  /// each lane's last sample (with a replay of the lanes that stop before adding a sample): the same
  /// bits either way, the cheaper way depending on how many runs stop early
  bool last_every_sample = false;
};

/// Lane l of mask m.
template <class M>
inline bool bit(M m, int l) {
  if constexpr (std::is_same_v<M, bool>) return m && l == 0;
  else return bits(m) >> l & 1;
}

namespace loop_detail {

/// trajectory_loop with its integrator fixed at compile time (kEuler: semi-implicit Euler, else RK4).
template <bool kEuler, class T, class Model>
void run_loop(Model& model, RunSums* out) {
  using M = MaskOf<T>;
  constexpr bool one = std::is_same_v<T, double>;
  constexpr int N = Model::max_joints;
  const int n = model.joints();
  const LoopShape shape = model.shape();
  const std::size_t samples = shape.samples;
  const double dt = shape.dt, h = 0.5 * dt, w = dt / 6.0;
  // e: at the sample; s: RK4 stages (value-initialised once: qdd is read only after an evaluation
  // that set it, which GCC cannot see through the whole inlined loop)
  typename Model::Evaluation e{}, s{};
  T q[N], qd[N], q_start[N], tau[N], abs_tau[N];
  RunStatus stopped = RunStatus::ok;  // one lane: a prescribed model's stop status
  M active = model.start(q);
  for (int j = 0; j < n; ++j) q_start[j] = q[j], qd[j] = T(0.0);
  M singular = T(0.0) != T(0.0), diverged = singular, bounded = singular;
  auto sums = model.sums();
  constexpr bool last_at_end = decltype(sums)::last_at_end;  // the Reduce::last entries at a lane's last sample
  sums.start_alpha(model.alpha(q));
  // a sample's value enters a lane's sums only while the lane runs (one lane: the loop stops instead;
  // while every lane runs, nothing is masked)
  bool all_on = all(active);
  const auto keep = [&](const T& updated, const T& old) -> T {
    if constexpr (one) return updated;
    else return all_on ? updated : select(active, updated, old);
  };
  const auto stop = [&](M ok, M& status) {  // lanes failing ok stop with `status`; true when none runs on
    if constexpr (one) {
      if (!ok) status = true;
      return !ok;
    } else {
      status = status | (active & !ok);
      active = active & ok;
      all_on = all(active);
      return !any(active);
    }
  };
  // last_at_end: the Reduce::last entries of sample i's values v, in the lanes of `ending` (the model
  // fills what only they read, when it has last_values)
  const auto take_last = [&](M ending, SampleValues<T>& v) {
    if constexpr (last_at_end) {
      const bool all_lanes = all(ending);
      if (!all_lanes && !any(ending)) return;
      if constexpr (requires { model.last_values(e, qd, v); }) model.last_values(e, qd, v);
      sums.take_last(ending, all_lanes, v);
    }
  };
  const bool early_last = sums.replaying() || shape.stop_on_violation;  // a last sample before the end
  const T bound = model.torque_bound();
  const T infinity(std::numeric_limits<double>::infinity());

  for (std::size_t i = 0; i < samples; ++i) {
    const double t = static_cast<double>(i) * dt;  // SampledPath::time(i)
    const auto state = model.at_sample(i, t, q, qd, e);
    if constexpr (std::is_same_v<std::remove_const_t<decltype(state)>, RunStatus>) {
      if (state != RunStatus::ok) {
        stopped = state;
        break;
      }
    } else {
      if constexpr (last_at_end)
        if (i > 0) sums.stopped_before_sample(active & !state);
      if (stop(state, singular)) break;
    }
    model.torques(e, qd, tau);
    // the sums start at joint 0's terms (a sum from 0 would add 0.0, which IEEE does not drop)
    T tt(0.0), ff(0.0);
    T p = tau[0] * qd[0], p6 = p * p;
    abs_tau[0] = vabs(tau[0]);
    M good = abs_tau[0] <= bound;  // NaN fails every comparison
    if constexpr (Model::prismatic_joints)
      (model.prismatic(0) ? ff : tt) += tau[0] * tau[0];
    else
      tt = tau[0] * tau[0];
    for (int j = 1; j < n; ++j) {
      if constexpr (Model::prismatic_joints)
        (model.prismatic(j) ? ff : tt) += tau[j] * tau[j];
      else
        tt += tau[j] * tau[j];
      p = tau[j] * qd[j];
      p6 += p * p;
      abs_tau[j] = vabs(tau[j]);
      good = good & (abs_tau[j] <= bound);
    }
    if constexpr (requires { model.squared_torque(tau); }) tt = model.squared_torque(tau);
    // one test catches non-finite values and the bound
    good = good & (vabs(tt) < infinity);
    if constexpr (Model::prismatic_joints) good = good & (vabs(ff) < infinity);
    if constexpr (last_at_end)
      if (i > 0) sums.stopped_before_sample(active & !good);
    if (stop(good, diverged)) break;
    SampleValues<T> v;  // field by field: no zero-filling aggregate initialiser per sample
    v.n = n, v.tt = tt, v.ff = ff, v.p6 = p6;
    model.values(e, i, q, qd, tau, v);
    M crossed = sums.template add<Model::prismatic_joints>(i, t, v, abs_tau, n, keep) & active;
    bool beyond = false;
    if constexpr (one) beyond = sums.limits(v.q, v.qd, v.tau, n);
    sums.mark(crossed, beyond);
    if constexpr (last_at_end) {  // the lanes whose last sample this is take the Reduce::last entries
      if (shape.last_every_sample || i + 1 == samples) {
        take_last(active, v);
      } else if (early_last) {  // a replay's lanes, or lanes that stop at a crossing
        M ending = sums.last_here(i) & active;
        if (shape.stop_on_violation) ending = ending | crossed;
        take_last(ending, v);
      }
    }
    model.record(i, t, e, q, qd, tau, active);
    if constexpr (one) crossed = crossed || beyond;
    if (shape.stop_on_violation && any(crossed) && stop(!crossed, bounded)) break;
    if (i + 1 == samples) break;  // the last sample is measured, not integrated past
    if (shape.prescribed) continue;
    // integrate to the next sample
    if constexpr (kEuler) {
      T dq[N];
      for (int j = 0; j < n; ++j) {
        qd[j] = keep(qd[j] + dt * e.qdd[j], T(0.0));
        dq[j] = dt * qd[j];
        q[j] = keep(q[j] + dq[j], q_start[j]);
      }
      model.moved(q, dq);
    } else {
      model.stages(t, dt);
      T k2q[N], k3q[N], k4q[N], k2v[N], k3v[N], yq[N];
      // stage 2 at (q + h k1q, k2q = qd + h k1v) with k1q = qd, k1v = qdd
      for (int j = 0; j < n; ++j) yq[j] = q[j] + h * qd[j], k2q[j] = qd[j] + h * e.qdd[j];
      M good_stages = model.stage(false, yq, k2q, s);
      for (int j = 0; j < n; ++j) k2v[j] = s.qdd[j];
      if (one && !any(good_stages)) {  // one run: a singular stage ends it, the rest is not evaluated
        stop(good_stages, singular);
        break;
      }
      for (int j = 0; j < n; ++j) yq[j] = q[j] + h * k2q[j], k3q[j] = qd[j] + h * k2v[j];
      good_stages = good_stages & model.stage(false, yq, k3q, s);
      for (int j = 0; j < n; ++j) k3v[j] = s.qdd[j];
      if (one && !any(good_stages)) {
        stop(good_stages, singular);
        break;
      }
      for (int j = 0; j < n; ++j) yq[j] = q[j] + dt * k3q[j], k4q[j] = qd[j] + dt * k3v[j];
      good_stages = good_stages & model.stage(true, yq, k4q, s);
      if constexpr (last_at_end) take_last(active & !good_stages, v);  // sample i, already added, is their last
      if (stop(good_stages, singular)) break;
      for (int j = 0; j < n; ++j) {
        q[j] = keep(q[j] + w * (qd[j] + 2.0 * k2q[j] + 2.0 * k3q[j] + k4q[j]), q_start[j]);
        qd[j] = keep(qd[j] + w * (e.qdd[j] + 2.0 * k2v[j] + 2.0 * k3v[j] + s.qdd[j]), T(0.0));
      }
      model.moved(q, nullptr);
    }
  }
  if constexpr (requires { model.finish(sums); }) model.finish(sums);
  constexpr int lanes = lanes_of<T>;
  for (int l = 0; l < lanes; ++l) {
    const bool sing = bit(singular, l), div = bit(diverged, l);
    out[l] = sums.of_lane(l, sing ? RunStatus::singular : div ? RunStatus::diverged : stopped, n);
  }
}

}  // namespace loop_detail

/// The runs of `model` along its samples from its start at rest: out[l] the sums of lane l (one for
/// T = double), with its loop status (singular, diverged, a prescribed model's, else ok; finish_run
/// turns the sums into the run's metrics and status). Each integrator has its own instance of the
/// loop, so that the registers of one are not shared with the other's stages.
template <class T, class Model>
void trajectory_loop(Model& model, RunSums* out) {
  if (model.shape().integrator == Integrator::semi_implicit_euler)
    loop_detail::run_loop<true, T>(model, out);
  else
    loop_detail::run_loop<false, T>(model, out);
}

}  // namespace ks
