// MotionProblem (motion/motion_problem.hpp): sampling, the criteria, the constraints and their
// gradients through the spline's exact weights and the per-sample torque partials.
#include "motion/motion_problem.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace ks::motion {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kStepQ = 6e-6;   // central-difference step in q, relative to max(1, |q_j|) [rad or m]
constexpr double kStepQd = 1.0;   // in q̇ [rad/s]: exact for the quadratic τ(q̇) at any step

bool fail(std::string* why, const std::string& text) {
  if (why) *why = text;
  return false;
}

}  // namespace

std::string_view to_string(Criterion c) {
  switch (c) {
    case Criterion::duration: return "duration";
    case Criterion::torque_sq: return "torque_sq";
    case Criterion::power_sq: return "power_sq";
    case Criterion::peak_torque: return "peak_torque";
    case Criterion::jerk_sq: return "jerk_sq";
    case Criterion::min_manipulability: return "min_manipulability";
    case Criterion::min_clearance: return "min_clearance";
  }
  return "?";
}

double sense(Criterion c) {
  return (c == Criterion::min_manipulability || c == Criterion::min_clearance) ? -1.0 : 1.0;
}

bool MotionSpec::IsValid(std::string* why) const {
  std::string chain_why;
  if (!chain.IsValid(&chain_why)) return fail(why, "chain: " + chain_why);
  const int n = chain.dof();
  if (q_start.size() != n || q_goal.size() != n)
    return fail(why, "q_start and q_goal need " + std::to_string(n) + " values (the chain's joints)");
  if (!q_start.allFinite() || !q_goal.allFinite()) return fail(why, "q_start and q_goal must be finite");
  if (controls < 0 || controls > kMaxControls)
    return fail(why, "controls must be in 0 .. " + std::to_string(kMaxControls));
  if (samples < 2) return fail(why, "samples must be >= 2");
  if (!(min_duration > 0.0 && min_duration <= duration && duration <= max_duration && std::isfinite(max_duration)))
    return fail(why, "durations must satisfy 0 < min_duration <= duration <= max_duration < inf");
  if (!vary_controls && !fixed_controls.empty() && static_cast<int>(fixed_controls.size()) != n * controls)
    return fail(why, "fixed_controls needs joints x controls values (or none: the cubic's)");
  if (!(vary_controls && controls > 0) && !vary_duration) return fail(why, "no variable: vary the controls (K > 0) or T");
  for (int c = 0; c < kCriteria; ++c)
    if (!(weights[c] >= 0.0) || !std::isfinite(weights[c]))
      return fail(why, "weight of " + std::string(to_string(static_cast<Criterion>(c))) + " must be finite and >= 0");
  if (obstacles.empty() && at(weights, Criterion::min_clearance) > 0.0)
    return fail(why, "the clearance weight needs obstacles");
  if (!obstacles.empty() && static_cast<int>(radii.size()) != n)
    return fail(why, "obstacles need one link radius per joint");
  for (double r : radii)
    if (!(r >= 0.0) || !std::isfinite(r)) return fail(why, "link radii must be finite and >= 0");
  if (!obstacle_velocities.empty() && obstacle_velocities.size() != obstacles.size())
    return fail(why, "obstacle_velocities needs one velocity per obstacle (or none: all fixed)");
  for (const geometry::Vec3& v : obstacle_velocities)
    if (!v.allFinite()) return fail(why, "obstacle velocities must be finite");
  if (!std::isfinite(clearance_margin)) return fail(why, "clearance_margin must be finite");
  if (normalise && !evaluate_reference) return fail(why, "normalise needs the reference (evaluate_reference)");
  if (!(limit_margin >= 0.0 && limit_margin < 1.0)) return fail(why, "limit_margin must be in [0, 1)");
  if (windows < 0) return fail(why, "windows must be >= 0");
  return true;
}

int motion_sample_count(int samples, int controls) {
  const int seg = controls + 1;
  const int per = std::max(1, (samples - 1 + seg - 1) / seg);
  return per * seg + 1;
}

MotionProblem::MotionProblem(MotionSpec spec) : spec_(std::move(spec)), basis_(std::clamp(spec_.controls, 0, kMaxControls)) {
  std::string why;
  if (!spec_.IsValid(&why)) throw std::invalid_argument("MotionProblem: " + why);
  n_ = spec_.chain.dof();
  K_ = spec_.controls;
  variables_ = (spec_.vary_controls ? n_ * K_ : 0) + (spec_.vary_duration ? 1 : 0);
  rows_ = spec_.chain.planar() ? 2 : 3;
  if (!spec_.vary_controls && spec_.fixed_controls.empty())
    spec_.fixed_controls = JointSpline(spec_.q_start, spec_.q_goal, K_, spec_.duration).cubic_controls();

  const int seg = K_ + 1;
  const int N = motion_sample_count(spec_.samples, K_);
  u_.resize(N);
  c_.resize(N);
  w_.resize(N);
  for (int s = 0; s < N; ++s) {
    u_[s] = static_cast<double>(s) / (N - 1);
    c_[s] = (s == 0 || s == N - 1 ? 0.5 : 1.0) / (N - 1);
    for (int d = 0; d < 3; ++d) basis_.weights(u_[s], d, w_[s][d]);
  }
  jerk_w_.resize(seg);
  for (int j = 0; j < seg; ++j) basis_.jerk_weights(j, jerk_w_[j]);

  // constraints: per window, each joint's limited quantities, then the clearance
  windows_ = spec_.windows == 0 ? seg : std::min(spec_.windows, N);
  window_of_.resize(N);
  for (int s = 0; s < N; ++s) window_of_[s] = static_cast<int>(static_cast<long>(s) * windows_ / N);
  mid_.assign(n_, 0.0), inv_half_.assign(n_, 0.0), inv_velocity_.assign(n_, 0.0), inv_effort_.assign(n_, 0.0);
  for (int j = 0; j < n_; ++j) {
    const ChainJoint& J = spec_.chain.joints[j];
    if (spec_.position_limits && std::isfinite(J.lower) && std::isfinite(J.upper) && J.upper > J.lower)
      mid_[j] = 0.5 * (J.lower + J.upper), inv_half_[j] = 2.0 / (J.upper - J.lower);
    if (spec_.velocity_limits && std::isfinite(J.velocity) && J.velocity > 0) inv_velocity_[j] = 1.0 / J.velocity;
    if (spec_.effort_limits && std::isfinite(J.effort) && J.effort > 0) inv_effort_[j] = 1.0 / J.effort;
  }
  for (int w = 0; w < windows_; ++w) {
    for (int j = 0; j < n_; ++j) {
      if (inv_half_[j] > 0) constraints_.push_back({MotionConstraint::Kind::position, j, w});
      if (inv_velocity_[j] > 0) constraints_.push_back({MotionConstraint::Kind::velocity, j, w});
      if (inv_effort_[j] > 0) constraints_.push_back({MotionConstraint::Kind::effort, j, w});
    }
    if (!spec_.obstacles.empty()) constraints_.push_back({MotionConstraint::Kind::clearance, -1, w});
  }

  q_.assign(N, VecN::Zero(n_)), qd_ = q_, qdd_ = q_, tau_ = q_, clear_grad_ = q_;
  dtau_dq_.assign(N, MatN::Zero(n_, n_)), dtau_dqd_ = dtau_dq_, M_ = dtau_dq_;
  clear_.assign(N, kInf);
  clear_dT_.assign(N, 0.0);
  moved_ = spec_.obstacles;
  nodes_.resize(n_, K_ + 2);
  nodes_.col(0) = spec_.q_start;
  nodes_.col(K_ + 1) = spec_.q_goal;

  scale_.fill(1.0);
  reference_.fill(std::numeric_limits<double>::quiet_NaN());
  if (!spec_.evaluate_reference) return;
  MotionEvaluation e;
  evaluate(initial_point(), false, e);
  reference_ = e.criteria;
  if (spec_.normalise)
    for (int c = 0; c < kCriteria; ++c) {
      if (spec_.weights[c] == 0.0) continue;
      const double r = std::abs(reference_[c]);
      if (!(r > 0.0) || !std::isfinite(r))
        throw std::invalid_argument("MotionProblem: cannot normalise " + std::string(to_string(static_cast<Criterion>(c))) +
                                    " by the initial motion's value " + std::to_string(reference_[c]));
      scale_[c] = r;
    }
}

std::vector<double> MotionProblem::initial_point() const {
  std::vector<double> x;
  x.reserve(static_cast<std::size_t>(variables_));
  if (spec_.vary_controls) x = JointSpline(spec_.q_start, spec_.q_goal, K_, spec_.duration).cubic_controls();
  if (spec_.vary_duration) x.push_back(spec_.duration);
  return x;
}

void MotionProblem::bounds(double pad, std::vector<double>& lower, std::vector<double>& upper) const {
  lower.clear(), upper.clear();
  if (spec_.vary_controls)
    for (int i = 0; i < n_; ++i) {
      const ChainJoint& J = spec_.chain.joints[i];
      const double a = std::min(spec_.q_start[i], spec_.q_goal[i]), b = std::max(spec_.q_start[i], spec_.q_goal[i]);
      for (int k = 0; k < K_; ++k) {
        lower.push_back(std::max(J.lower, a - pad));
        upper.push_back(std::min(J.upper, b + pad));
      }
    }
  if (spec_.vary_duration) lower.push_back(spec_.min_duration), upper.push_back(spec_.max_duration);
}

void MotionProblem::set_nodes(std::span<const double> x) const {
  if (static_cast<int>(x.size()) != variables_)
    throw std::invalid_argument("MotionProblem: " + std::to_string(x.size()) + " values for " +
                                std::to_string(variables_) + " variables");
  const double* c = spec_.vary_controls ? x.data() : spec_.fixed_controls.data();
  for (int i = 0; i < n_; ++i)
    for (int k = 0; k < K_; ++k) nodes_(i, k + 1) = c[i * K_ + k];
  T_ = spec_.vary_duration ? x[static_cast<std::size_t>(variables_ - 1)] : spec_.duration;
}

JointSpline MotionProblem::spline_at(std::span<const double> x) const {
  set_nodes(x);
  JointSpline spline(spec_.q_start, spec_.q_goal, K_, T_);
  std::vector<double> c(static_cast<std::size_t>(n_ * K_));
  for (int i = 0; i < n_; ++i)
    for (int k = 0; k < K_; ++k) c[static_cast<std::size_t>(i * K_ + k)] = nodes_(i, k + 1);
  spline.set_controls(c);
  return spline;
}

double MotionProblem::manipulability(const VecN& q) const {
  forward_kinematics(spec_.chain, data_, q);
  Mat6N J;
  tip_jacobian(spec_.chain, data_, J);
  if (rows_ == 2) {
    const Eigen::Matrix2d G = J.topRows<2>() * J.topRows<2>().transpose();
    return std::sqrt(std::max(0.0, G.determinant()));
  }
  const Eigen::Matrix3d G = J.topRows<3>() * J.topRows<3>().transpose();
  return std::sqrt(std::max(0.0, G.determinant()));
}

void MotionProblem::project(int s, const VecN& a_q, const VecN& a_qd, const VecN& a_qdd, double scale, double* g) const {
  const double T = T_;
  if (spec_.vary_controls) {
    const auto& w = w_[static_cast<std::size_t>(s)];
    for (int i = 0; i < n_; ++i) {
      const double p = scale * a_q[i], v = scale * a_qd[i] / T, a = scale * a_qdd[i] / (T * T);
      for (int k = 0; k < K_; ++k) g[i * K_ + k] += p * w[0][k + 1] + v * w[1][k + 1] + a * w[2][k + 1];
    }
  }
  // at fixed u: dq/dT = 0, dq̇/dT = -q̇/T, dq̈/dT = -2 q̈/T
  if (spec_.vary_duration)
    g[variables_ - 1] += scale * (-a_qd.dot(qd_[static_cast<std::size_t>(s)]) - 2.0 * a_qdd.dot(qdd_[static_cast<std::size_t>(s)])) / T;
}

void MotionProblem::evaluate(std::span<const double> x, bool gradients, MotionEvaluation& out) const {
  set_nodes(x);
  const Chain& chain = spec_.chain;
  const int N = samples(), nv = variables_, nc = constraints();
  const double T = T_;
  out.constraints.assign(static_cast<std::size_t>(nc), -kInf);
  std::vector<int>& top = top_sample_;
  top.assign(static_cast<std::size_t>(nc), 0);
  if (gradients) {
    out.objective_gradient.assign(static_cast<std::size_t>(nv), 0.0);
    for (auto& g : out.criterion_gradients) g.assign(static_cast<std::size_t>(nv), 0.0);
    out.constraint_jacobian.assign(static_cast<std::size_t>(nc) * nv, 0.0);
  }
  double f5 = 0.0, f6 = 0.0, peak = -1.0, wmin = kInf, dmin = kInf;
  int peak_s = 0, peak_i = 0, wmin_s = 0, dmin_s = 0;
  double* g5 = gradients ? out.criterion_gradients[static_cast<int>(Criterion::torque_sq)].data() : nullptr;
  double* g6 = gradients ? out.criterion_gradients[static_cast<int>(Criterion::power_sq)].data() : nullptr;
  VecN a_q(n_), a_qd(n_), a_qdd(n_), b(n_), up(n_), down(n_), x_step(n_);
  std::size_t first = 0;  // the first constraint of the current window
  const std::size_t per_window = windows_ > 0 ? constraints_.size() / static_cast<std::size_t>(windows_) : 0;

  for (int s = 0; s < N; ++s) {
    const auto& w = w_[static_cast<std::size_t>(s)];
    VecN &q = q_[s], &qd = qd_[s], &qdd = qdd_[s], &tau = tau_[s];
    q = nodes_ * w[0];
    qd = nodes_ * w[1] / T;
    qdd = nodes_ * w[2] / (T * T);
    rnea(chain, data_, q, qd, qdd, tau);
    if (gradients) {
      crba(chain, data_, q, M_[s]);
      for (int j = 0; j < n_; ++j) {
        const double h = kStepQ * std::max(1.0, std::abs(q[j]));
        x_step = q, x_step[j] += h;
        rnea(chain, data_, x_step, qd, qdd, up);
        x_step[j] = q[j] - h;
        rnea(chain, data_, x_step, qd, qdd, down);
        dtau_dq_[s].col(j) = (up - down) / (2.0 * h);
        x_step = qd, x_step[j] += kStepQd;
        rnea(chain, data_, q, x_step, qdd, up);
        x_step[j] = qd[j] - kStepQd;
        rnea(chain, data_, q, x_step, qdd, down);
        dtau_dqd_[s].col(j) = (up - down) / (2.0 * kStepQd);
      }
    }
    // integrals: f5 = T Σ c_s |τ|², f6 = T Σ c_s Σ (τ_i q̇_i)²
    const double cs = c_[static_cast<std::size_t>(s)];
    f5 += cs * tau.squaredNorm();
    f6 += cs * (tau.cwiseProduct(qd)).squaredNorm();
    if (gradients) {
      b = 2.0 * tau;  // ∂|τ|²/∂τ
      a_q.noalias() = dtau_dq_[s].transpose() * b;
      a_qd.noalias() = dtau_dqd_[s].transpose() * b;
      a_qdd.noalias() = M_[s] * b;
      project(s, a_q, a_qd, a_qdd, T * cs, g5);
      b = 2.0 * tau.cwiseProduct(qd).cwiseProduct(qd);  // ∂Σ(τ_i q̇_i)²/∂τ
      a_q.noalias() = dtau_dq_[s].transpose() * b;
      a_qd.noalias() = dtau_dqd_[s].transpose() * b;
      a_qd += 2.0 * tau.cwiseProduct(tau).cwiseProduct(qd);  // its direct q̇ part
      a_qdd.noalias() = M_[s] * b;
      project(s, a_q, a_qd, a_qdd, T * cs, g6);
    }
    for (int i = 0; i < n_; ++i)
      if (std::abs(tau[i]) > peak) peak = std::abs(tau[i]), peak_s = s, peak_i = i;
    if (const double m = manipulability(q); m < wmin) wmin = m, wmin_s = s;
    if (!spec_.obstacles.empty()) {
      const bool moving = !spec_.obstacle_velocities.empty();
      if (moving)
        for (std::size_t j = 0; j < moved_.size(); ++j)
          moved_[j] = geometry::translated(spec_.obstacles[j], (u_[s] * T) * spec_.obstacle_velocities[j]);
      const geometry::Clearance c = geometry::min_clearance(chain, q, spec_.radii, moving ? moved_ : spec_.obstacles, clear_ws_);
      clear_[s] = c.distance;
      clear_grad_[s] = c.gradient;
      clear_dT_[s] = moving && c.obstacle >= 0
                         ? u_[s] * c.obstacle_gradient.dot(spec_.obstacle_velocities[static_cast<std::size_t>(c.obstacle)])
                         : 0.0;
      if (c.distance < dmin) dmin = c.distance, dmin_s = s;
    }
    // the window's constraints: the largest value so far and its sample
    first = static_cast<std::size_t>(window_of_[s]) * per_window;
    for (std::size_t r = first; r < first + per_window; ++r) {
      const MotionConstraint& k = constraints_[r];
      double v = 0.0;
      switch (k.kind) {
        case MotionConstraint::Kind::position: v = std::abs(q[k.joint] - mid_[k.joint]) * inv_half_[k.joint]; break;
        case MotionConstraint::Kind::velocity: v = std::abs(qd[k.joint]) * inv_velocity_[k.joint]; break;
        case MotionConstraint::Kind::effort: v = std::abs(tau[k.joint]) * inv_effort_[k.joint]; break;
        case MotionConstraint::Kind::clearance: v = spec_.clearance_margin - clear_[s]; break;
      }
      if (k.kind != MotionConstraint::Kind::clearance) v -= 1.0 - spec_.limit_margin;
      if (v > out.constraints[r]) out.constraints[r] = v, top[r] = s;
    }
  }

  // the jerk term, exact per segment: ∫ Σ jerk² dt = Σ_j (T h) |jerk_j|², jerk_j = Y w3_j / T³
  double jerk_sq = 0.0;
  const double h = basis_.spacing(), T3 = T * T * T;
  for (int j = 0; j < basis_.segments(); ++j) {
    b = nodes_ * jerk_w_[static_cast<std::size_t>(j)] / T3;
    jerk_sq += T * h * b.squaredNorm();
    if (gradients && spec_.vary_controls) {
      double* g = out.criterion_gradients[static_cast<int>(Criterion::jerk_sq)].data();
      for (int i = 0; i < n_; ++i)
        for (int k = 0; k < K_; ++k) g[i * K_ + k] += T * h * 2.0 * b[i] * jerk_w_[static_cast<std::size_t>(j)][k + 1] / T3;
    }
  }

  Criteria& cr = out.criteria;
  at(cr, Criterion::duration) = T;
  at(cr, Criterion::torque_sq) = T * f5;
  at(cr, Criterion::power_sq) = T * f6;
  at(cr, Criterion::peak_torque) = peak;
  at(cr, Criterion::jerk_sq) = jerk_sq;
  at(cr, Criterion::min_manipulability) = wmin;
  at(cr, Criterion::min_clearance) = dmin;
  out.objective = 0.0;
  for (int c = 0; c < kCriteria; ++c)
    if (spec_.weights[c] > 0.0) out.objective += spec_.weights[c] * sense(static_cast<Criterion>(c)) * cr[c] / scale_[c];
  if (!gradients) return;

  auto& G = out.criterion_gradients;
  const VecN zero = VecN::Zero(n_);
  if (spec_.vary_duration) {  // the direct share of T: the integrals' factor T, the jerk's T^-5, T itself
    G[static_cast<int>(Criterion::duration)][nv - 1] = 1.0;
    G[static_cast<int>(Criterion::torque_sq)][nv - 1] += f5;
    G[static_cast<int>(Criterion::power_sq)][nv - 1] += f6;
    G[static_cast<int>(Criterion::jerk_sq)][nv - 1] = -5.0 * jerk_sq / T;
  }
  {  // the peak: its sample's and joint's |τ_i|
    b = zero, b[peak_i] = tau_[peak_s][peak_i] >= 0.0 ? 1.0 : -1.0;
    a_q.noalias() = dtau_dq_[peak_s].transpose() * b;
    a_qd.noalias() = dtau_dqd_[peak_s].transpose() * b;
    a_qdd.noalias() = M_[peak_s] * b;
    project(peak_s, a_q, a_qd, a_qdd, 1.0, G[static_cast<int>(Criterion::peak_torque)].data());
  }
  {  // the least manipulability: central differences in q at its sample
    const VecN& q = q_[wmin_s];
    for (int j = 0; j < n_; ++j) {
      const double hq = kStepQ * std::max(1.0, std::abs(q[j]));
      x_step = q, x_step[j] += hq;
      const double wu = manipulability(x_step);
      x_step[j] = q[j] - hq;
      a_q[j] = (wu - manipulability(x_step)) / (2.0 * hq);
    }
    project(wmin_s, a_q, zero, zero, 1.0, G[static_cast<int>(Criterion::min_manipulability)].data());
  }
  if (!spec_.obstacles.empty()) {
    project(dmin_s, clear_grad_[dmin_s], zero, zero, 1.0, G[static_cast<int>(Criterion::min_clearance)].data());
    if (spec_.vary_duration) G[static_cast<int>(Criterion::min_clearance)][nv - 1] += clear_dT_[dmin_s];
  }
  for (int c = 0; c < kCriteria; ++c) {
    const double k = spec_.weights[c] * sense(static_cast<Criterion>(c)) / scale_[c];
    if (k != 0.0)
      for (int v = 0; v < nv; ++v) out.objective_gradient[v] += k * G[c][v];
  }
  for (int r = 0; r < nc; ++r) {
    const MotionConstraint& k = constraints_[r];
    const int s = top[r], j = k.joint;
    a_q = zero, a_qd = zero, a_qdd = zero;
    switch (k.kind) {
      case MotionConstraint::Kind::position: a_q[j] = (q_[s][j] >= mid_[j] ? 1.0 : -1.0) * inv_half_[j]; break;
      case MotionConstraint::Kind::velocity: a_qd[j] = (qd_[s][j] >= 0.0 ? 1.0 : -1.0) * inv_velocity_[j]; break;
      case MotionConstraint::Kind::effort:
        a_q = dtau_dq_[s].row(j).transpose(), a_qd = dtau_dqd_[s].row(j).transpose(), a_qdd = M_[s].row(j).transpose();
        if (tau_[s][j] < 0.0) a_q = -a_q, a_qd = -a_qd, a_qdd = -a_qdd;
        a_q *= inv_effort_[j], a_qd *= inv_effort_[j], a_qdd *= inv_effort_[j];
        break;
      case MotionConstraint::Kind::clearance: a_q = -clear_grad_[s]; break;
    }
    project(s, a_q, a_qd, a_qdd, 1.0, out.constraint_jacobian.data() + static_cast<std::size_t>(r) * nv);
    if (k.kind == MotionConstraint::Kind::clearance && spec_.vary_duration)
      out.constraint_jacobian[static_cast<std::size_t>(r) * nv + nv - 1] -= clear_dT_[s];
  }
}

}  // namespace ks::motion
