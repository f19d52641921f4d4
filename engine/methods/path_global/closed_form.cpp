// PathGlobalProblem (methods/path_global/closed_form.hpp): the joint path by exact IK, the objective with its
// chain-rule gradient, and the metrics through the per-sample accumulator.
#include "methods/path_global/closed_form.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "methods/metrics/sample_sums.hpp"

namespace ks {

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
  velocity_.reserve(path.size());
  for (std::size_t i = 0; i < path.size(); ++i)
    velocity_.push_back(path.path().sample_on(path.segment(i), path.time(i)).v);
  if (extension_ != Extension::self_motion) return;
  chart_.resize(path.size());
  for (std::size_t i = 0; i < path.size(); ++i)
    chart_defined_ = chart_defined_ && self_motion_chart(path.position(i), velocity_[i], path.acceleration(i),
                                                arm.l[0] + arm.l[1], arm.l[2], chart_[i]);
}

double PathGlobalProblem::coordinate(std::size_t i, double alpha, Elbow elbow) const {
  if (extension_ == Extension::alpha) return alpha;
  const ChartSample& c = chart_[i];
  const double d = std::remainder(alpha - c.phi[0], 2.0 * std::numbers::pi);
  const double s = std::clamp(d / c.beta[0], -1.0, 1.0);
  return std::atan2(s, static_cast<int>(elbow) * std::sqrt(1.0 - s * s));
}

void PathGlobalProblem::sample(std::size_t i, double x, double xd, double xdd, GlobalSample& s) const {
  if (extension_ == Extension::alpha) return sample_alpha(i, x, xd, xdd, elbow_, s);
  const ChartSample& c = chart_[i];
  const double sp = std::sin(x), cp = std::cos(x);
  const double a = c.phi[0] + c.beta[0] * sp;
  const double ad = c.phi[1] + c.beta[1] * sp + c.beta[0] * cp * xd;
  const double add = c.phi[2] + c.beta[2] * sp + 2.0 * c.beta[1] * cp * xd - c.beta[0] * sp * xd * xd + c.beta[0] * cp * xdd;
  sample_alpha(i, a, ad, add, cp >= 0.0 ? Elbow::positive : Elbow::negative, s, self_motion_elbow(x, c.beta[0],
               path_.position(i).norm(), arm_.l[2], arm_.l[0], arm_.l[1]));
}

double self_motion_elbow(double psi, double beta, double r, double l3, double l1, double l2) {
  // 1 - cos(theta2) = r l3 (cos(beta sin psi) - cos beta) / (l1 l2), the difference of cosines as a
  // product of sines and 1 -+ sin psi as 2 sin^2(pi/4 -+ psi/2): no cancellation near the stretched arm
  constexpr double q = std::numbers::pi / 4;
  const double u = 2.0 * std::pow(std::sin(q - 0.5 * psi), 2), v = 2.0 * std::pow(std::sin(q + 0.5 * psi), 2);
  const double h = std::clamp(r * l3 * std::sin(0.5 * beta * v) * std::sin(0.5 * beta * u) / (l1 * l2), 0.0, 1.0);
  return (std::cos(psi) >= 0.0 ? 2.0 : -2.0) * std::asin(std::sqrt(h));
}

void PathGlobalProblem::sample_alpha(std::size_t i, double a, double ad, double add, Elbow elbow,
                                     GlobalSample& s, double theta2) const {
  // inverse_kinematics (model/kinematics.hpp) with cos(theta2) kept within reach, so that the joint
  // path and the objective continue past the reach boundary (the optimiser's trial points; the reach
  // constraints bring it back): an unreachable sample is reported, its values are those at the boundary
  const Vec2 p = path_.position(i);
  const double ca = std::cos(a), sa = std::sin(a);
  const double x2 = p.x() - arm_.l[2] * ca, y2 = p.y() - arm_.l[2] * sa;
  const double d = x2 * x2 + y2 * y2;
  const double c2_raw = (d - arm_.l[0] * arm_.l[0] - arm_.l[1] * arm_.l[1]) / (2.0 * arm_.l[0] * arm_.l[1]);
  s.reachable = std::abs(c2_raw) <= 1.0 && d > 0.0;
  if (!(d > 0.0) || !std::isfinite(c2_raw)) {
    s.reachable = false;
    s.det = 0.0;
    return;
  }
  const bool given = std::isfinite(theta2);  // the self-motion chart's, within reach by construction
  if (given) s.reachable = true;
  const double c2 = given ? std::cos(theta2) : std::clamp(c2_raw, -kReachClamp, kReachClamp);
  const double s2 = given ? std::sin(theta2) : static_cast<int>(elbow) * std::sqrt(1.0 - c2 * c2);
  const double c1 = ((arm_.l[0] + arm_.l[1] * c2) * x2 + arm_.l[1] * s2 * y2) / d;
  const double s1 = ((arm_.l[0] + arm_.l[1] * c2) * y2 - arm_.l[1] * s2 * x2) / d;
  const double t1 = std::atan2(s1, c1), t2 = std::atan2(s2, c2);
  s.q = Vec3(t1, t2, a - t1 - t2);
  const JointTrig t = joint_trig(s.q);
  s.J = jacobian(arm_, t);
  Mat3 J3;
  J3.topRows<2>() = s.J;
  J3.row(2).setOnes();
  const Eigen::PartialPivLU<Mat3> lu(J3);
  s.det = lu.determinant();
  s.qd = lu.solve(Vec3(velocity_[i].x(), velocity_[i].y(), ad));
  const Vec2 jdqd = jacobian_dot_times_qd(arm_, t, s.qd);
  const Vec2 xdd = path_.acceleration(i);
  s.qdd = lu.solve(Vec3(xdd.x() - jdqd.x(), xdd.y() - jdqd.y(), add));
  s.M = mass_matrix_sym(dyn_, t);
  s.tau = s.M * s.qdd + coriolis(dyn_, t, s.qd) + gravity(dyn_, t);
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

double PathGlobalProblem::cost(std::size_t i, double a, double ad, double add, GlobalObjective objective) const {
  GlobalSample s;
  sample(i, a, ad, add, s);
  if (extension_ == Extension::alpha && !(std::abs(s.det) >= tolerance_)) {  // a barrier the size of a diverged run
    return 1e6 / static_cast<double>(path_.size());
  }
  const std::size_t n = path_.size();
  const double trapezoid = (i == 0 || i + 1 == n) ? 0.5 * path_.dt() : path_.dt();
  switch (objective) {
    case GlobalObjective::E: return std::sqrt(s.tau.squaredNorm()) / static_cast<double>(n);
    case GlobalObjective::E_M: {
      const SymInverse3 Mi(s.M);
      return std::sqrt(Mi.P.quadratic_form(s.tau) / Mi.det) / static_cast<double>(n);
    }
    case GlobalObjective::torque_sq_integral: return trapezoid * s.tau.squaredNorm();
    case GlobalObjective::kinetic_energy: return trapezoid * 0.5 * s.M.quadratic_form(s.qd);
  }
  return 0.0;
}

double PathGlobalProblem::objective(const AlphaBasis& basis, const double* c, GlobalObjective objective,
                                    double* grad) const {
  const int K = basis.coefficients;
  if (grad) std::fill(grad, grad + K, 0.0);
  double f = 0.0;
  for (std::size_t i = 0; i < path_.size(); ++i) {
    double x[3];
    basis.at(i, c, x[0], x[1], x[2]);
    f += cost(i, x[0], x[1], x[2], objective);
    if (!grad) continue;
    const BasisRow& r = basis.rows[i];
    for (int d = 0; d < 3; ++d) {
      const double h = 1e-6 * std::max(1.0, std::abs(x[d]));
      double up[3] = {x[0], x[1], x[2]}, down[3] = {x[0], x[1], x[2]};
      up[d] += h;
      down[d] -= h;
      const double partial = (cost(i, up[0], up[1], up[2], objective) - cost(i, down[0], down[1], down[2], objective)) /
                             (up[d] - down[d]);
      for (int k = 0; k < kBasisWidth && r.first + k < K; ++k) grad[r.first + k] += partial * r.w[d][k];
    }
  }
  return f;
}

TrajectoryMetrics PathGlobalProblem::measure(const AlphaBasis& basis, const double* c, const TrajectoryOptions& o,
                                             TrajectoryHistory* history) const {
  const std::size_t n = path_.size();
  if (history) history->prepare(n);
  SampleSums<double, 3> sums(o.tracking_bound, o.orientation_bound);
  double x0, xd0, xdd0;
  basis.at(0, c, x0, xd0, xdd0);
  GlobalSample s0;
  sample(0, x0, xd0, xdd0, s0);
  sums.start_alpha(s0.reachable ? s0.q.sum() : x0);
  RunStatus stop = RunStatus::ok;
  const auto keep = [](double updated, double) { return updated; };
  for (std::size_t i = 0; i < n; ++i) {
    const double t = path_.time(i);
    double a, ad, add;
    basis.at(i, c, a, ad, add);
    GlobalSample s;
    sample(i, a, ad, add, s);
    if (!s.reachable || !std::isfinite(s.det)) {
      stop = RunStatus::infeasible;
      break;
    }
    if (extension_ == Extension::alpha && !(std::abs(s.det) >= o.singular_tolerance)) {
      stop = RunStatus::singular_extension;
      break;
    }
    const double abs_tau[3] = {std::abs(s.tau[0]), std::abs(s.tau[1]), std::abs(s.tau[2])};
    const double tt = s.tau.squaredNorm();
    if (!(std::max({abs_tau[0], abs_tau[1], abs_tau[2]}) <= o.torque_bound) || !std::isfinite(tt)) {
      stop = RunStatus::diverged;
      break;
    }
    const SymInverse3 Mi(s.M);
    const JointTrig trig = joint_trig(s.q);
    const Vec2 tip = end_effector(arm_, trig), err = tip - path_.position(i);
    const double p0 = s.tau[0] * s.qd[0], p1 = s.tau[1] * s.qd[1], p2 = s.tau[2] * s.qd[2];
    const double alpha = s.q[0] + s.q[1] + s.q[2];
    const SampleValues<double> v{3, s.q.data(), s.qd.data(), s.tau.data(), tt, 0.0, Mi.P.quadratic_form(s.tau), Mi.det,
                                 p0 * p0 + p1 * p1 + p2 * p2, manipulability_squared(s.J), err.squaredNorm(), 0.0, alpha,
                                 0.5 * s.M.quadratic_form(s.qd)};
    const bool off = sums.add(i, t, v, abs_tau, 3, keep);
    sums.mark(off);
    if (history && (i % static_cast<std::size_t>(history->stride) == 0 || i + 1 == n)) {
      const Eigen::Index col = history->size++;
      history->t[col] = t;
      history->q.col(col) = s.q;
      history->qd.col(col) = s.qd;
      history->qdd.col(col) = s.qdd;
      history->tau.col(col) = s.tau;
      history->x.col(col) = tip;
      history->alpha[col] = alpha;
    }
    if (off && o.on_violation == OnViolation::stop) break;
  }
  RunShape shape;
  return finish_run(sums.of_lane(0, stop, 3), shape, o);
}

}  // namespace ks
