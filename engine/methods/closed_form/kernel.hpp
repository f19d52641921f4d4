#pragma once
// The seed's closed-form 3R run as a model of the one trajectory loop (methods/loop/trajectory_loop.hpp)
// over the lane type T (model/lanes.hpp). T = double is simulate() itself; F64x4 and F64x8 run 4 or 8
// runs side by side (simulate_lanes), every lane with the operations of the run alone in the same
// order, so with its bits. Per-lane decisions here: the trig tracker's direct evaluations and the
// histories (the loop masks the statuses and parks a stopped lane's state).
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
#include "methods/loop/trajectory_loop.hpp"
#include "model/dynamics.hpp"

namespace ks::kernel {

constexpr int kMaxLanes = 8;

/// The path's data at one RK4 step's stage times t + dt/2 and t + dt (the same for every lane).
struct StageTasks {
  std::size_t seg_h, seg_1;  ///< segments of the two times
  double a_h[2], a_1[2];     ///< path accelerations [m/s^2]
  double unit_h, unit_1;     ///< vertex_alpha: the orientation acceleration per radian of segment rise [1/s^2]
};
/// Out of line (methods/closed_form/run.cpp): the tasks of TaskPath::sample_on at RK4's stage times, and
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
  /// lanes: the Reduce::last entries taken at every sample (no replay needed; LoopShape::last_every_sample)
  bool last_every_sample = false;
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
  /// a replay of lanes that stopped before adding a sample (RunSums::last_pending): lane l's last
  /// sample index, where its Reduce::last entries are taken
  bool replay = false;
  double last_at[kMaxLanes] = {};
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

/// The closed-form 3R as methods/loop/trajectory_loop.hpp's model over the lanes of T: the path's
/// task at each sample and stage (shared by the lanes), the resolver, the trig carried from step to
/// step (semi-implicit Euler), the per-sample values and the lanes' histories.
template <class T>
class Model {
 public:
  using V3 = Vec3Of<T>;
  using M = MaskOf<T>;
  using Evaluation = kernel::Evaluation<T>;
  static constexpr int max_joints = 3;

  /// resolver and trig: the run's (trig: at the start q0), kept apart from the model so that the
  /// compiler keeps each in registers.
  Model(const Shared& s, const Runs& in, const Resolver<T>& resolver, TrigTrackerOf<T>& trig)
      : s_(s), in_(in), resolver_(resolver), vertex_(s.method == TrajectoryMethod::vertex_alpha), trig_(trig) {}

  int joints() const { return 3; }
  LoopShape shape() const { return {s_.n, s_.dt, s_.integrator, s_.stop_on_bound, false, s_.last_every_sample}; }
  SampleSums<T, 3> sums() const {
    SampleSums<T, 3> sums(load_lanes<T>(in_.tracking_bound), load_lanes<T>(in_.orientation_bound));
    if constexpr (!std::is_same_v<T, double>)
      if (in_.replay) sums.replay_last_at(load_lanes<T>(in_.last_at));
    return sums;
  }
  M start(T* q) const {
    for (int j = 0; j < 3; ++j) q[j] = load_lanes<T>(in_.q0[j]);
    return load_lanes<T>(in_.active) != 0.0;
  }
  static T alpha(const T* q) { return q[0] + q[1] + q[2]; }
  T torque_bound() const { return load_lanes<T>(in_.torque_bound); }
  static constexpr bool prismatic_joints = false;

  M at_sample(std::size_t i, double t, const T* q, const T* qd, Evaluation& e) {
    const double* xa = s_.samples + 4 * i;
    Task<T> x;
    x.set(xa[2], xa[3], xa[0], xa[1], alpha(q), t, s_);
    if (vertex_) x.alpha_dd = unit_alpha_acceleration(*s_.alpha_unit, s_.segment[i], t) * rise(s_.segment[i]);
    if (s_.closed_loop || vertex_ || x.rest) feed(s_.segment[i], t, x);
    alpha_d_ = x.alpha_d;
    return resolver_.evaluate(x, trig_.trig(), V3{qd[0], qd[1], qd[2]}, e);
  }
  static void torques(const Evaluation& e, const T*, T* tau) {
    const V3 Mqdd = e.M * e.qdd;
    for (int j = 0; j < 3; ++j) tau[j] = Mqdd[j] + e.c[j] + e.g[j];
  }
  void values(const Evaluation& e, std::size_t i, const T* q, const T* qd, const T* tau, SampleValues<T>& v) const {
    const double* xa = s_.samples + 4 * i;
    const T ex = e.J(1, 0) - xa[0], ey = -e.J(0, 0) - xa[1];  // tip = (x1, y1) = (J10, -J00)
    const T a = alpha(q);
    v.q = q, v.qd = qd, v.tau = tau;
    v.qf = e.Mi.P.quadratic_form(V3{tau[0], tau[1], tau[2]}), v.det = e.Mi.det, v.w2 = e.w2;
    v.err2 = ex * ex + ey * ey, v.orient = vertex_ ? vabs(a - alpha_d_) : T(0.0), v.alpha = a;
    if constexpr (!SampleSums<T, 3>::last_at_end) last_values(e, qd, v);
  }
  /// The kinetic energy qd^T M qd / 2, read only by the Reduce::last entries (at 8 lanes: at a lane's
  /// last sample only).
  static void last_values(const Evaluation& e, const T* qd, SampleValues<T>& v) {
    const V3 Mqd = e.M * V3{qd[0], qd[1], qd[2]};
    v.ke = 0.5 * (qd[0] * Mqd[0] + qd[1] * Mqd[1] + qd[2] * Mqd[2]);
  }
  void record(std::size_t i, double t, const Evaluation& e, const T* q, const T* qd, const T* tau, M active) const {
    if (!in_.any_history) return;
    int write = 0;
    for (int l = 0; l < lanes_of<T>; ++l)
      if (in_.history[l] && (i % in_.history[l]->stride == 0 || i + 1 == s_.n)) write |= 1 << l;
    write &= lane_bits<T>(active);
    if (write)
      write_histories<T>(in_, write, t, V3{q[0], q[1], q[2]}, V3{qd[0], qd[1], qd[2]}, e, {tau[0], tau[1], tau[2]},
                         alpha(q));
  }
  void stages(double t, double dt) {
    StageTasks stt;
    stage_tasks(*s_.path, s_.alpha_unit, t, dt, stt);
    const double hdt = 0.5 * dt;
    xh_.set(stt.a_h[0], stt.a_h[1], 0.0, 0.0, T(0.0), t + hdt, s_);
    x1_.set(stt.a_1[0], stt.a_1[1], 0.0, 0.0, T(0.0), t + dt, s_);
    if (vertex_) {
      xh_.alpha_dd = stt.unit_h * rise(stt.seg_h);
      x1_.alpha_dd = stt.unit_1 * rise(stt.seg_1);
    }
    if (s_.closed_loop || xh_.rest) feed(stt.seg_h, t + hdt, xh_);
    if (s_.closed_loop || x1_.rest) feed(stt.seg_1, t + dt, x1_);
  }
  M stage(bool end, const T* yq, const T* yv, Evaluation& st) {
    Task<T>& x = end ? x1_ : xh_;
    const V3 q{yq[0], yq[1], yq[2]};
    x.alpha = q[0] + q[1] + q[2];
    return resolver_.evaluate(x, joint_trig(q), V3{yv[0], yv[1], yv[2]}, st);
  }
  void moved(const T* q, const T* dq) {
    if (dq)
      trig_.advance(V3{q[0], q[1], q[2]}, V3{dq[0], dq[1], dq[2]});
    else
      trig_.reset(V3{q[0], q[1], q[2]});
  }

 private:
  T lanes_at(const double* a, std::size_t segment) const { return load_lanes<T>(a + segment * kMaxLanes); }
  T rise(std::size_t segment) const { return lanes_at(in_.alpha_rise, segment); }
  /// The closed loop's path state at (segment, t) into task x (vertex_alpha: also the desired orientation).
  void feed(std::size_t segment, double t, Task<T>& x) const {
    PathState ps;
    path_state(*s_.path, s_.alpha_unit, segment, t, ps);
    x.p[0] = ps.p[0], x.p[1] = ps.p[1], x.v[0] = ps.v[0], x.v[1] = ps.v[1];
    if (vertex_) {
      const T r = rise(segment);
      x.alpha_d = lanes_at(in_.alpha_from, segment) + ps.rise_p * r;
      x.alpha_v = ps.rise_v * r;
    }
  }

  const Shared& s_;
  const Runs& in_;
  const Resolver<T>& resolver_;
  const bool vertex_;
  TrigTrackerOf<T>& trig_;  // the sample's trig, carried from step to step (semi-implicit Euler)
  T alpha_d_;              // vertex_alpha: the sample's desired orientation
  Task<T> xh_, x1_;        // RK4: the tasks at the half step and the step's end
};

/// The runs of the lanes of `in` (those active): out[l] for lane l. Flattened: the model, the
/// resolution, the trig tracker and the sums are inlined into the one loop, so that a step's
/// intermediates (Evaluation, Task) stay in registers rather than passing through memory to
/// out-of-line calls; the operations and their order are the loop's, so are the results.
template <class T>
[[gnu::flatten]] void run(const Shared& s, const Runs& in, Sums* out) {
  const Resolver<T> resolver(s, in);
  TrigTrackerOf<T> trig(Vec3Of<T>{load_lanes<T>(in.q0[0]), load_lanes<T>(in.q0[1]), load_lanes<T>(in.q0[2])});
  Model<T> model(s, in, resolver, trig);
  trajectory_loop<T>(model, out);
}

}  // namespace ks::kernel
