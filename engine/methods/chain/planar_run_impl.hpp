#pragma once
// The definition of planar_chain_run_n<N> (methods/chain/planar_run.hpp), included by the files that
// instantiate it. The loop is methods/chain/trajectory.cpp's, step for step (same samples, statuses,
// metrics and history), with the chain's dynamics from model/planar_chain_dynamics.hpp and the
// resolutions written out on fixed-size arrays: an LDL^T factor of M (N x N) and one of
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

  Stepper(const PlanarChainConstants<N>& k, const QuinticPath<3>& path, const TrajectoryOptions& o,
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
  const QuinticPath<3>& path_;
  const TrajectoryOptions& o_;
  const std::optional<Profile1>& alpha_;
  // the limit spring (TrajectoryOptions::limit_centring): the limits' middle in u = sigma q
  bool spring_ = false;
  bool sprung_[N] = {};
  double centre_[N] = {};
};

/// The loop of one run from q_start at rest.
template <int N, TaskSpace S, Resolution R>
TrajectoryMetrics run(const Chain& chain, const ChainTask& task, const VecN& q_start, const TrajectoryOptions& o,
                      const std::optional<Profile1>& alpha_profile, ChainHistory* history) {
  constexpr int m = task_dimension(S), P = position_rows(S);
  static_assert(P == 2);
  const SampledPath3& sampled = task.path;
  const QuinticPath<3>& path = sampled.path();
  const std::size_t n = sampled.size();
  const PlanarChainConstants<N> k(chain);
  const double alpha_offset = PlanarAngle(chain).offset;
  const LimitTable limits = LimitTable::of(chain);
  const Stepper<N, S, R> stepper(k, path, o, alpha_profile, limits);
  const auto alpha_of = [&](const double* u) {  // the tip angle at u [rad]
    double a = 0;
    for (int j = 0; j < N; ++j) a += u[j];
    return alpha_offset + a;
  };
  const bool closed = o.closed_loop();
  constexpr bool oriented = m == 3;
  const RunShape shape{N, oriented, false, limits.any() ? &limits : nullptr};

  RunStatus status = RunStatus::ok;
  Evaluation<N, m> e, s;  // e: at the sample; s: RK4 stages
  // q, qd, qdd, tau: in the coordinates u = sigma q of the kernel (model/planar_chain_dynamics.hpp)
  double q[N], qd[N], tau[N], abs_tau[N];
  for (int j = 0; j < N; ++j) q[j] = k.sigma[j] * q_start[j], qd[j] = 0.0;
  PlanarChainTrig<N> trig, stage;  // trig: the sample's, carried from step to step (semi-implicit Euler)
  trig.reset(k, q);
  SampleSums<double, N> sums(o.tracking_bound, o.orientation_bound, shape.limits);
  const auto keep = [](double updated, double) { return updated; };
  const double dt = o.dt;
  double xdd[m];
  double fb[7] = {}, fh[7] = {}, f1[7] = {};  // closed loop: path position (3), velocity (3), arm angle
  sums.start_alpha(alpha_of(q));

  for (std::size_t i = 0; i < n; ++i) {
    const double t = sampled.time(i);
    stepper.task(sampled, i, xdd);
    if (closed || oriented) stepper.desired(t, sampled.segment(i), fb, fb + 3);
    const double alpha = alpha_of(q);
    fb[6] = alpha;
    if (!stepper.evaluate(xdd, q, trig.s, trig.c, qd, e, closed ? fb : nullptr)) {
      status = RunStatus::singular;
      break;
    }
    double tt = 0, p6 = 0;
    bool bounded = true;
    for (int j = 0; j < N; ++j) {
      double Mqdd = 0;
      for (int l = 0; l < N; ++l) Mqdd += e.st.M[j][l] * e.qdd[l];
      const double tj = Mqdd + e.st.c[j] + e.st.g[j];
      tau[j] = tj;
      tt += tj * tj;
      const double pj = tj * qd[j];
      p6 += pj * pj;
      abs_tau[j] = std::abs(tj);
      bounded = bounded && abs_tau[j] <= o.torque_bound;  // NaN fails the comparison
    }
    // one test catches non-finite values and the bound
    if (!(bounded && std::isfinite(tt))) {
      status = RunStatus::diverged;
      break;
    }
    // metrics of this sample
    double qa[N], qda[N], taua[N];  // in the chain's coordinates q = sigma u
    for (int j = 0; j < N; ++j) qa[j] = k.sigma[j] * q[j], qda[j] = k.sigma[j] * qd[j], taua[j] = k.sigma[j] * tau[j];
    SampleValues<double> v;
    v.n = N, v.q = qa, v.qd = qda, v.tau = taua;
    v.tt = tt, v.ff = 0.0, v.p6 = p6;
    double z[N];
    for (int j = 0; j < N; ++j) z[j] = tau[j];
    v.qf = e.Mf.inverse_quadratic_form(z), v.det = 1.0;  // tau^T M^-1 tau
    if constexpr (P == m && R != Resolution::nonredundant)
      v.w2 = e.w2;
    else
      v.w2 = gram_det<P>(e.st.J);
    const Eigen::Vector3d ref = sampled.position(i);
    const double ex = e.st.px - ref[0], ey = e.st.py - ref[1];
    v.err2 = ex * ex + ey * ey;
    v.orient = oriented ? std::abs(alpha - fb[2]) : 0.0;
    v.alpha = alpha;
    double ke = 0;  // qd^T M qd / 2: the same in the kernel's coordinates u = sigma q
    for (int j = 0; j < N; ++j) {
      double Mqd = 0;
      for (int l = 0; l < N; ++l) Mqd += e.st.M[j][l] * qd[l];
      ke += qd[j] * Mqd;
    }
    v.ke = 0.5 * ke;
    const bool off = sums.add(i, t, v, abs_tau, N, keep);
    bool beyond = false;
    if (shape.limits) beyond = sums.limits(qa, qda, tau, N);
    sums.mark(off, beyond);
    if (history && (i % history->stride == 0 || i + 1 == n)) {
      const Eigen::Index col = history->size++;
      history->t[col] = t;
      for (int j = 0; j < N; ++j) {
        history->q(j, col) = k.sigma[j] * q[j];
        history->qd(j, col) = k.sigma[j] * qd[j];
        history->qdd(j, col) = k.sigma[j] * e.qdd[j];
        history->tau(j, col) = k.sigma[j] * tau[j];
      }
      history->x(0, col) = e.st.px;
      history->x(1, col) = e.st.py;
      history->alpha[col] = alpha;
    }
    if (o.on_violation == OnViolation::stop && (off || beyond)) break;
    if (i + 1 == n) break;  // the last sample is measured, not integrated past
    // integrate to the next sample
    if (o.integrator == Integrator::semi_implicit_euler) {
      double dq[N];
      for (int j = 0; j < N; ++j) {
        qd[j] += dt * e.qdd[j];
        dq[j] = dt * qd[j];
        q[j] += dq[j];
      }
      trig.advance(k, q, dq);
    } else {
      const double h = 0.5 * dt, th = t + h, t1 = t + dt;
      const std::size_t sh = path.segment_at(th), s1 = path.segment_at(t1);
      double xh[m], x1[m], k2q[N], k3q[N], k4q[N], k2v[N], k3v[N], yq[N], yv[N];
      stepper.task(th, sh, xh);
      stepper.task(t1, s1, x1);
      if (closed) {
        stepper.desired(th, sh, fh, fh + 3);
        stepper.desired(t1, s1, f1, f1 + 3);
      }
      // stage 2 at (q + h k1q, qd + h k1v) with k1q = qd, k1v = qdd
      for (int j = 0; j < N; ++j) {
        yq[j] = q[j] + h * qd[j];
        k2q[j] = yv[j] = qd[j] + h * e.qdd[j];
      }
      stage.reset(k, yq);
      fh[6] = alpha_of(yq);
      bool good = stepper.evaluate(xh, yq, stage.s, stage.c, yv, s, closed ? fh : nullptr);
      for (int j = 0; j < N; ++j) {
        k2v[j] = s.qdd[j];
        yq[j] = q[j] + h * k2q[j];
        k3q[j] = yv[j] = qd[j] + h * k2v[j];
      }
      stage.reset(k, yq);
      fh[6] = alpha_of(yq);
      good = good && stepper.evaluate(xh, yq, stage.s, stage.c, yv, s, closed ? fh : nullptr);
      for (int j = 0; j < N; ++j) {
        k3v[j] = s.qdd[j];
        yq[j] = q[j] + dt * k3q[j];
        k4q[j] = yv[j] = qd[j] + dt * k3v[j];
      }
      stage.reset(k, yq);
      f1[6] = alpha_of(yq);
      good = good && stepper.evaluate(x1, yq, stage.s, stage.c, yv, s, closed ? f1 : nullptr);
      if (!good) {
        status = RunStatus::singular;
        break;
      }
      const double w = dt / 6.0;
      for (int j = 0; j < N; ++j) {
        const double k4v = s.qdd[j];
        q[j] += w * (qd[j] + 2.0 * k2q[j] + 2.0 * k3q[j] + k4q[j]);
        qd[j] += w * (e.qdd[j] + 2.0 * k2v[j] + 2.0 * k3v[j] + k4v);
      }
      trig.reset(k, q);
    }
  }
  return finish_run(sums.of_lane(0, status, N), shape, o);
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
