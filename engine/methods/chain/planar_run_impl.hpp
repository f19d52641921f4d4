#pragma once
// The definition of planar_chain_run_n<N> (methods/chain/planar_run.hpp), included by the files that
// instantiate it: the planar chain as a model of the one trajectory loop
// (methods/loop/trajectory_loop.hpp), with the chain's dynamics from model/planar_chain_dynamics.hpp
// and the resolutions written out on fixed-size arrays: an LDL^T factor of M (N x N) and one of
// A = J W^-1 J^T (m x m), N + m divisions per evaluation.
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "methods/chain/resolution.hpp"
#include "methods/base/fixed_ldlt.hpp"
#include "methods/metrics/run_sums.hpp"
#include "methods/metrics/sample_sums.hpp"
#include "methods/chain/planar_run.hpp"
#include "methods/loop/trajectory_loop.hpp"
#include "model/planar_chain_dynamics.hpp"

namespace ks {
namespace planar_run {

enum class Resolution { weighted, unweighted, nonredundant };

/// Everything one evaluation of the method at (t, q, qd) produces.
template <int N, int m>
struct Evaluation {
  PlanarChainState<N, m> st;
  FixedLdlt<N> Mf;  // M = L D L^T
  double qdd[N];
  double w2 = 0;    // det(J J^T) of the task rows (local methods)
};

/// det(G) of the Gram matrix G = J J^T of the first k task rows of J (k = 2 or 3), clamped at 0 from
/// below (rounding at a singular configuration) [(m or rad)^(2k) per rad^2].
template <int k, int N, int m>
double gram_det(const double (&J)[m][N]) {
  static_assert(k <= m && (k == 2 || k == 3));
  double G[k][k];
  for (int r = 0; r < k; ++r)
    for (int s = 0; s <= r; ++s) {
      double a = 0;
      for (int j = 0; j < N; ++j) a += J[r][j] * J[s][j];
      G[r][s] = a;
    }
  double d;
  if constexpr (k == 2) {
    d = G[0][0] * G[1][1] - G[1][0] * G[1][0];
  } else {
    d = G[0][0] * (G[1][1] * G[2][2] - G[2][1] * G[2][1]) - G[1][0] * (G[1][0] * G[2][2] - G[2][1] * G[2][0]) +
        G[2][0] * (G[1][0] * G[2][1] - G[1][1] * G[2][0]);
  }
  return d > 0.0 ? d : 0.0;
}

/// The method at one instant: joint accelerations from the task acceleration and (q, qd).
template <int N, TaskSpace S, Resolution R>
class Stepper {
 public:
  static constexpr int m = task_dimension(S);

  Stepper(const PlanarChainConstants<N>& k, const TaskPath<3>& path, const TrajectoryOptions& o,
          const std::optional<Profile1>& alpha, const LimitTable& limits)
      : k_(k), path_(path), o_(o), alpha_(alpha) {
    spring_ = o.limit_centring != 0.0 && limits.any_position;
    for (int j = 0; j < N; ++j) centre_[j] = k.sigma[j] * limits.mid[j], sprung_[j] = limits.inv_half[j] != 0.0;
  }

  /// Task acceleration xdd (m) at time t [s] on path segment `segment`.
  void task(double t, std::size_t segment, double* xdd) const { task_of(path_.sample_on(segment, t).a, segment, t, xdd); }
  /// Task acceleration xdd (m) at sample i of the sampled path.
  void task(const SampledPath3& p, std::size_t i, double* xdd) const {
    task_of(p.acceleration(i), p.segment(i), p.time(i), xdd);
  }

  /// Where the path wants the tip at time t on `segment`: position p (2) [m], velocity v (2) [m/s],
  /// for planar_pose the tip angle and its rate in p[2], v[2] [rad, rad/s].
  void desired(double t, std::size_t segment, double* p, double* v) const {
    const PathSample<3> x = path_.sample_on(segment, t);
    p[0] = x.p[0], p[1] = x.p[1], v[0] = x.v[0], v[1] = x.v[1];
    if constexpr (m == 3) {
      const PathSample<1> a = alpha_->sample_on(segment, t);
      p[2] = a.p[0], v[2] = a.v[0];
    }
  }

  /// Joint accelerations e.qdd for task acceleration xdd (m) at u (N, the kernel's coordinates), the
  /// frames' trig of u (s, c) and qd (N);
  /// fills every intermediate in `e`. With fb (closed loop: the path's position and velocity as
  /// desired() gives them, then the arm's tip angle at this state), xdd + K_D (v - J qd) + K_P (p - x)
  /// is commanded instead. Returns false when the task Jacobian is singular.
  bool evaluate(const double* xdd, const double* u, const double* s, const double* c, const double* qd,
                Evaluation<N, m>& e, const double* fb = nullptr) const {
    planar_chain_state<N, m>(k_, s, c, qd, e.st);
    double b[m];
    for (int r = 0; r < m; ++r) b[r] = xdd[r] - e.st.bias[r];
    if (fb) {
      const double* p = fb;
      const double* v = fb + 3;
      const double x[3] = {e.st.px, e.st.py, fb[6]};
      for (int r = 0; r < m; ++r) {
        double xd = 0;
        for (int j = 0; j < N; ++j) xd += e.st.J[r][j] * qd[j];
        b[r] += o_.clik_kd * (v[r] - xd) + o_.clik_kp * (p[r] - x[r]);
      }
    }
    e.Mf.compute(e.st.M);
    if constexpr (R == Resolution::nonredundant) {
      static_assert(N == m);
      Eigen::Matrix<double, m, m> J;
      Eigen::Matrix<double, m, 1> bv;
      for (int r = 0; r < m; ++r) {
        for (int j = 0; j < N; ++j) J(r, j) = e.st.J[r][j];
        bv[r] = b[r];
      }
      const Eigen::PartialPivLU<Eigen::Matrix<double, m, m>> lu(J);
      const Eigen::Matrix<double, m, 1> x = lu.solve(bv);
      for (int j = 0; j < N; ++j) e.qdd[j] = x[j];
      return std::abs(lu.determinant()) >= o_.singular_tolerance;
    } else {
      e.w2 = gram_det<m>(e.st.J);
      if (!(e.w2 >= o_.singular_tolerance * o_.singular_tolerance)) return false;
      local_acceleration(e, b, u, qd);
      return true;
    }
  }

 private:
  /// qdd = Y A^-1 (b + J v) - v with Y = W^-1 J^T, A = J Y, v = M^-1 (c + k g) + K_N qd + K_L (u - u_mid)
  /// (see local_acceleration in methods/chain/resolution.hpp).
  void local_acceleration(Evaluation<N, m>& e, const double* b, const double* u, const double* qd) const {
    const auto& J = e.st.J;
    double Y[m][N], v[N];
    for (int s = 0; s < m; ++s) {
      for (int j = 0; j < N; ++j) Y[s][j] = J[s][j];
      e.Mf.solve(Y[s]);
      if constexpr (R == Resolution::unweighted) e.Mf.solve(Y[s]);
    }
    for (int j = 0; j < N; ++j) v[j] = e.st.c[j] + o_.k * e.st.g[j];
    e.Mf.solve(v);
    if (o_.null_damping != 0.0)
      for (int j = 0; j < N; ++j) v[j] += o_.null_damping * qd[j];
    if (spring_)
      for (int j = 0; j < N; ++j)
        if (sprung_[j]) v[j] += o_.limit_centring * (u[j] - centre_[j]);
    double A[m][m], r[m];
    for (int s = 0; s < m; ++s) {
      for (int t = 0; t <= s; ++t) {
        double a = 0;
        for (int j = 0; j < N; ++j) a += J[s][j] * Y[t][j];
        A[s][t] = a;  // the factor reads the lower triangle
      }
      double jv = 0;
      for (int j = 0; j < N; ++j) jv += J[s][j] * v[j];
      r[s] = b[s] + jv;
    }
    FixedLdlt<m> Af;
    Af.compute(A);
    Af.solve(r);
    for (int j = 0; j < N; ++j) {
      double x = -v[j];
      for (int s = 0; s < m; ++s) x += Y[s][j] * r[s];
      e.qdd[j] = x;
    }
  }

  void task_of(const Eigen::Vector3d& a, std::size_t segment, double t, double* xdd) const {
    xdd[0] = a[0];
    xdd[1] = a[1];
    if constexpr (m == 3) xdd[2] = alpha_->sample_on(segment, t).a[0];
  }

  const PlanarChainConstants<N>& k_;
  const TaskPath<3>& path_;
  const TrajectoryOptions& o_;
  const std::optional<Profile1>& alpha_;
  // the limit spring (TrajectoryOptions::limit_centring): the limits' middle in u = sigma q
  bool spring_ = false;
  bool sprung_[N] = {};
  double centre_[N] = {};
};

/// The fixed-size planar chain as methods/loop/trajectory_loop.hpp's model. The loop's state is in
/// the kernel's coordinates u = sigma q (model/planar_chain_dynamics.hpp); values() and record()
/// report the chain's.
template <int N, TaskSpace S, Resolution R>
class PlanarModel {
 public:
  static constexpr int max_joints = N;
  static constexpr int m = task_dimension(S);
  static_assert(position_rows(S) == 2);
  static constexpr bool oriented = m == 3;
  using Evaluation = planar_run::Evaluation<N, m>;

  PlanarModel(const Chain& chain, const ChainTask& task, const VecN& q_start, const TrajectoryOptions& o,
              const std::optional<Profile1>& alpha, ChainHistory* history)
      : k_(chain), sampled_(task.path), o_(o), q_start_(q_start), history_(history), limits_(LimitTable::of(chain)),
        stepper_(k_, task.path.path(), o, alpha, limits_), alpha_offset_(PlanarAngle(chain).offset),
        closed_(o.closed_loop()) {}

  int joints() const { return N; }
  LoopShape shape() const { return {sampled_.size(), o_.dt, o_.integrator, o_.on_violation == OnViolation::stop}; }
  RunShape run_shape() const { return RunShape{N, oriented, false, limits_.any() ? &limits_ : nullptr}; }
  SampleSums<double, N> sums() const {
    return SampleSums<double, N>(o_.tracking_bound, o_.orientation_bound, limits_.any() ? &limits_ : nullptr);
  }
  static constexpr bool prismatic_joints = false;
  bool start(double* u) {
    for (int j = 0; j < N; ++j) u[j] = k_.sigma[j] * q_start_[j];
    trig_.reset(k_, u);
    return true;
  }
  double torque_bound() const { return o_.torque_bound; }
  /// The tip angle at u [rad].
  double alpha(const double* u) const {
    double a = 0;
    for (int j = 0; j < N; ++j) a += u[j];
    return alpha_offset_ + a;
  }

  bool at_sample(std::size_t i, double t, const double* u, const double* ud, Evaluation& e) {
    stepper_.task(sampled_, i, xdd_);
    if (closed_ || oriented) stepper_.desired(t, sampled_.segment(i), fb_, fb_ + 3);
    fb_[6] = alpha(u);
    return stepper_.evaluate(xdd_, u, trig_.s, trig_.c, ud, e, closed_ ? fb_ : nullptr);
  }
  void torques(const Evaluation& e, const double*, double* tau) const {
    for (int j = 0; j < N; ++j) {
      double Mqdd = 0;
      for (int l = 0; l < N; ++l) Mqdd += e.st.M[j][l] * e.qdd[l];
      tau[j] = Mqdd + e.st.c[j] + e.st.g[j];
    }
  }

  void values(const Evaluation& e, std::size_t i, const double* u, const double* ud, const double* tau,
              SampleValues<double>& v) {
    for (int j = 0; j < N; ++j) qa_[j] = k_.sigma[j] * u[j], qda_[j] = k_.sigma[j] * ud[j], taua_[j] = k_.sigma[j] * tau[j];
    v.q = qa_, v.qd = qda_, v.tau = taua_;
    double z[N];
    for (int j = 0; j < N; ++j) z[j] = tau[j];
    v.qf = e.Mf.inverse_quadratic_form(z), v.det = 1.0;  // tau^T M^-1 tau
    if constexpr (m == 2 && R != Resolution::nonredundant)
      v.w2 = e.w2;
    else
      v.w2 = gram_det<2>(e.st.J);
    const Eigen::Vector3d ref = sampled_.position(i);
    const double ex = e.st.px - ref[0], ey = e.st.py - ref[1];
    v.err2 = ex * ex + ey * ey;
    v.orient = oriented ? std::abs(fb_[6] - fb_[2]) : 0.0;
    v.alpha = fb_[6];
    double ke = 0;  // qd^T M qd / 2: the same in the kernel's coordinates u = sigma q
    for (int j = 0; j < N; ++j) {
      double Mqd = 0;
      for (int l = 0; l < N; ++l) Mqd += e.st.M[j][l] * ud[l];
      ke += ud[j] * Mqd;
    }
    v.ke = 0.5 * ke;
  }

  void record(std::size_t i, double t, const Evaluation& e, const double* u, const double* ud, const double* tau,
              bool) {
    if (!history_ || !(i % history_->stride == 0 || i + 1 == sampled_.size())) return;
    ChainHistory& h = *history_;
    const Eigen::Index col = h.size++;
    h.t[col] = t;
    for (int j = 0; j < N; ++j) {
      h.q(j, col) = k_.sigma[j] * u[j];
      h.qd(j, col) = k_.sigma[j] * ud[j];
      h.qdd(j, col) = k_.sigma[j] * e.qdd[j];
      h.tau(j, col) = k_.sigma[j] * tau[j];
    }
    h.x(0, col) = e.st.px;
    h.x(1, col) = e.st.py;
    h.alpha[col] = fb_[6];
  }

  void stages(double t, double dt) {
    const TaskPath<3>& path = sampled_.path();
    const double th = t + 0.5 * dt, t1 = t + dt;
    const std::size_t sh = path.segment_at(th), s1 = path.segment_at(t1);
    stepper_.task(th, sh, xh_);
    stepper_.task(t1, s1, x1_);
    if (closed_) {
      stepper_.desired(th, sh, fh_, fh_ + 3);
      stepper_.desired(t1, s1, f1_, f1_ + 3);
    }
  }
  bool stage(bool end, const double* yq, const double* yv, Evaluation& s) {
    stage_.reset(k_, yq);
    double* f = end ? f1_ : fh_;
    f[6] = alpha(yq);
    return stepper_.evaluate(end ? x1_ : xh_, yq, stage_.s, stage_.c, yv, s, closed_ ? f : nullptr);
  }
  /// The sample's trig carried along (semi-implicit Euler's step dq) or recomputed at u (RK4).
  void moved(const double* u, const double* dq) {
    if (dq)
      trig_.advance(k_, u, dq);
    else
      trig_.reset(k_, u);
  }

 private:
  const PlanarChainConstants<N> k_;
  const SampledPath3& sampled_;
  const TrajectoryOptions& o_;
  const VecN& q_start_;
  ChainHistory* history_;
  const LimitTable limits_;
  const Stepper<N, S, R> stepper_;
  const double alpha_offset_;
  const bool closed_;
  PlanarChainTrig<N> trig_, stage_;  // trig_: the sample's, carried from step to step (semi-implicit Euler)
  double xdd_[m], xh_[m], x1_[m];
  double fb_[7] = {}, fh_[7] = {}, f1_[7] = {};  // path position (3), velocity (3), the arm's tip angle
  double qa_[N], qda_[N], taua_[N];               // in the chain's coordinates q = sigma u
};

/// One run from q_start at rest: the one trajectory loop over the planar chain.
template <int N, TaskSpace S, Resolution R>
TrajectoryMetrics run(const Chain& chain, const ChainTask& task, const VecN& q_start, const TrajectoryOptions& o,
                      const std::optional<Profile1>& alpha_profile, ChainHistory* h) {
  PlanarModel<N, S, R> model(chain, task, q_start, o, alpha_profile, h);
  RunSums sums;
  trajectory_loop<double>(model, &sums);
  return finish_run(sums, model.run_shape(), o);
}

}  // namespace planar_run

template <int N>
TrajectoryMetrics planar_chain_run_n(const Chain& chain, const ChainTask& task, const VecN& q_start,
                                     const TrajectoryOptions& o, const std::optional<Profile1>& alpha,
                                     ChainHistory* history) {
  using planar_run::Resolution;
  using planar_run::run;
  constexpr TaskSpace position = TaskSpace::planar_position, pose = TaskSpace::planar_pose;
  if (task.space == position) {
    if (o.method == TrajectoryMethod::local_weighted)
      return run<N, position, Resolution::weighted>(chain, task, q_start, o, alpha, history);
    if (o.method == TrajectoryMethod::local_unweighted)
      return run<N, position, Resolution::unweighted>(chain, task, q_start, o, alpha, history);
  } else if (task.space == pose) {
    if constexpr (N > 3) {
      if (o.method == TrajectoryMethod::local_weighted)
        return run<N, pose, Resolution::weighted>(chain, task, q_start, o, alpha, history);
      if (o.method == TrajectoryMethod::local_unweighted)
        return run<N, pose, Resolution::unweighted>(chain, task, q_start, o, alpha, history);
    }
    if constexpr (N == 3) {
      if (o.method == TrajectoryMethod::vertex_alpha)
        return run<N, pose, Resolution::nonredundant>(chain, task, q_start, o, alpha, history);
    }
  }
  throw std::invalid_argument("planar_chain_run: the task space and method do not fit a planar chain of " +
                              std::to_string(N) + " joints");
}

}  // namespace ks
