// simulate() for a chain: the closed form's loop (methods/trajectory.cpp) over the chain's dynamics
// (model/chain_dynamics.hpp) and the resolutions of methods/chain_resolution.hpp. The task space and
// the method are template parameters of the loop, chosen once per run: the step branches on neither.
// Fixed-maximum-size types throughout: nothing is allocated per step. Planar tasks on planar chains of
// revolute joints take the fixed-size run of methods/planar_chain_run.hpp instead.
#include "methods/chain_trajectory.hpp"
#include "methods/run_sums.hpp"

#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "common/name_table.hpp"
#include "methods/planar_chain_run.hpp"
#include "model/chain_dynamics.hpp"
#include "model/planar_chain_dynamics.hpp"

namespace ks {

namespace {
constexpr NameTable<TaskSpace, 4> kTaskSpaces{{{TaskSpace::planar_position, "planar_position"},
                                              {TaskSpace::planar_pose, "planar_pose"},
                                              {TaskSpace::spatial_position, "spatial_position"},
                                              {TaskSpace::spatial_pose, "spatial_pose"}}};
}  // namespace

std::string_view to_string(TaskSpace s) { return name_of(kTaskSpaces, s); }
bool parse(std::string_view n, TaskSpace& out) { return value_of(kTaskSpaces, n, out); }

void ChainHistory::prepare(std::size_t samples, int joints, int position_rows) {
  const Eigen::Index n = static_cast<Eigen::Index>((samples + stride - 1) / stride + 1);
  if (t.size() < n || q.rows() != joints || x.rows() != position_rows) {
    t.resize(n);
    q.resize(joints, n);
    qd.resize(joints, n);
    qdd.resize(joints, n);
    tau.resize(joints, n);
    x.resize(position_rows, n);
    alpha.resize(n);
  }
  size = 0;
}

namespace {

enum class Resolution { weighted, unweighted, nonredundant };

/// Everything one evaluation of the method at (t, q, qd) produces.
template <int m>
struct Evaluation {
  ChainState st;           // M, c, g, J (6 x n), bias, tip
  InertiaFactor Mf;        // M = L D L^T
  TaskJacobian<m> Jt;      // task rows of J
  VecN qdd;
  double w2 = 0;           // det(Jt Jt^T) (local methods); unused by the non-redundant solve
};

template <TaskSpace S, Resolution R>
class ChainResolver {
 public:
  static constexpr int m = task_dimension(S);

  ChainResolver(const Chain& chain, const QuinticPath<3>& path, const TrajectoryOptions& o,
                const std::optional<Profile1>& alpha)
      : chain_(chain), path_(path), o_(o), alpha_(alpha) {}

  /// The task acceleration at time t on segment `segment` (RK4's stages).
  TaskVec<m> task(double t, std::size_t segment) const { return task_of(path_.sample_on(segment, t).a, segment, t); }
  /// The task acceleration at sample i of the sampled path.
  TaskVec<m> task(const SampledPath3& p, std::size_t i) const {
    return task_of(p.acceleration(i), p.segment(i), p.time(i));
  }

  /// Joint accelerations for task acceleration xdd at (q, qd); fills every intermediate in `e`.
  /// Returns false when the task Jacobian is singular.
  bool evaluate(const TaskVec<m>& xdd, const VecN& q, const VecN& qd, Evaluation<m>& e) {
    evaluate_dynamics(chain_, data_, q, qd, e.st);
    select_task_rows<S>(e.st.J, e.Jt);
    const TaskVec<m> b = xdd - select_task_rows<S>(e.st.bias);
    const int n = static_cast<int>(q.size());
    e.Mf.compute(e.st.M, n);
    if constexpr (R == Resolution::nonredundant) {
      double det = 0;
      e.qdd = nonredundant_acceleration<m>(e.Jt, b, det);
      return std::abs(det) >= o_.singular_tolerance;
    } else {
      e.w2 = gram_determinant<m, m>(e.Jt);
      if (!(e.w2 >= o_.singular_tolerance * o_.singular_tolerance)) return false;
      u_.resize(n);
      for (int j = 0; j < n; ++j) u_[j] = e.st.c[j] + o_.k * e.st.g[j];
      constexpr Weighting w = R == Resolution::unweighted ? Weighting::inertia_squared : Weighting::inertia;
      e.qdd = local_acceleration<m>(w, e.Mf, e.Jt, b, u_, o_.null_damping, qd);
      return true;
    }
  }

 private:
  TaskVec<m> task_of(const Eigen::Vector3d& a, std::size_t segment, double t) const {
    TaskVec<m> x;
    if constexpr (S == TaskSpace::planar_position) {
      x << a[0], a[1];
    } else if constexpr (S == TaskSpace::planar_pose) {
      x << a[0], a[1], alpha_->sample_on(segment, t).a[0];
    } else if constexpr (S == TaskSpace::spatial_position) {
      x = a;
    } else {
      x << a, Eigen::Vector3d::Zero();
    }
    return x;
  }

  const Chain& chain_;
  const QuinticPath<3>& path_;
  const TrajectoryOptions& o_;
  const std::optional<Profile1>& alpha_;
  ChainData data_;
  VecN u_;  // c + k g
};

TrajectoryMetrics unreachable(int n) {
  TrajectoryMetrics out;
  out.status = RunStatus::unreachable_start;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.E = out.E_M = out.min_manipulability = out.torque_sq_integral = out.power_sq_integral = nan;
  out.max_tracking_error = out.final_alpha = nan;
  out.tau_inf.setConstant(n, nan);
  return out;
}

/// The loop of one run from the start q_start at rest.
template <TaskSpace S, Resolution R>
TrajectoryMetrics run(const Chain& chain, const ChainTask& task, const VecN& q_start, const TrajectoryOptions& o,
                      const std::optional<Profile1>& alpha_profile, ChainHistory* history) {
  constexpr int m = task_dimension(S), P = position_rows(S);
  const SampledPath3& sampled = task.path;
  const QuinticPath<3>& path = sampled.path();
  const std::size_t n = sampled.size();
  const int dof = chain.dof();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::optional<PlanarAngle> angle = is_planar(S) ? std::optional<PlanarAngle>(PlanarAngle(chain)) : std::nullopt;

  TrajectoryMetrics out;
  ChainResolver<S, R> resolver(chain, path, o, alpha_profile);
  Evaluation<m> e, s;  // e: at the sample; s: RK4 stages
  VecN q = q_start, qd = VecN::Zero(dof), tau(dof), z(dof), inf = VecN::Zero(dof);
  VecN k1q, k1v, k2q, k2v, k3q, k3v, k4q, k4v;
  double sumE = 0, sumEM = 0, min_w2 = std::numeric_limits<double>::infinity(), max_err2 = 0;
  TrapezoidSums trapezoid;
  const double dt = o.dt;
  std::size_t done = 0;
  double last_t = 0, last_alpha = angle ? (*angle)(q) : nan;

  for (std::size_t i = 0; i < n; ++i) {
    const double t = sampled.time(i);
    if (!resolver.evaluate(resolver.task(sampled, i), q, qd, e)) {
      out.status = RunStatus::singular;
      break;
    }
    double tt = 0, p6 = 0;
    bool bounded = true;
    for (int j = 0; j < dof; ++j) {
      double Mqdd = 0;
      for (int k = 0; k < dof; ++k) Mqdd += e.st.M(j, k) * e.qdd[k];
      const double tj = Mqdd + e.st.c[j] + e.st.g[j];
      tau[j] = z[j] = tj;
      tt += tj * tj;
      const double pj = tj * qd[j];
      p6 += pj * pj;
      const double a = std::abs(tj);
      bounded = bounded && a <= o.torque_bound;  // NaN fails the comparison
    }
    // one test catches non-finite values and the bound
    if (!(bounded && std::isfinite(tt))) {
      out.status = RunStatus::diverged;
      break;
    }
    // metrics of this sample
    for (int j = 0; j < dof; ++j) inf[j] = std::max(inf[j], std::abs(tau[j]));
    sumE += std::sqrt(tt);
    sumEM += std::sqrt(e.Mf.inverse_quadratic_form(z.data()));  // tau^T M^-1 tau
    if constexpr (P == m && R != Resolution::nonredundant)
      min_w2 = std::min(min_w2, e.w2);
    else
      min_w2 = std::min(min_w2, gram_determinant<P, m>(e.Jt));
    const Eigen::Matrix<double, P, 1> err = e.st.tip.p.template head<P>() - sampled.position(i).template head<P>();
    max_err2 = std::max(max_err2, err.squaredNorm());
    trapezoid.add(i, tt, p6);
    last_t = t;
    if (angle) last_alpha = (*angle)(q);
    if (history && (i % history->stride == 0 || i + 1 == n)) {
      const Eigen::Index c = history->size++;
      history->t[c] = t;
      history->q.col(c) = q;
      history->qd.col(c) = qd;
      history->qdd.col(c) = e.qdd;
      history->tau.col(c) = tau;
      history->x.col(c) = e.st.tip.p.template head<P>();
      history->alpha[c] = last_alpha;
    }
    ++done;
    if (i + 1 == n) break;  // the last sample is measured, not integrated past
    // integrate to the next sample
    if (o.integrator == Integrator::semi_implicit_euler) {
      for (int j = 0; j < dof; ++j) {
        qd[j] += dt * e.qdd[j];
        q[j] += dt * qd[j];
      }
    } else {
      const double th = t + 0.5 * dt, t1 = t + dt;
      const std::size_t sh = path.segment_at(th), s1 = path.segment_at(t1);
      k1q = qd;
      k1v = e.qdd;
      const TaskVec<m> xh = resolver.task(th, sh), x1 = resolver.task(t1, s1);
      bool good = resolver.evaluate(xh, q + 0.5 * dt * k1q, qd + 0.5 * dt * k1v, s);
      k2q = qd + 0.5 * dt * k1v;
      k2v = s.qdd;
      good = good && resolver.evaluate(xh, q + 0.5 * dt * k2q, qd + 0.5 * dt * k2v, s);
      k3q = qd + 0.5 * dt * k2v;
      k3v = s.qdd;
      good = good && resolver.evaluate(x1, q + dt * k3q, qd + dt * k3v, s);
      if (!good) {
        out.status = RunStatus::singular;
        break;
      }
      k4q = qd + dt * k3v;
      k4v = s.qdd;
      q += dt / 6.0 * (k1q + 2.0 * k2q + 2.0 * k3q + k4q);
      qd += dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    }
  }
  out.tau_inf = inf;
  finish_metrics(out, done, sumE, sumEM, min_w2, max_err2, trapezoid, dt, last_alpha, last_t);
  return out;
}

template <TaskSpace S>
TrajectoryMetrics run_method(const Chain& chain, const ChainTask& task, const VecN& q, const TrajectoryOptions& o,
                             const std::optional<Profile1>& alpha, ChainHistory* h) {
  switch (o.method) {
    case TrajectoryMethod::local_weighted: return run<S, Resolution::weighted>(chain, task, q, o, alpha, h);
    case TrajectoryMethod::local_unweighted: return run<S, Resolution::unweighted>(chain, task, q, o, alpha, h);
    case TrajectoryMethod::vertex_alpha:
      if constexpr (S == TaskSpace::planar_pose) return run<S, Resolution::nonredundant>(chain, task, q, o, alpha, h);
      break;
  }
  throw std::invalid_argument("simulate: vertex_alpha needs the planar_pose task");
}

}  // namespace

TrajectoryMetrics simulate(const Chain& chain, const ChainTask& task, const VecN& q0, const TrajectoryOptions& o,
                           ChainHistory* history) {
  const SampledPath3& sampled = task.path;
  const int n = chain.dof(), m = task_dimension(task.space);
  if (sampled.dt() != o.dt)
    throw std::invalid_argument("simulate: path sampled at dt = " + std::to_string(sampled.dt()) +
                                " s, options ask for dt = " + std::to_string(o.dt) + " s");
  if (q0.size() != n)
    throw std::invalid_argument("simulate: q0 has " + std::to_string(q0.size()) + " values for a chain of " +
                                std::to_string(n) + " joints");
  const bool planar = is_planar(task.space);
  if (planar && !chain.planar())
    throw std::invalid_argument("simulate: the " + std::string(to_string(task.space)) + " task needs a planar chain");
  if (o.method == TrajectoryMethod::vertex_alpha) {
    if (task.space != TaskSpace::planar_pose || n != 3)
      throw std::invalid_argument("simulate: vertex_alpha needs the planar_pose task and 3 joints");
  } else if (n <= m) {
    throw std::invalid_argument("simulate: " + std::string(to_string(o.method)) + " needs more joints (" +
                                std::to_string(n) + ") than task rows (" + std::to_string(m) + ")");
  }
  const Path3& path = sampled.path();
  std::optional<Profile1> alpha_profile;
  if (task.space == TaskSpace::planar_pose) {
    if (o.vertex_alpha.size() != path.segments())
      throw std::invalid_argument("planar_pose needs one alpha per vertex after the first (" +
                                  std::to_string(path.segments()) + ")");
    std::vector<Eigen::Matrix<double, 1, 1>> a{Eigen::Matrix<double, 1, 1>(o.alpha1A)};
    for (double v : o.vertex_alpha) a.emplace_back(v);
    alpha_profile.emplace(std::move(a), path.durations());
  }
  if (history) history->prepare(sampled.size(), n, position_rows(task.space));

  StartTarget target;
  target.position = path.vertices().front();
  target.planar = planar;
  target.angle = o.alpha1A;
  const std::optional<VecN> start = solve_start(chain, target, q0);
  if (!start) return unreachable(n);

  // planar chains of revolute joints: the run on fixed-size types, chosen by the joint count
  if (planar && planar_revolute(chain)) return planar_chain_run(chain, task, *start, o, alpha_profile, history);
  switch (task.space) {
    case TaskSpace::planar_position:
      return run_method<TaskSpace::planar_position>(chain, task, *start, o, alpha_profile, history);
    case TaskSpace::planar_pose:
      return run_method<TaskSpace::planar_pose>(chain, task, *start, o, alpha_profile, history);
    case TaskSpace::spatial_position:
      return run_method<TaskSpace::spatial_position>(chain, task, *start, o, alpha_profile, history);
    case TaskSpace::spatial_pose:
      return run_method<TaskSpace::spatial_pose>(chain, task, *start, o, alpha_profile, history);
  }
  throw std::invalid_argument("simulate: unknown task space");
}

}  // namespace ks
