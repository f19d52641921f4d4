// simulate(): the seed's loop (Appendix F) with solves instead of inverses, fixed-size types and no
// allocation per step. The per-sample arithmetic is written element by element: Eigen's two-lane
// packets on 3-vectors would load, as one 16-byte read, two scalars the step has just stored, and
// such a load cannot be forwarded from the store buffer (a stall of the whole step on x86).
#include "methods/trajectory.hpp"

#include <Eigen/LU>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "methods/resolution.hpp"
#include "methods/run_sums.hpp"
#include "model/dynamics.hpp"

namespace ks {

bool samples_path(const std::vector<double>& durations, double dt) {
  for (double d : durations)
    if (!(d / dt >= kMinSamplesPerSegment * (1 - 1e-12))) return false;
  return true;
}

TrajectoryMetrics not_simulated(RunStatus status, int joints) {
  TrajectoryMetrics out;
  out.status = status;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.E = out.E_M = out.min_manipulability = out.torque_sq_integral = out.power_sq_integral = nan;
  out.max_tracking_error = out.final_alpha = nan;
  out.tau_inf.setConstant(joints, nan);
  return out;
}

void TrajectoryHistory::prepare(std::size_t samples) {
  const Eigen::Index n = static_cast<Eigen::Index>((samples + stride - 1) / stride + 1);
  if (t.size() < n) {
    t.resize(n);
    q.resize(3, n);
    qd.resize(3, n);
    qdd.resize(3, n);
    tau.resize(3, n);
    x.resize(2, n);
    alpha.resize(n);
  }
  size = 0;
}

namespace {

/// What the path asks of the arm at one instant.
struct TaskSample {
  Vec2 a;           // path acceleration [m/s^2]
  double alpha_dd;  // vertex_alpha: orientation acceleration [rad/s^2]
};

/// Everything one evaluation of the method at (t, q, qd) produces.
struct Evaluation {
  Sym3 M;
  SymInverse3 Mi;  // M^-1 as adj(M) / det(M)
  Vec3 c, g, qdd;
  Mat23 J;
  double w2;     // squared manipulability det(J J^T) (the square root is taken once, at the end)
};

class Resolver {
 public:
  Resolver(const PlanarArm3& arm, const Path2& path, const TrajectoryOptions& o,
           const std::optional<Profile1>& alpha_profile)
      : arm_(arm), dyn_(arm), path_(path), o_(o), alpha_(alpha_profile) {}

  /// The task at time t on segment `segment` (for times off the sample grid: RK4's stages).
  TaskSample task(double t, std::size_t segment) const {
    return {path_.sample_on(segment, t).a, alpha_ ? alpha_->sample_on(segment, t).a[0] : 0.0};
  }
  /// The task at sample i of the sampled path.
  TaskSample task(const SampledPath& p, std::size_t i) const {
    return {p.acceleration(i), alpha_ ? alpha_->sample_on(p.segment(i), p.time(i)).a[0] : 0.0};
  }
  /// Joint accelerations of the method for task x at (q, qd); fills every intermediate in `e`.
  /// Returns false when the Jacobian is singular.
  bool evaluate(const TaskSample& x, const Vec3& q, const Vec3& qd, Evaluation& e) const {
    return evaluate(x, joint_trig(q), qd, e);
  }
  /// The same with the joint trig of q given (see TrigTracker).
  bool evaluate(const TaskSample& x, const JointTrig& trig, const Vec3& qd, Evaluation& e) const {
    e.M = mass_matrix_sym(dyn_, trig);
    e.c = coriolis(dyn_, trig, qd);
    e.g = gravity(dyn_, trig);
    e.J = jacobian(arm_, trig);
    e.Mi = SymInverse3(e.M);
    const Vec2 jdqd = jacobian_dot_times_qd(arm_, trig, qd);
    const Vec2 b(x.a[0] - jdqd[0], x.a[1] - jdqd[1]);
    if (o_.method == TrajectoryMethod::vertex_alpha) {
      double det = 0;
      e.qdd = nonredundant_acceleration(e.J, b, x.alpha_dd, det);
      e.w2 = manipulability_squared(e.J);
      return std::abs(det) >= o_.singular_tolerance;
    }
    e.w2 = manipulability_squared(e.J);
    if (!(e.w2 >= o_.singular_tolerance * o_.singular_tolerance)) return false;
    const Weighting w = o_.method == TrajectoryMethod::local_unweighted ? Weighting::inertia_squared : Weighting::inertia;
    e.qdd = local_acceleration(w, e.Mi, e.J, b, e.c, e.g, o_.k, o_.null_damping, qd);
    return true;
  }

 private:
  const PlanarArm3 arm_;
  const DynamicsCoefficients dyn_;
  const Path2& path_;
  const TrajectoryOptions& o_;
  const std::optional<Profile1>& alpha_;
};

}  // namespace

TrajectoryMetrics simulate(const PlanarArm3& arm, const Path2& path, const TrajectoryOptions& o,
                           TrajectoryHistory* history) {
  return simulate(arm, SampledPath(path, o.dt), o, history);
}

TrajectoryMetrics simulate(const PlanarArm3& arm, const SampledPath& sampled, const TrajectoryOptions& o,
                           TrajectoryHistory* history) {
  if (sampled.dt() != o.dt)
    throw std::invalid_argument("simulate: path sampled at dt = " + std::to_string(sampled.dt()) +
                                " s, options ask for dt = " + std::to_string(o.dt) + " s");
  const Path2& path = sampled.path();
  TrajectoryMetrics out;
  std::optional<Profile1> alpha_profile;
  if (o.method == TrajectoryMethod::vertex_alpha) {
    if (o.vertex_alpha.size() != path.segments())
      throw std::invalid_argument("vertex_alpha needs one alpha per vertex after the first (" +
                                  std::to_string(path.segments()) + ")");
    std::vector<Eigen::Matrix<double, 1, 1>> a{Eigen::Matrix<double, 1, 1>(o.alpha1A)};
    for (double v : o.vertex_alpha) a.emplace_back(v);
    alpha_profile.emplace(std::move(a), path.durations());
  }
  const std::size_t n = sampled.size();
  if (history) history->prepare(n);

  const std::optional<Vec3> q0 = inverse_kinematics(arm, path.vertices().front(), o.alpha1A, o.elbow);
  if (!q0) {
    out.status = RunStatus::unreachable_start;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    out.E = out.E_M = out.min_manipulability = out.torque_sq_integral = out.power_sq_integral = nan;
    out.max_tracking_error = out.final_alpha = nan;
    out.tau_inf.setConstant(3, nan);
    return out;
  }
  Vec3 q = *q0, qd = Vec3::Zero();
  const Resolver resolver(arm, path, o, alpha_profile);
  Evaluation e, s;  // e: at the sample; s: RK4 stages
  TrigTracker trig(q);  // the sample's trig, carried from step to step (semi-implicit Euler)
  RootSums roots;
  double min_w2 = std::numeric_limits<double>::infinity(), max_err2 = 0;
  TrapezoidSums trapezoid;
  double inf0 = 0, inf1 = 0, inf2 = 0;
  const double dt = o.dt;
  std::size_t done = 0;
  double last_t = 0, last_alpha = q[0] + q[1] + q[2];

  for (std::size_t i = 0; i < n; ++i) {
    const double t = sampled.time(i);
    if (!resolver.evaluate(resolver.task(sampled, i), trig.trig(), qd, e)) {
      out.status = RunStatus::singular;
      break;
    }
    const Vec3 Mqdd = e.M * e.qdd;
    const double tau0 = Mqdd[0] + e.c[0] + e.g[0], tau1 = Mqdd[1] + e.c[1] + e.g[1], tau2 = Mqdd[2] + e.c[2] + e.g[2];
    const Vec3 tau(tau0, tau1, tau2);
    const double a0 = std::abs(tau0), a1 = std::abs(tau1), a2 = std::abs(tau2);
    const double tt = tau0 * tau0 + tau1 * tau1 + tau2 * tau2;
    // NaN fails every comparison: one test catches non-finite values and the bound
    if (!(a0 <= o.torque_bound && a1 <= o.torque_bound && a2 <= o.torque_bound && std::isfinite(tt))) {
      out.status = RunStatus::diverged;
      break;
    }
    // metrics of this sample
    roots.add(tt, e.Mi.P.quadratic_form(tau), e.Mi.det);
    inf0 = std::max(inf0, a0);
    inf1 = std::max(inf1, a1);
    inf2 = std::max(inf2, a2);
    min_w2 = std::min(min_w2, e.w2);
    const Vec2 ref = sampled.position(i);
    const double ex = e.J(1, 0) - ref[0], ey = -e.J(0, 0) - ref[1];  // tip = (x1, y1) = (J10, -J00)
    max_err2 = std::max(max_err2, ex * ex + ey * ey);
    const double p0 = tau0 * qd[0], p1 = tau1 * qd[1], p2 = tau2 * qd[2];
    const double p6 = p0 * p0 + p1 * p1 + p2 * p2;
    trapezoid.add(i, tt, p6);
    last_t = t;
    last_alpha = q[0] + q[1] + q[2];
    if (history && (i % history->stride == 0 || i + 1 == n)) {
      const Eigen::Index c = history->size++;
      history->t[c] = t;
      history->q.col(c) = q;
      history->qd.col(c) = qd;
      history->qdd.col(c) = e.qdd;
      history->tau.col(c) = tau;
      history->x.col(c) = end_effector_from_jacobian(e.J);
      history->alpha[c] = last_alpha;
    }
    ++done;
    if (i + 1 == n) break;  // the last sample is measured, not integrated past
    // integrate to the next sample
    if (o.integrator == Integrator::semi_implicit_euler) {
      for (int j = 0; j < 3; ++j) qd[j] += dt * e.qdd[j];
      const Vec3 dq(dt * qd[0], dt * qd[1], dt * qd[2]);
      for (int j = 0; j < 3; ++j) q[j] += dq[j];
      trig.advance(q, dq);
    } else {
      const double th = t + 0.5 * dt, t1 = t + dt;
      const std::size_t sh = path.segment_at(th), s1 = path.segment_at(t1);
      const Vec3 k1q = qd, k1v = e.qdd;
      const TaskSample xh = resolver.task(th, sh), x1 = resolver.task(t1, s1);
      bool good = resolver.evaluate(xh, q + 0.5 * dt * k1q, qd + 0.5 * dt * k1v, s);
      const Vec3 k2q = qd + 0.5 * dt * k1v, k2v = s.qdd;
      good = good && resolver.evaluate(xh, q + 0.5 * dt * k2q, qd + 0.5 * dt * k2v, s);
      const Vec3 k3q = qd + 0.5 * dt * k2v, k3v = s.qdd;
      good = good && resolver.evaluate(x1, q + dt * k3q, qd + dt * k3v, s);
      if (!good) {
        out.status = RunStatus::singular;
        break;
      }
      const Vec3 k4q = qd + dt * k3v, k4v = s.qdd;
      q += dt / 6.0 * (k1q + 2.0 * k2q + 2.0 * k3q + k4q);
      qd += dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
      trig.reset(q);
    }
  }
  roots.flush();
  if (done > 0) out.tau_inf = Vec3(inf0, inf1, inf2);  // VecN of size 3: no allocation
  finish_metrics(out, done, roots.sumE, roots.sumEM, min_w2, max_err2, trapezoid, dt, last_alpha, last_t);
  return out;
}

}  // namespace ks
