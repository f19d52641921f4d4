#pragma once
// The simulation loop of simulate() as a template over the lane type T (model/lanes.hpp). T = double
// is simulate() itself; F64x4 and F64x8 run 4 or 8 runs side by side (simulate_lanes), every lane with
// the operations of the run alone in the same order, so with its bits. Per-lane decisions: the trig
// tracker's direct evaluations, the statuses (a lane that stops is masked: its sums stop where the run
// alone breaks, its state is parked at its start with zero velocity so that it computes harmless
// values), the histories.
// The kernel reads plain arrays and calls only templates over T and out-of-line functions, so that a
// translation unit compiled for wider vectors (methods/closed_form/lanes_x8.cpp) emits no inline
// function that the rest of the program could end up calling (tests/CMakeLists.txt checks its symbols).
#include <cstddef>
#include <cstdint>
#include <limits>

#include "methods/base/resolution.hpp"
#include "methods/metrics/run_sums.hpp"
#include "methods/metrics/sample_sums.hpp"
#include "methods/base/trajectory.hpp"
#include "model/dynamics.hpp"

namespace ks::kernel {

constexpr int kMaxLanes = 8;

/// The path's data at one RK4 step's stage times t + dt/2 and t + dt (the same for every lane).
struct StageTasks {
  std::size_t seg_h, seg_1;  ///< segments of the two times
  double a_h[2], a_1[2];     ///< path accelerations [m/s^2]
  double unit_h, unit_1;     ///< vertex_alpha: the orientation acceleration per radian of segment rise [1/s^2]
};
/// Out of line (methods/closed_form/run.cpp): the tasks of QuinticPath::sample_on at RK4's stage times, and
/// the orientation acceleration per radian of rise of a vertex_alpha segment (a profile whose segments
/// each rise by exactly 1: `unit`, null when the method is not vertex_alpha).
void stage_tasks(const Path2& path, const Profile1* unit, double t, double dt, StageTasks& out);
double unit_alpha_acceleration(const Profile1& unit, std::size_t segment, double t);

/// The path's position and velocity at time t on `segment`, and for vertex_alpha (`unit` not null)
/// the fraction of the segment's rise done and its rate (closed-loop feedback, orientation error).
struct PathState {
  double p[2], v[2];     ///< [m], [m/s]
  double rise_p, rise_v;  ///< vertex_alpha: unit profile's value past its segment start [1], rate [1/s]
};
void path_state(const Path2& path, const Profile1* unit, std::size_t segment, double t, PathState& out);

/// A run's history as raw column-major arrays (TrajectoryHistory's storage), written in place.
struct HistoryView {
  int stride = 1;
  double *t = nullptr, *q = nullptr, *qd = nullptr, *qdd = nullptr, *tau = nullptr, *x = nullptr, *alpha = nullptr;
  Eigen::Index* size = nullptr;
};

/// What every run of a batch shares.
struct Shared {
  const PlanarArm3* arm = nullptr;
  const DynamicsCoefficients* dyn = nullptr;
  const Path2* path = nullptr;
  const Profile1* alpha_unit = nullptr;  ///< vertex_alpha (see stage_tasks)
  TrajectoryMethod method = TrajectoryMethod::local_weighted;
  Integrator integrator = Integrator::semi_implicit_euler;
  double dt = 0;
  std::size_t n = 0;                    ///< samples
  const double* samples = nullptr;      ///< SampledPath::data(): position (2), acceleration (2) per sample
  const std::uint32_t* segment = nullptr;  ///< SampledPath::segments()
  bool closed_loop = false;             ///< the runs feed the task error back (TrajectoryOptions::closed_loop)
  bool stop_on_bound = false;           ///< on_violation = stop
  /// end = rest (local methods): the time from which the terminal feedback replaces the method's
  /// null-space term [s] (infinity: never), and its gain K_S [1/s]
  double rest_from = std::numeric_limits<double>::infinity();
  double rest_window = 1;  ///< its duration [s]
  double rest_gain = 0;
};
/// Out of line (methods/closed_form/run.cpp): the terminal feedback's weight at time t [s]: 0 before the
/// window, rising smoothly (3 u^2 - 2 u^3 of the window's fraction u) to 1 at the path's end.
double rest_weight(const Shared& s, double t);

/// The per-run inputs, one slot per lane (lanes past the batch and unreachable starts: active = 0, with
/// another run's inputs so that they compute ordinary numbers).
struct Runs {
  double active[kMaxLanes] = {};
  double q0[3][kMaxLanes] = {};
  double k[kMaxLanes] = {}, null_damping[kMaxLanes] = {}, torque_bound[kMaxLanes] = {}, tolerance[kMaxLanes] = {};
  double kp[kMaxLanes] = {}, kd[kMaxLanes] = {};  ///< CLIK gains [1/s^2], [1/s]
  double tracking_bound[kMaxLanes] = {}, orientation_bound[kMaxLanes] = {};  ///< [m], [rad]
  const double* alpha_rise = nullptr;  ///< vertex_alpha: rise of segment s in lane l at [s * kMaxLanes + l] [rad]
  const double* alpha_from = nullptr;  ///< vertex_alpha: alpha at the start of segment s, the same layout [rad]
  const HistoryView* history[kMaxLanes] = {};
  bool any_history = false;
};

/// A lane's sums when the loop ends (finish_run turns them into TrajectoryMetrics).
using Sums = RunSums;

template <class T>
inline T load_lanes(const double* p) {
  if constexpr (std::is_same_v<T, double>) return *p;
  else return T::load(p);
}
template <class T>
inline void store_lanes(const T& x, double* p) {
  if constexpr (std::is_same_v<T, double>) *p = x;
  else x.store(p);
}

/// What the path asks of the arm at one instant, per lane.
template <class T>
struct Task {
  double a[2];  // path acceleration (shared)
  T alpha_dd;   // vertex_alpha: orientation acceleration
  // closed loop only: the path's position and velocity (shared), and for vertex_alpha the desired
  // orientation, its rate and the arm's orientation at this state
  double p[2], v[2];
  T alpha_d, alpha_v, alpha;
  bool rest = false;  // end = rest: in the terminal feedback's window (local methods)
  double rest_weight = 0;  // and its weight there (rest_weight)

  /// Sets every field (the path's acceleration a, its position p, the rest zero: alpha_dd, v,
  /// alpha_d, alpha_v; rest from rest_from). Field by field: an aggregate initialiser of this
  /// 64-byte-aligned struct zero-fills all of it first (GCC: a rep stos per sample and stage).
  void set(double a0, double a1, double p0, double p1, const T& alpha_now, double t, const Shared& s) {
    a[0] = a0, a[1] = a1;
    alpha_dd = T(0.0);
    p[0] = p0, p[1] = p1, v[0] = 0.0, v[1] = 0.0;
    alpha_d = T(0.0), alpha_v = T(0.0), alpha = alpha_now;
    rest = t >= s.rest_from;
    rest_weight = rest ? ks::kernel::rest_weight(s, t) : 0.0;  // rest_weight is 0 outside the window
  }
};

template <class T>
struct Evaluation {
  Sym3Of<T> M;
  SymInverse3Of<T> Mi;  // M^-1 as adj(M) / det(M)
  Vec3Of<T> c, g, qdd;
  Mat23Of<T> J;
  T w2;  // squared manipulability det(J J^T) (the square root is taken once, at the end)
};

template <class T>
class Resolver {
 public:
  using V3 = Vec3Of<T>;
  Resolver(const Shared& s, const Runs& in)
      : arm_(*s.arm), dyn_(*s.dyn), method_(s.method),
        w_(s.method == TrajectoryMethod::local_unweighted ? Weighting::inertia_squared : Weighting::inertia),
        closed_(s.closed_loop), ks_(s.rest_gain), kp_rest_(s.rest_gain * s.rest_gain), kd_rest_(2.0 * s.rest_gain),
        k_(load_lanes<T>(in.k)), kn_(load_lanes<T>(in.null_damping)),
        tol_(load_lanes<T>(in.tolerance)), tol2_(tol_ * tol_), kp_(load_lanes<T>(in.kp)), kd_(load_lanes<T>(in.kd)) {}

  /// Joint accelerations of the method for task x at (trig, qd); fills every intermediate in `e`.
  /// The mask: lanes whose Jacobian is not singular.
  MaskOf<T> evaluate(const Task<T>& x, const JointTrigOf<T>& trig, const V3& qd, Evaluation<T>& e) const {
    e.M = mass_matrix_sym(dyn_, trig);
    e.c = coriolis(dyn_, trig, qd);
    e.g = gravity(dyn_, trig);
    e.J = jacobian(arm_, trig);
    e.Mi = SymInverse3Of<T>(e.M);
    const Vec2Of<T> jdqd = jacobian_dot_times_qd(arm_, trig, qd);
    Vec2Of<T> b{x.a[0] - jdqd[0], x.a[1] - jdqd[1]};
    T alpha_dd = x.alpha_dd;
    if (closed_ || x.rest) {  // CLIK: + K_D (v_path - J qd) + K_P (p_path - tip), tip = (J10, -J00)
      // (the end = rest window of an open-loop run: K_D = 2 K_S, K_P = K_S^2, the tip error critically damped)
      const T& kd = closed_ ? kd_ : kd_rest_;
      const T& kp = closed_ ? kp_ : kp_rest_;
      const T v0 = e.J(0, 0) * qd[0] + e.J(0, 1) * qd[1] + e.J(0, 2) * qd[2];
      const T v1 = e.J(1, 0) * qd[0] + e.J(1, 1) * qd[1] + e.J(1, 2) * qd[2];
      b[0] = b[0] + kd * (x.v[0] - v0) + kp * (x.p[0] - e.J(1, 0));
      b[1] = b[1] + kd * (x.v[1] - v1) + kp * (x.p[1] + e.J(0, 0));
      if (method_ == TrajectoryMethod::vertex_alpha)
        alpha_dd = alpha_dd + kd_ * (x.alpha_v - (qd[0] + qd[1] + qd[2])) + kp_ * (x.alpha_d - x.alpha);
    }
    if (method_ == TrajectoryMethod::vertex_alpha) {
      T det = 0.0;
      e.qdd = nonredundant_acceleration<T>(e.J, b, alpha_dd, det);
      e.w2 = manipulability_squared(e.J);
      return vabs(det) >= tol_;
    }
    e.w2 = manipulability_squared(e.J);
    const MaskOf<T> ok = e.w2 >= tol2_;
    if (!any(ok)) return ok;
    if (x.rest) {  // terminal feedback: the null-space term blends from the method's into -(I - J+ J) K_S qd
      // (local_acceleration is linear in c, g and K_N: weights 1 - s and s give that blend)
      const T keep = T(1.0 - x.rest_weight), s = T(x.rest_weight);
      const Vec3Of<T> c{keep * e.c[0], keep * e.c[1], keep * e.c[2]}, g{keep * e.g[0], keep * e.g[1], keep * e.g[2]};
      e.qdd = local_acceleration<T>(w_, e.Mi, e.J, b, c, g, k_, keep * kn_ + s * ks_, qd);
      return ok;
    }
    e.qdd = local_acceleration<T>(w_, e.Mi, e.J, b, e.c, e.g, k_, kn_, qd);
    return ok;
  }

 private:
  const PlanarArm3& arm_;
  const DynamicsCoefficients& dyn_;
  const TrajectoryMethod method_;
  const Weighting w_;
  const bool closed_;
  const T ks_, kp_rest_, kd_rest_, k_, kn_, tol_, tol2_, kp_, kd_;
};

/// Writes sample i of the lanes in `write` (a bit per lane) to their histories.
template <class T>
void write_histories(const Runs& in, int write, double t, const Vec3Of<T>& q, const Vec3Of<T>& qd,
                     const Evaluation<T>& e, const T (&tau)[3], const T& alpha) {
  constexpr int N = lanes_of<T>;
  alignas(64) double v[15][N];
  for (int j = 0; j < 3; ++j) {
    store_lanes(q[j], v[j]);
    store_lanes(qd[j], v[3 + j]);
    store_lanes(e.qdd[j], v[6 + j]);
    store_lanes(tau[j], v[9 + j]);
  }
  store_lanes(T(e.J(1, 0)), v[12]);  // tip = (x1, y1) = (J10, -J00)
  store_lanes(T(-e.J(0, 0)), v[13]);
  store_lanes(alpha, v[14]);
  for (int l = 0; l < N; ++l) {
    if (!(write >> l & 1)) continue;
    const HistoryView& h = *in.history[l];
    const Eigen::Index c = (*h.size)++;
    h.t[c] = t;
    for (int j = 0; j < 3; ++j) {
      h.q[3 * c + j] = v[j][l];
      h.qd[3 * c + j] = v[3 + j][l];
      h.qdd[3 * c + j] = v[6 + j][l];
      h.tau[3 * c + j] = v[9 + j][l];
    }
    h.x[2 * c] = v[12][l];
    h.x[2 * c + 1] = v[13][l];
    h.alpha[c] = v[14][l];
  }
}

template <class T>
inline int lane_bits(MaskOf<T> m) {
  if constexpr (std::is_same_v<T, double>) return m ? 1 : 0;
  else return bits(m);
}

/// The loop of simulate() over lanes: out[l] for lane l (the lanes of `in` that are active).
/// Flattened: the resolver, the resolution, the trig tracker and the sums are inlined into the loop,
/// so that a step's intermediates (Evaluation, Task) stay in registers rather than passing through
/// memory to out-of-line calls; the operations and their order are the same, so are the results.
template <class T>
[[gnu::flatten]] void run(const Shared& s, const Runs& in, Sums* out) {
  using V3 = Vec3Of<T>;
  using M = MaskOf<T>;
  constexpr bool one = std::is_same_v<T, double>;
  constexpr int N = lanes_of<T>;
  const Resolver<T> resolver(s, in);
  const V3 q_start{load_lanes<T>(in.q0[0]), load_lanes<T>(in.q0[1]), load_lanes<T>(in.q0[2])};
  V3 q = q_start, qd{T(0.0), T(0.0), T(0.0)};
  M active = load_lanes<T>(in.active) != 0.0;
  M singular = T(0.0) != T(0.0), diverged = singular, bounded = singular;
  Evaluation<T> e, st;  // e: at the sample; st: RK4 stages
  // qdd is read only after an evaluation that set it (an evaluation that stops every lane returns
  // before it and the loop breaks); set once here so that GCC, with the whole loop inlined, does not warn
  e.qdd = st.qdd = V3{T(0.0), T(0.0), T(0.0)};
  TrigTrackerOf<T> trig(q);  // the sample's trig, carried from step to step (semi-implicit Euler)
  SampleSums<T, 3> sums(load_lanes<T>(in.tracking_bound), load_lanes<T>(in.orientation_bound));
  sums.start_alpha(q[0] + q[1] + q[2]);
  // a sample's value enters a lane's sums only while the lane runs (one lane: the loop stops instead;
  // while every lane runs, nothing is masked)
  bool all_on = all(active);
  const auto keep = [&](const T& updated, const T& old) -> T {  // uses active, all_on with lanes
    if constexpr (one) return updated;
    else return all_on ? updated : select(active, updated, old);
  };
  const double dt = s.dt, hdt = 0.5 * dt, dt6 = dt / 6.0;
  const std::size_t n = s.n;
  const bool vertex = s.method == TrajectoryMethod::vertex_alpha;
  const auto lanes_at = [](const double* a, std::size_t segment) -> T { return load_lanes<T>(a + segment * kMaxLanes); };
  const auto rise = [&](std::size_t segment) -> T { return lanes_at(in.alpha_rise, segment); };
  // the closed loop's path state at (segment, t) into task x (vertex_alpha: also the desired orientation)
  const auto feed = [&](std::size_t segment, double t, Task<T>& x) {
    PathState ps;
    path_state(*s.path, s.alpha_unit, segment, t, ps);
    x.p[0] = ps.p[0], x.p[1] = ps.p[1], x.v[0] = ps.v[0], x.v[1] = ps.v[1];
    if (vertex) {
      const T r = rise(segment);
      x.alpha_d = lanes_at(in.alpha_from, segment) + ps.rise_p * r;
      x.alpha_v = ps.rise_v * r;
    }
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

  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * dt;  // SampledPath::time(i)
    const double* xa = s.samples + 4 * i;
    Task<T> x;
    x.set(xa[2], xa[3], xa[0], xa[1], q[0] + q[1] + q[2], t, s);
    if (vertex) x.alpha_dd = unit_alpha_acceleration(*s.alpha_unit, s.segment[i], t) * rise(s.segment[i]);
    if (s.closed_loop || vertex || x.rest) feed(s.segment[i], t, x);
    if (stop(resolver.evaluate(x, trig.trig(), qd, e), singular)) break;
    const V3 Mqdd = e.M * e.qdd;
    const T tau0 = Mqdd[0] + e.c[0] + e.g[0], tau1 = Mqdd[1] + e.c[1] + e.g[1], tau2 = Mqdd[2] + e.c[2] + e.g[2];
    const T a[3] = {vabs(tau0), vabs(tau1), vabs(tau2)};
    const T tt = tau0 * tau0 + tau1 * tau1 + tau2 * tau2;
    // NaN fails every comparison: one test catches non-finite values and the bound
    const T bound = load_lanes<T>(in.torque_bound);
    const M good = (a[0] <= bound) & (a[1] <= bound) & (a[2] <= bound) & (vabs(tt) < std::numeric_limits<double>::infinity());
    if (stop(good, diverged)) break;
    // metrics of this sample
    const V3 tau{tau0, tau1, tau2};
    const T ex = e.J(1, 0) - xa[0], ey = -e.J(0, 0) - xa[1];  // tip = (x1, y1) = (J10, -J00)
    const T p0 = tau0 * qd[0], p1 = tau1 * qd[1], p2 = tau2 * qd[2];
    const T alpha = q[0] + q[1] + q[2];
    const T taus[3] = {tau0, tau1, tau2};
    const V3 Mqd = e.M * qd;
    const T ke = 0.5 * (qd[0] * Mqd[0] + qd[1] * Mqd[1] + qd[2] * Mqd[2]);
    SampleValues<T> v;  // field by field: see Task::set
    v.n = 3, v.q = &q[0], v.qd = &qd[0], v.tau = taus, v.tt = tt, v.ff = T(0.0);
    v.qf = e.Mi.P.quadratic_form(tau), v.det = e.Mi.det, v.p6 = p0 * p0 + p1 * p1 + p2 * p2, v.w2 = e.w2;
    v.err2 = ex * ex + ey * ey, v.orient = vertex ? vabs(alpha - x.alpha_d) : T(0.0), v.alpha = alpha, v.ke = ke;
    const M off = sums.add(i, t, v, a, 3, keep) & active;
    sums.mark(off);
    if (in.any_history) {
      int write = 0;
      for (int l = 0; l < N; ++l)
        if (in.history[l] && (i % in.history[l]->stride == 0 || i + 1 == n)) write |= 1 << l;
      write &= lane_bits<T>(active);
      if (write) write_histories<T>(in, write, t, q, qd, e, {tau0, tau1, tau2}, alpha);
    }
    if (s.stop_on_bound && any(off) && stop(!off, bounded)) break;
    if (i + 1 == n) break;  // the last sample is measured, not integrated past
    // integrate to the next sample
    if (s.integrator == Integrator::semi_implicit_euler) {
      for (int j = 0; j < 3; ++j) qd[j] = keep(qd[j] + dt * e.qdd[j], T(0.0));
      const V3 dq{dt * qd[0], dt * qd[1], dt * qd[2]};
      for (int j = 0; j < 3; ++j) q[j] = keep(q[j] + dq[j], q_start[j]);
      trig.advance(q, dq);
    } else {
      StageTasks stt;
      stage_tasks(*s.path, s.alpha_unit, t, dt, stt);
      Task<T> xh, x1;
      xh.set(stt.a_h[0], stt.a_h[1], 0.0, 0.0, T(0.0), t + hdt, s);
      x1.set(stt.a_1[0], stt.a_1[1], 0.0, 0.0, T(0.0), t + dt, s);
      if (vertex) {
        xh.alpha_dd = stt.unit_h * rise(stt.seg_h);
        x1.alpha_dd = stt.unit_1 * rise(stt.seg_1);
      }
      if (s.closed_loop || xh.rest) feed(stt.seg_h, t + hdt, xh);
      if (s.closed_loop || x1.rest) feed(stt.seg_1, t + dt, x1);
      const V3 k1q = qd, k1v = e.qdd;
      const V3 q2{q[0] + hdt * k1q[0], q[1] + hdt * k1q[1], q[2] + hdt * k1q[2]};
      const V3 k2q{qd[0] + hdt * k1v[0], qd[1] + hdt * k1v[1], qd[2] + hdt * k1v[2]};
      xh.alpha = q2[0] + q2[1] + q2[2];
      M good_stages = resolver.evaluate(xh, joint_trig(q2), k2q, st);
      const V3 k2v = st.qdd;
      const V3 q3{q[0] + hdt * k2q[0], q[1] + hdt * k2q[1], q[2] + hdt * k2q[2]};
      const V3 k3q{qd[0] + hdt * k2v[0], qd[1] + hdt * k2v[1], qd[2] + hdt * k2v[2]};
      xh.alpha = q3[0] + q3[1] + q3[2];
      good_stages = good_stages & resolver.evaluate(xh, joint_trig(q3), k3q, st);
      const V3 k3v = st.qdd;
      const V3 q4{q[0] + dt * k3q[0], q[1] + dt * k3q[1], q[2] + dt * k3q[2]};
      const V3 k4q{qd[0] + dt * k3v[0], qd[1] + dt * k3v[1], qd[2] + dt * k3v[2]};
      x1.alpha = q4[0] + q4[1] + q4[2];
      good_stages = good_stages & resolver.evaluate(x1, joint_trig(q4), k4q, st);
      if (stop(good_stages, singular)) break;
      const V3 k4v = st.qdd;
      for (int j = 0; j < 3; ++j) {
        q[j] = keep(q[j] + dt6 * (k1q[j] + 2.0 * k2q[j] + 2.0 * k3q[j] + k4q[j]), q_start[j]);
        qd[j] = keep(qd[j] + dt6 * (k1v[j] + 2.0 * k2v[j] + 2.0 * k3v[j] + k4v[j]), T(0.0));
      }
      trig.reset(q);
    }
  }

  const int sing = lane_bits<T>(singular), div = lane_bits<T>(diverged);
  for (int l = 0; l < N; ++l) {
    const RunStatus st = (sing >> l & 1) ? RunStatus::singular : (div >> l & 1) ? RunStatus::diverged : RunStatus::ok;
    out[l] = sums.of_lane(l, st, 3);
  }
}

}  // namespace ks::kernel
