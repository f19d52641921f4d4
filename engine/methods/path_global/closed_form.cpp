// PathGlobalProblem (methods/path_global/closed_form.hpp): the joint path by exact IK, the objective with its
// chain-rule gradient, and the metrics through the per-sample accumulator.
#include "methods/path_global/closed_form.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "methods/closed_form/lanes.hpp"
#include "methods/loop/trajectory_loop.hpp"
#include "methods/metrics/sample_sums.hpp"

namespace ks {
namespace {

/// Calls run(lanes, count) with the widest lane width the processor has (methods/closed_form/lanes.hpp)
/// and the largest multiple of it not above n, and returns that count (0 with one lane): the caller
/// evaluates the rest one by one. Every lane computes what one by one computes.
template <class Run>
std::size_t in_lanes(std::size_t n, Run&& run) {
  const int lanes = max_lanes();
  if (lanes <= 1) return 0;
  const std::size_t count = n - n % static_cast<std::size_t>(lanes);
  if (count > 0) run(lanes, count);
  return count;
}

}  // namespace

bool self_motion_chart(const Vec2& p, const Vec2& v, const Vec2& acc, double L, double l3, ChartSample& c) {
  const double r2 = p.squaredNorm(), r = std::sqrt(r2);
  if (!(r > 0.0)) return false;
  const double cross = p.x() * v.y() - p.y() * v.x(), dot = p.x() * v.x() + p.y() * v.y();
  c.phi[0] = std::atan2(p.y(), p.x());
  c.phi[1] = cross / r2;
  c.phi[2] = (p.x() * acc.y() - p.y() * acc.x()) / r2 - 2.0 * cross * dot / (r2 * r2);
  const double k = l3 * l3 - L * L;
  const double gamma = (r2 + k) / (2.0 * l3 * r);
  if (!(std::abs(gamma) < 1.0)) return false;
  const double rd = dot / r, rdd = (v.squaredNorm() + p.x() * acc.x() + p.y() * acc.y()) / r - rd * rd / r;
  const double g1 = 1.0 / (2.0 * l3) - k / (2.0 * l3 * r2), g2 = k / (l3 * r2 * r);  // d gamma/dr, d2 gamma/dr2
  const double gd = g1 * rd, gdd = g2 * rd * rd + g1 * rdd;
  const double root = std::sqrt(1.0 - gamma * gamma);
  c.beta[0] = std::acos(gamma);
  c.beta[1] = -gd / root;
  c.beta[2] = -gdd / root - gamma * gd * gd / (root * root * root);
  return true;
}


PathGlobalProblem::PathGlobalProblem(const PlanarArm3& arm, const SampledPath& path, Elbow elbow,
                                     double singular_tolerance, Extension extension)
    : arm_(arm), dyn_(arm), path_(path), elbow_(elbow), tolerance_(singular_tolerance), extension_(extension) {
  const std::size_t n = path.size();
  for (std::vector<double>* v : {&px_, &py_, &vx_, &vy_, &ax_, &ay_, &weight_, &x_, &xd_, &xdd_}) v->resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 p = path.position(i), v = path.path().sample_on(path.segment(i), path.time(i)).v,
               a = path.acceleration(i);
    px_[i] = p.x(), py_[i] = p.y(), vx_[i] = v.x(), vy_[i] = v.y(), ax_[i] = a.x(), ay_[i] = a.y();
    weight_[i] = (i == 0 || i + 1 == n) ? 0.5 * path.dt() : path.dt();
  }
  if (extension_ != Extension::self_motion) return;
  chart_.resize(n);
  for (int k = 0; k < 3; ++k) phi_[k].resize(n), beta_[k].resize(n);
  r_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 p(px_[i], py_[i]), v(vx_[i], vy_[i]), a(ax_[i], ay_[i]);
    ChartSample& c = chart_[i];
    chart_defined_ = chart_defined_ && self_motion_chart(p, v, a, arm.l[0] + arm.l[1], arm.l[2], c);
    for (int k = 0; k < 3; ++k) phi_[k][i] = c.phi[k], beta_[k][i] = c.beta[k];
    r_[i] = p.norm();
  }
}

Terms3RInput PathGlobalProblem::input(GlobalObjective objective) const {
  Terms3RInput in;
  in.arm = &arm_;
  in.dyn = &dyn_;
  in.n = path_.size();
  in.self_motion = extension_ == Extension::self_motion;
  in.elbow = static_cast<int>(elbow_);
  in.clamp = kReachClamp;
  in.tolerance = tolerance_;
  in.objective = objective;
  in.px = px_.data(), in.py = py_.data(), in.vx = vx_.data(), in.vy = vy_.data(), in.ax = ax_.data(), in.ay = ay_.data();
  in.weight = weight_.data();
  for (int k = 0; k < 3; ++k) in.phi[k] = phi_[k].data(), in.beta[k] = beta_[k].data();
  in.r = r_.data();
  in.x = x_.data(), in.xd = xd_.data(), in.xdd = xdd_.data();
  return in;
}

double PathGlobalProblem::coordinate(std::size_t i, double alpha, Elbow elbow) const {
  if (extension_ == Extension::alpha) return alpha;
  const ChartSample& c = chart_[i];
  const double d = std::remainder(alpha - c.phi[0], 2.0 * std::numbers::pi);
  const double s = std::clamp(d / c.beta[0], -1.0, 1.0);
  return std::atan2(s, static_cast<int>(elbow) * std::sqrt(1.0 - s * s));
}

double self_motion_elbow(double psi, double beta, double r, double l3, double l1, double l2) {
  // 1 - cos(theta2) = r l3 (cos(beta sin psi) - cos beta) / (l1 l2), the difference of cosines as a
  // product of sines and 1 -+ sin psi as 2 sin^2(pi/4 -+ psi/2): no cancellation near the stretched arm
  constexpr double q = std::numbers::pi / 4;
  const double u = 2.0 * std::pow(std::sin(q - 0.5 * psi), 2), v = 2.0 * std::pow(std::sin(q + 0.5 * psi), 2);
  const double h = std::clamp(r * l3 * std::sin(0.5 * beta * v) * std::sin(0.5 * beta * u) / (l1 * l2), 0.0, 1.0);
  return (std::cos(psi) >= 0.0 ? 2.0 : -2.0) * std::asin(std::sqrt(h));
}

void PathGlobalProblem::evaluate(std::size_t i, double x, double xd, double xdd, Sample3ROf<double>& s,
                                 double& alpha) const {
  evaluate_3r(input(GlobalObjective::E), i, x, xd, xdd, s, alpha);
}

void PathGlobalProblem::sample(std::size_t i, double x, double xd, double xdd, GlobalSample& out) const {
  Sample3ROf<double> s;
  double alpha = 0.0;
  evaluate(i, x, xd, xdd, s, alpha);
  out.reachable = s.reachable;
  out.det = s.det;
  if (!(s.det == s.det) || (!s.reachable && s.det == 0.0)) return;
  const double t1 = std::atan2(s.trig.s1, s.trig.c1), t2 = std::atan2(s.trig.s2, s.trig.c2);
  out.q = Vec3(t1, t2, alpha - t1 - t2);
  out.qd = s.qd;
  out.qdd = s.qdd;
  out.tau = s.tau;
  out.M = s.M;
  out.J = s.J;
}

void PathGlobalProblem::reach(const AlphaBasis& basis, const double* c, double* con, double* jac) const {
  const int K = basis.coefficients;
  for (std::size_t i = 0; i < path_.size(); ++i) {
    double a, ad, add;
    basis.at(i, c, a, ad, add);
    const Vec2 p = path_.position(i);
    const double ca = std::cos(a), sa = std::sin(a);
    const double x2 = p.x() - arm_.l[2] * ca, y2 = p.y() - arm_.l[2] * sa;
    const double k = 1.0 / (2.0 * arm_.l[0] * arm_.l[1]);
    const double c2 = (x2 * x2 + y2 * y2 - arm_.l[0] * arm_.l[0] - arm_.l[1] * arm_.l[1]) * k;
    con[i] = c2 * c2 - 1.0;
    if (!jac) continue;
    // d|w|^2 / d alpha with w = p - l3 (cos a, sin a): 2 w . l3 (sin a, -cos a)
    const double dc2 = 2.0 * arm_.l[2] * (x2 * sa - y2 * ca) * k;
    double* row = jac + i * static_cast<std::size_t>(K);
    std::fill(row, row + K, 0.0);
    const BasisRow& r = basis.rows[i];
    for (int m = 0; m < kBasisWidth && r.first + m < K; ++m) row[r.first + m] = 2.0 * c2 * dc2 * r.w[0][m];
  }
}

double PathGlobalProblem::objective(const AlphaBasis& basis, const double* c, GlobalObjective objective,
                                    double* grad) const {
  const int K = basis.coefficients;
  const std::size_t n = path_.size();
  for (std::size_t i = 0; i < n; ++i) basis.at(i, c, x_[i], xd_[i], xdd_[i]);
  const Terms3RInput in = input(objective);
  if (term_.size() != n)  // allocated by the first evaluation (a problem only measured needs none)
    for (std::vector<double>* v : {&term_, &partial_[0], &partial_[1], &partial_[2]}) v->resize(n);
  double* const partial[3] = {partial_[0].data(), partial_[1].data(), partial_[2].data()};
  const std::size_t done = in_lanes(n, [&](int lanes, std::size_t end) {
    (void)lanes, (void)end;
#if defined(KS_LANES_X8)
    if (lanes == 8) terms_3r_x8(in, 0, end, grad != nullptr, term_.data(), partial);
#endif
#if defined(KS_LANES_X4)
    if (lanes == 4) terms_3r_x4(in, 0, end, grad != nullptr, term_.data(), partial);
#endif
  });
  terms_3r<double>(in, done, n, grad != nullptr, term_.data(), partial);
  double f = 0.0;
  for (std::size_t i = 0; i < n; ++i) f += term_[i];
  if (!grad) return f;
  std::fill(grad, grad + K, 0.0);
  basis.add_gradients(partial, grad);
  return f;
}

void PathGlobalProblem::samples(const AlphaBasis& basis, const double* c, const Terms3RInput& in, std::size_t first,
                                std::size_t end, Sample3RBlock& block) const {
  for (std::size_t i = first; i < end; ++i) basis.at(i, c, x_[i], xd_[i], xdd_[i]);
  const std::size_t done = first + in_lanes(end - first, [&](int lanes, std::size_t count) {
    (void)lanes, (void)count;
#if defined(KS_LANES_X8)
    if (lanes == 8) samples_3r_x8(in, first, first + count, block);
#endif
#if defined(KS_LANES_X4)
    if (lanes == 4) samples_3r_x4(in, first, first + count, block);
#endif
  });
  samples_3r<double>(in, done, end, block);
}

/// The run of a spline as a prescribed model of the one trajectory loop (methods/loop/trajectory_loop.hpp):
/// the samples computed a block at a time (in lanes where the processor has them), nothing
/// integrated. The joint angles (atan2) only where something reads them: a history column, and the
/// last sample's tip angle (final_alpha; the samples carry no joint limits, which would read q): it
/// is computed at the end of each block and, for a run ending inside a block, once the loop ends.
class PathGlobalProblem::MeasureModel {
 public:
  static constexpr int max_joints = 3;
  static constexpr bool prismatic_joints = false;
  struct Evaluation {
    double qdd[3];  // (read by the loop's integrator only, which a prescribed model skips)
  };

  MeasureModel(const PathGlobalProblem& p, const AlphaBasis& basis, const double* c, const TrajectoryOptions& o,
               TrajectoryHistory* history)
      : p_(p), basis_(basis), c_(c), o_(o), history_(history), in_(p.input(GlobalObjective::E)) {}

  int joints() const { return 3; }
  LoopShape shape() const {
    return {p_.samples(), p_.path_.dt(), o_.integrator, o_.on_violation == OnViolation::stop, true};
  }
  SampleSums<double, 3> sums() const { return SampleSums<double, 3>(o_.tracking_bound, o_.orientation_bound); }
  /// The tip angle at the start: sample 0's, or its coordinate where it is out of reach.
  bool start(double*) {
    double x0, xd0, xdd0;
    basis_.at(0, c_, x0, xd0, xdd0);
    GlobalSample s0;
    p_.sample(0, x0, xd0, xdd0, s0);
    alpha0_ = s0.reachable ? s0.q.sum() : x0;
    return true;
  }
  double alpha(const double*) const { return alpha0_; }
  double torque_bound() const { return o_.torque_bound; }

  RunStatus at_sample(std::size_t i, double, double*, double* qd, Evaluation&) {
    j_ = i % kSampleBlock;
    if (j_ == 0) p_.samples(basis_, c_, in_, i, std::min(p_.samples(), i + kSampleBlock), block_);
    const double det = block_.det[j_];
    if (!(block_.reach[j_] != 0.0) || !std::isfinite(det)) return RunStatus::infeasible;
    if (p_.extension_ == Extension::alpha && !(std::abs(det) >= o_.singular_tolerance))
      return RunStatus::singular_extension;
    for (int k = 0; k < 3; ++k) qd[k] = block_.qd[k][j_];
    return RunStatus::ok;
  }
  void torques(const Evaluation&, const double*, double* tau) const {
    for (int k = 0; k < 3; ++k) tau[k] = block_.tau[k][j_];
  }
  static double squared_torque(const double* tau) { return Vec3(tau[0], tau[1], tau[2]).squaredNorm(); }

  void values(const Evaluation&, std::size_t i, const double*, const double* qd, const double* tau,
              SampleValues<double>& v) {
    const std::size_t j = j_;
    const Sym3 M{block_.M[0][j], block_.M[1][j], block_.M[2][j], block_.M[3][j], block_.M[4][j], block_.M[5][j]};
    Mat23 J;
    J << block_.J[0][j], block_.J[1][j], block_.J[2][j], block_.J[3][j], block_.J[4][j], block_.J[5][j];
    const SymInverse3 Mi(M);
    tip_ = Vec2(block_.tip[0][j], block_.tip[1][j]);
    const Vec2 err = tip_ - p_.path_.position(i);
    const Vec3 t3(tau[0], tau[1], tau[2]), qd3(qd[0], qd[1], qd[2]);
    v.q = nullptr, v.qd = qd, v.tau = tau;
    v.qf = Mi.P.quadratic_form(t3), v.det = Mi.det, v.w2 = manipulability_squared(J), v.err2 = err.squaredNorm();
    v.orient = 0.0, v.alpha = 0.0, v.ke = 0.5 * M.quadratic_form(qd3);
    added_ = true;
    pending_ = static_cast<std::ptrdiff_t>(j);
    if (j + 1 == kSampleBlock || i + 1 == p_.samples()) {
      const Vec3 q = angles(j);
      last_alpha_ = q[0] + q[1] + q[2];
      pending_ = -1;
    }
  }
  void record(std::size_t i, double t, const Evaluation&, const double*, const double* qd, const double* tau, bool) const {
    const std::size_t n = p_.samples();
    if (!history_ || !(i % static_cast<std::size_t>(history_->stride) == 0 || i + 1 == n)) return;
    TrajectoryHistory& h = *history_;
    const Eigen::Index col = h.size++;
    h.t[col] = t;
    const Vec3 q = angles(j_);
    h.q.col(col) = q;
    h.qd.col(col) = Vec3(qd[0], qd[1], qd[2]);
    h.qdd.col(col) = Vec3(block_.qdd[0][j_], block_.qdd[1][j_], block_.qdd[2][j_]);
    h.tau.col(col) = Vec3(tau[0], tau[1], tau[2]);
    h.x.col(col) = tip_;
    h.alpha[col] = q[0] + q[1] + q[2];
  }
  void finish(SampleSums<double, 3>& sums) {
    if (pending_ >= 0) {
      const Vec3 q = angles(static_cast<std::size_t>(pending_));
      last_alpha_ = q[0] + q[1] + q[2];
    }
    if (added_) sums.set_last_alpha(last_alpha_);
  }
  void stages(double, double) {}
  bool stage(bool, const double*, const double*, Evaluation&) { return true; }
  void moved(const double*, const double*) {}

 private:
  Vec3 angles(std::size_t j) const {
    const double t1 = std::atan2(block_.s1[j], block_.c1[j]), t2 = std::atan2(block_.s2[j], block_.c2[j]);
    return Vec3(t1, t2, block_.alpha[j] - t1 - t2);
  }

  const PathGlobalProblem& p_;
  const AlphaBasis& basis_;
  const double* c_;
  const TrajectoryOptions& o_;
  TrajectoryHistory* history_;
  const Terms3RInput in_;
  Sample3RBlock block_;
  std::size_t j_ = 0;               // the sample's row in block_
  double alpha0_ = 0.0, last_alpha_ = 0.0;
  std::ptrdiff_t pending_ = -1;     // the block row of the last sample added, its angle not yet computed
  bool added_ = false;
  Vec2 tip_ = Vec2::Zero();
};

TrajectoryMetrics PathGlobalProblem::measure(const AlphaBasis& basis, const double* c, const TrajectoryOptions& o,
                                             TrajectoryHistory* history) const {
  if (history) history->prepare(samples());
  MeasureModel model(*this, basis, c, o, history);
  RunSums sums;
  trajectory_loop<double>(model, &sums);
  return finish_run(sums, RunShape{}, o);
}

}  // namespace ks
