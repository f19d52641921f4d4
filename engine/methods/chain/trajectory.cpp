// simulate_local() for a chain: the chain as a model of the one trajectory loop
// (methods/loop/trajectory_loop.hpp) over the chain's dynamics (model/chain_dynamics.hpp) and the
// resolutions of methods/chain/resolution.hpp. The task space and the method are template parameters
// of the model, chosen once per run: the step branches on neither. Fixed-maximum-size types
// throughout: nothing is allocated per step. Planar tasks on planar chains of revolute joints take the
// fixed-size model of methods/chain/planar_run.hpp instead.
#include "methods/chain/trajectory.hpp"
#include "methods/loop/trajectory_loop.hpp"
#include "methods/metrics/run_sums.hpp"
#include "methods/metrics/sample_sums.hpp"
#include "methods/base/singular_scale.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "common/name_table.hpp"
#include "methods/chain/planar_run.hpp"
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

namespace {

enum class Resolution { weighted, unweighted, nonredundant };

/// Everything one evaluation of the method at (t, q, qd) produces.
template <int m>
struct SampleEvaluation {
  ChainState st;           // M, c, g, J (6 x n), bias, tip
  InertiaFactor Mf;        // M = L D L^T
  TaskJacobian<m> Jt;      // task rows of J
  VecN qdd;
  double w2 = 0;           // det(Jt Jt^T) (local methods); unused by the non-redundant solve
};

/// Where the path wants the tip at one instant (closed-loop feedback and the orientation error): its
/// position and velocity [m, m/s], for planar_pose the tip angle, its rate and the arm's angle at the
/// state evaluated [rad, rad/s], for spatial_pose the orientation held (the start's).
struct Desired {
  Eigen::Vector3d p, v;
  double alpha = 0, alpha_v = 0, alpha_now = 0;
  const Eigen::Matrix3d* R = nullptr;
};

/// The orientation error vector of R against Rd, 1/2 sum_k r_k x rd_k (zero when R = Rd; for small
/// errors the rotation vector from R to Rd) [rad].
inline Eigen::Vector3d orientation_error(const Eigen::Matrix3d& R, const Eigen::Matrix3d& Rd) {
  return 0.5 * (R.col(0).cross(Rd.col(0)) + R.col(1).cross(Rd.col(1)) + R.col(2).cross(Rd.col(2)));
}
/// The angle of the rotation from Rd to R [rad].
inline double orientation_angle(const Eigen::Matrix3d& R, const Eigen::Matrix3d& Rd) {
  const Eigen::Matrix3d E = Rd.transpose() * R;
  const Eigen::Vector3d w(E(2, 1) - E(1, 2), E(0, 2) - E(2, 0), E(1, 0) - E(0, 1));
  return std::atan2(0.5 * w.norm(), 0.5 * (E.trace() - 1.0));
}

template <TaskSpace S, Resolution R>
class ChainResolver {
 public:
  static constexpr int m = task_dimension(S);

  ChainResolver(const Chain& chain, const TaskPath<3>& path, const TrajectoryOptions& o,
                const std::optional<Profile1>& alpha)
      : chain_(chain), path_(path), o_(o), alpha_(alpha) {
    if (o.limit_centring != 0.0) {
      const LimitTable L = LimitTable::of(chain);
      for (int j = 0; j < L.n; ++j) centre_[j] = L.mid[j], sprung_[j] = L.inv_half[j] != 0.0;
      spring_ = L.any_position;
    }
  }

  /// The task acceleration at time t on segment `segment` (RK4's stages).
  TaskVec<m> task(double t, std::size_t segment) const { return task_of(path_.sample_on(segment, t).a, segment, t); }
  /// The task acceleration at sample i of the sampled path.
  TaskVec<m> task(const SampledPath3& p, std::size_t i) const {
    return task_of(p.acceleration(i), p.segment(i), p.time(i));
  }

  /// Where the path wants the tip at time t on `segment` (closed loop, orientation error).
  void desired(double t, std::size_t segment, Desired& d) const {
    const PathSample<3> x = path_.sample_on(segment, t);
    d.p = x.p;
    d.v = x.v;
    if constexpr (S == TaskSpace::planar_pose) {
      const PathSample<1> a = alpha_->sample_on(segment, t);
      d.alpha = a.p[0];
      d.alpha_v = a.v[0];
    }
  }

  /// Joint accelerations for task acceleration xdd at (q, qd); fills every intermediate in `e`. With
  /// `fb` (closed loop), xdd + K_D (path velocity - J qd) + K_P (path - tip) is commanded instead.
  /// Returns false when the task Jacobian is singular.
  bool evaluate(const TaskVec<m>& xdd, const VecN& q, const VecN& qd, SampleEvaluation<m>& e, const Desired* fb = nullptr) {
    evaluate_dynamics(chain_, data_, q, qd, e.st);
    select_task_rows<S>(e.st.J, e.Jt);
    TaskVec<m> b = xdd - select_task_rows<S>(e.st.bias);
    if (fb) {
      constexpr int P = position_rows(S);
      const TaskVec<m> xd = e.Jt * qd;
      b.template head<P>() += o_.clik_kd * (fb->v.template head<P>() - xd.template head<P>()) +
                              o_.clik_kp * (fb->p.template head<P>() - e.st.tip.p.template head<P>());
      if constexpr (S == TaskSpace::planar_pose)
        b[2] += o_.clik_kd * (fb->alpha_v - xd[2]) + o_.clik_kp * (fb->alpha - fb->alpha_now);
      if constexpr (S == TaskSpace::spatial_pose)
        b.template tail<3>() += -o_.clik_kd * xd.template tail<3>() + o_.clik_kp * orientation_error(e.st.tip.R, *fb->R);
    }
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
      const double* extra = nullptr;
      if (spring_) {
        for (int j = 0; j < n; ++j) spring_term_[j] = sprung_[j] ? o_.limit_centring * (q[j] - centre_[j]) : 0.0;
        extra = spring_term_;
      }
      e.qdd = local_acceleration<m>(w, e.Mf, e.Jt, b, u_, o_.null_damping, qd, extra);
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
    } else {  // fixed-size halves: no 4-wide packet reads past the 3 values of a
      x.template head<3>() = a;
      x.template tail<3>().setZero();
    }
    return x;
  }

  const Chain& chain_;
  const TaskPath<3>& path_;
  const TrajectoryOptions& o_;
  const std::optional<Profile1>& alpha_;
  ChainData data_;
  VecN u_;  // c + k g
  // the limit spring K_L (q - q_mid) (TrajectoryOptions::limit_centring), on joints with both limits
  bool spring_ = false;
  bool sprung_[kMaxJoints] = {};
  double centre_[kMaxJoints] = {}, spring_term_[kMaxJoints] = {};
};

/// The chain as methods/loop/trajectory_loop.hpp's model: the loop's state copied into the
/// resolver's vectors, the per-sample values on the chain's Eigen types.
template <TaskSpace S, Resolution R>
class ChainModel {
 public:
  static constexpr int max_joints = kMaxJoints;
  static constexpr bool prismatic_joints = true;
  static constexpr int m = task_dimension(S), P = position_rows(S);
  static constexpr bool oriented = S == TaskSpace::planar_pose || S == TaskSpace::spatial_pose;
  using Evaluation = SampleEvaluation<m>;

  ChainModel(const Chain& chain, const ChainTask& task, const VecN& q_start, const TrajectoryOptions& o,
             const std::optional<Profile1>& alpha, ChainHistory* history)
      : chain_(chain), sampled_(task.path), o_(o), q_start_(q_start), history_(history),
        resolver_(chain, task.path.path(), o, alpha), limits_(LimitTable::of(chain)), closed_(o.closed_loop()),
        n_(chain.dof()) {
    if constexpr (is_planar(S)) angle_.emplace(chain);
    for (int j = 0; j < n_; ++j) prismatic_[j] = chain.joints[j].type == JointType::prismatic;
    q_.resize(n_), qd_.resize(n_), yq_.resize(n_), yv_.resize(n_), z_.resize(n_);
    d_.R = dh_.R = d1_.R = &held_;
  }

  int joints() const { return n_; }
  LoopShape shape() const { return {sampled_.size(), o_.dt, o_.integrator, o_.on_violation == OnViolation::stop}; }
  RunShape run_shape() const {
    RunShape shape{n_, oriented, false, limits_.any() ? &limits_ : nullptr};
    for (int j = 0; j < n_; ++j) shape.prismatic |= prismatic_[j];
    return shape;
  }
  SampleSums<double, kMaxJoints> sums() const {
    return SampleSums<double, kMaxJoints>(o_.tracking_bound, o_.orientation_bound, limits_.any() ? &limits_ : nullptr);
  }
  bool start(double* q) {
    for (int j = 0; j < n_; ++j) q[j] = q_[j] = q_start_[j];
    return true;
  }
  double alpha(const double*) const { return angle_ ? (*angle_)(q_) : std::numeric_limits<double>::quiet_NaN(); }
  double torque_bound() const { return o_.torque_bound; }
  bool prismatic(int j) const { return prismatic_[j]; }

  bool at_sample(std::size_t i, double t, const double* q, const double* qd, Evaluation& e) {
    for (int j = 0; j < n_; ++j) q_[j] = q[j], qd_[j] = qd[j];
    if (closed_ || oriented) resolver_.desired(t, sampled_.segment(i), d_);
    if (angle_) d_.alpha_now = (*angle_)(q_);
    if (i == 0 && S == TaskSpace::spatial_pose) {  // the orientation held: the start's, before any feedback
      ChainState st0;
      ChainData data0;
      evaluate_dynamics(chain_, data0, q_, qd_, st0);
      held_ = st0.tip.R;
    }
    return resolver_.evaluate(resolver_.task(sampled_, i), q_, qd_, e, closed_ ? &d_ : nullptr);
  }
  void torques(const Evaluation& e, const double*, double* tau) const {
    for (int j = 0; j < n_; ++j) {
      double Mqdd = 0;
      for (int k = 0; k < n_; ++k) Mqdd += e.st.M(j, k) * e.qdd[k];
      tau[j] = Mqdd + e.st.c[j] + e.st.g[j];
    }
  }

  void values(const Evaluation& e, std::size_t i, const double* q, const double* qd, const double* tau,
              SampleValues<double>& v) {
    v.q = q, v.qd = qd, v.tau = tau;
    for (int j = 0; j < n_; ++j) z_[j] = tau[j];
    v.qf = e.Mf.inverse_quadratic_form(z_.data()), v.det = 1.0;  // tau^T M^-1 tau
    if constexpr (P == m && R != Resolution::nonredundant)
      v.w2 = e.w2;
    else
      v.w2 = gram_determinant<P, m>(e.Jt);
    const Eigen::Matrix<double, P, 1> err = e.st.tip.p.template head<P>() - sampled_.position(i).template head<P>();
    v.err2 = err.squaredNorm();
    v.orient = 0.0;
    if constexpr (S == TaskSpace::planar_pose) v.orient = std::abs(d_.alpha_now - d_.alpha);
    if constexpr (S == TaskSpace::spatial_pose) v.orient = orientation_angle(e.st.tip.R, held_);
    v.alpha = angle_ ? d_.alpha_now : std::numeric_limits<double>::quiet_NaN();
    double ke = 0;  // qd^T M qd (no temporary per sample)
    for (int j = 0; j < n_; ++j) ke += qd_[j] * e.st.M.row(j).head(n_).dot(qd_.head(n_));
    v.ke = 0.5 * ke;
  }

  void record(std::size_t i, double t, const Evaluation& e, const double*, const double*, const double* tau, bool) {
    if (!history_ || !(i % history_->stride == 0 || i + 1 == sampled_.size())) return;
    ChainHistory& h = *history_;
    const Eigen::Index c = h.size++;
    h.t[c] = t;
    h.q.col(c) = q_;
    h.qd.col(c) = qd_;
    h.qdd.col(c) = e.qdd;
    for (int j = 0; j < n_; ++j) h.tau(j, c) = tau[j];
    h.x.col(c) = e.st.tip.p.template head<P>();
    h.alpha[c] = angle_ ? d_.alpha_now : std::numeric_limits<double>::quiet_NaN();
  }

  void stages(double t, double dt) {
    const TaskPath<3>& path = sampled_.path();
    const double th = t + 0.5 * dt, t1 = t + dt;
    const std::size_t sh = path.segment_at(th), s1 = path.segment_at(t1);
    xh_ = resolver_.task(th, sh), x1_ = resolver_.task(t1, s1);
    if (closed_) {
      resolver_.desired(th, sh, dh_);
      resolver_.desired(t1, s1, d1_);
    }
  }
  bool stage(bool end, const double* yq, const double* yv, Evaluation& s) {
    for (int j = 0; j < n_; ++j) yq_[j] = yq[j], yv_[j] = yv[j];
    Desired& dd = end ? d1_ : dh_;
    const Desired* fb = nullptr;
    if (closed_) {  // the stage state's tip angle for planar_pose feedback
      if (angle_) dd.alpha_now = (*angle_)(yq_);
      fb = &dd;
    }
    return resolver_.evaluate(end ? x1_ : xh_, yq_, yv_, s, fb);
  }
  void moved(const double*, const double*) {}

 private:
  const Chain& chain_;
  const SampledPath3& sampled_;
  const TrajectoryOptions& o_;
  const VecN& q_start_;
  ChainHistory* history_;
  ChainResolver<S, R> resolver_;
  const LimitTable limits_;
  const bool closed_;
  const int n_;
  std::optional<PlanarAngle> angle_;
  bool prismatic_[kMaxJoints] = {};
  VecN q_, qd_, yq_, yv_, z_;  // the sample's state, a stage's, tau (for M^-1 tau)
  TaskVec<m> xh_, x1_;         // RK4: the task at the half step and the step's end
  Desired d_, dh_, d1_;        // at the sample, at RK4's stage times
  Eigen::Matrix3d held_ = Eigen::Matrix3d::Identity();  // spatial_pose: the start's orientation
};

/// One run from the start q_start at rest: the one trajectory loop over the chain.
template <TaskSpace S, Resolution R>
TrajectoryMetrics run(const Chain& chain, const ChainTask& task, const VecN& q_start, const TrajectoryOptions& o,
                      const std::optional<Profile1>& alpha_profile, ChainHistory* history) {
  ChainModel<S, R> model(chain, task, q_start, o, alpha_profile, history);
  RunSums sums;
  trajectory_loop<double>(model, &sums);
  return finish_run(sums, model.run_shape(), o);
}

template <TaskSpace S>
TrajectoryMetrics run_method(const Chain& chain, const ChainTask& task, const VecN& q, const TrajectoryOptions& o,
                             const std::optional<Profile1>& alpha, ChainHistory* h) {
  // as many joints as task rows: no redundancy to resolve, J qdd = b solved (the local methods agree)
  if (chain.dof() == task_dimension(S) && o.method != TrajectoryMethod::global_spline)
    return run<S, Resolution::nonredundant>(chain, task, q, o, alpha, h);
  switch (o.method) {
    case TrajectoryMethod::local_weighted: return run<S, Resolution::weighted>(chain, task, q, o, alpha, h);
    case TrajectoryMethod::local_unweighted: return run<S, Resolution::unweighted>(chain, task, q, o, alpha, h);
    case TrajectoryMethod::vertex_alpha:
      if constexpr (S == TaskSpace::planar_pose) return run<S, Resolution::nonredundant>(chain, task, q, o, alpha, h);
      throw std::invalid_argument("simulate: vertex_alpha needs the planar_pose task");
    case TrajectoryMethod::global_spline: break;
  }
  throw std::invalid_argument("simulate: global_spline runs through solve_global_spline_chain");
}

}  // namespace

TrajectoryMetrics simulate_local(const Chain& chain, const ChainTask& task, const VecN& q0, const TrajectoryOptions& o,
                                 ChainHistory* history) {
  const SampledPath3& sampled = task.path;
  const int n = chain.dof(), m = task_dimension(task.space);
  if (std::string why; !o.IsValid(&why)) throw std::invalid_argument("simulate: " + why);
  if (sampled.dt() != o.dt)
    throw std::invalid_argument("simulate: path sampled at dt = " + std::to_string(sampled.dt()) +
                                " s, options ask for dt = " + std::to_string(o.dt) + " s");
  if (o.end == EndState::rest)
    throw std::invalid_argument("simulate: end = rest is the seed arm's closed-form runs' option; a chain's runs end free");
  if (q0.size() != n)
    throw std::invalid_argument("simulate: q0 has " + std::to_string(q0.size()) + " values for a chain of " +
                                std::to_string(n) + " joints");
  const bool planar = is_planar(task.space);
  if (planar && !chain.planar())
    throw std::invalid_argument("simulate: the " + std::string(to_string(task.space)) + " task needs a planar chain");
  if (o.method == TrajectoryMethod::vertex_alpha) {
    if (task.space != TaskSpace::planar_pose || n != 3)
      throw std::invalid_argument("simulate: vertex_alpha needs the planar_pose task and 3 joints");
  } else if (n < m || (is_planar(task.space) && n == m)) {  // a planar start fixes the tip angle too
    throw std::invalid_argument("simulate: " + std::string(to_string(o.method)) + " needs " +
                                (is_planar(task.space) ? "more joints (" : "at least as many joints (") +
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
  if (!start) return not_simulated(RunStatus::unreachable_start, n);

  // the singularity tolerance relative to the arm's size below 1 m (methods/base/singular_scale.hpp)
  const double scale = singular_scale(chain_reach(chain), position_rows(task.space));
  TrajectoryOptions scaled;
  if (scale != 1.0) scaled = o, scaled.singular_tolerance *= scale;
  const TrajectoryOptions& os = scale != 1.0 ? scaled : o;
  // planar chains of revolute joints: the run on fixed-size types, chosen by the joint count
  if (planar && planar_revolute(chain)) return planar_chain_run(chain, task, *start, os, alpha_profile, history);
  switch (task.space) {
    case TaskSpace::planar_position:
      return run_method<TaskSpace::planar_position>(chain, task, *start, os, alpha_profile, history);
    case TaskSpace::planar_pose:
      return run_method<TaskSpace::planar_pose>(chain, task, *start, os, alpha_profile, history);
    case TaskSpace::spatial_position:
      return run_method<TaskSpace::spatial_position>(chain, task, *start, os, alpha_profile, history);
    case TaskSpace::spatial_pose:
      return run_method<TaskSpace::spatial_pose>(chain, task, *start, os, alpha_profile, history);
  }
  throw std::invalid_argument("simulate: unknown task space");
}

}  // namespace ks
