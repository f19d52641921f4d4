// solve_start(): damped Newton / minimum-norm steps on the start's rows (see chain_start.hpp).
#include "methods/chain/start.hpp"

#include <Eigen/LU>

#include <array>
#include <cmath>

#include "methods/chain/resolution.hpp"
#include "model/chain_kinematics.hpp"

namespace ks {
namespace {

using RowVec = Eigen::Vector3d;
using RowMat = Eigen::Matrix3d;
using RowJac = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kMaxJoints>;

/// The start's rows at q: residual e = target - current, and their Jacobian.
class StartRows {
 public:
  StartRows(const Chain& chain, const StartTarget& t) : chain_(chain), t_(t), angle_(chain) {}
  /// |e| at q; fills e and, when J is given, the Jacobian.
  double residual(const VecN& q, RowVec& e, RowJac* J) {
    forward_kinematics(chain_, data_, q);
    const int pos = t_.planar ? 2 : 3;
    for (int r = 0; r < pos; ++r) e[r] = t_.position[r] - data_.tip.p[r];
    if (t_.planar) e[2] = t_.angle - angle_(q);
    if (J) {
      tip_jacobian(chain_, data_, J6_);
      J->resize(3, q.size());
      J->topRows(pos) = J6_.topRows(pos);
      if (t_.planar) J->row(2) = J6_.row(5);
    }
    return e.norm();
  }

 private:
  const Chain& chain_;
  const StartTarget& t_;
  const PlanarAngle angle_;
  ChainData data_;
  Mat6N J6_;
};

/// Position-limit violation of joint j at value x [rad or m]: 0 within [lower, upper].
double violation(const ChainJoint& J, double x) {
  if (x > J.upper) return x - J.upper;
  if (x < J.lower) return x - J.lower;
  return 0.0;
}

bool within_limits(const Chain& chain, const VecN& q) {
  for (int j = 0; j < q.size(); ++j)
    if (violation(chain.joints[static_cast<std::size_t>(j)], q[j]) != 0.0) return false;
  return true;
}

/// Each revolute joint outside its limits moved by the multiple of 2 pi that brings it nearest to
/// the centre of [lower, upper] (the same pose, the least violation).
void shift_into_limits(const Chain& chain, VecN& q) {
  constexpr double two_pi = 2.0 * 3.14159265358979323846;
  for (int j = 0; j < q.size(); ++j) {
    const ChainJoint& J = chain.joints[static_cast<std::size_t>(j)];
    if (J.type != JointType::revolute || violation(J, q[j]) == 0.0 || !std::isfinite(J.lower) || !std::isfinite(J.upper))
      continue;
    const double centre = 0.5 * (J.lower + J.upper);
    q[j] -= two_pi * std::round((q[j] - centre) / two_pi);
  }
}

/// The Halton sequence's k-th value in base b, in (0, 1): k's digits in base b mirrored about the point.
double radical_inverse(int k, int b) {
  double x = 0.0, f = 1.0 / b;
  for (; k > 0; k /= b, f /= b) x += f * (k % b);
  return x;
}
constexpr std::array<int, kMaxJoints> kPrimes = [] {
  std::array<int, kMaxJoints> p{};
  for (int n = 2, i = 0; i < kMaxJoints; ++n) {
    bool prime = true;
    for (int d = 2; d * d <= n; ++d) prime = prime && n % d != 0;
    if (prime) p[static_cast<std::size_t>(i++)] = n;
  }
  return p;
}();

}  // namespace

namespace {

/// The damped Newton / minimum-norm iteration from q0 (solve_start's first stage).
std::optional<VecN> place_on_target(const Chain& chain, const StartTarget& target, const VecN& q0,
                                    const StartSolveOptions& o) {
  StartRows rows(chain, target);
  VecN q = q0, trial;
  RowVec e, e_trial;
  RowJac J;
  double norm = rows.residual(q, e, &J);
  double lambda2 = 0.0;
  int polish = 0;  // steps taken after convergence
  for (int it = 0; it < o.max_iterations; ++it) {
    if (norm <= o.tolerance && polish == 2) break;
    RowMat A = J * J.transpose();
    A.diagonal().array() += lambda2;
    const RowVec y = A.partialPivLu().solve(e);
    trial = q + J.transpose() * y;
    const double trial_norm = rows.residual(trial, e_trial, nullptr);
    if (trial_norm < norm) {
      q = trial;
      norm = rows.residual(q, e, &J);
      lambda2 = lambda2 > 1e-12 ? lambda2 / 10.0 : 0.0;
      if (norm <= o.tolerance) ++polish;
    } else if (norm <= o.tolerance) {
      break;  // converged, and no step improves on it
    } else {
      lambda2 = lambda2 == 0.0 ? 1e-6 : 10.0 * lambda2;  // (1e-3)^2, then tenfold in lambda^2
      if (!(lambda2 < 1e12)) break;
    }
  }
  if (!(norm <= o.tolerance) || !q.allFinite()) return std::nullopt;
  return q;
}

/// Null-space steps that pull the joints outside their position limits towards a margin inside them
/// while the tip stays on the target: dq = J^+ e - (I - J^+ J) v, v_j = the joint's violation of
/// [lower + m_j, upper - m_j] (m_j = 2 % of its range), each followed by the task's correction.
/// Returns the iterate with the least total violation of the true limits (q itself if none is better).
VecN pull_into_limits(const Chain& chain, const StartTarget& target, const VecN& q_start, int steps) {
  StartRows rows(chain, target);
  VecN q = q_start, best = q_start, v(q.size());
  RowVec e;
  RowJac J;
  auto total = [&](const VecN& x) {
    double t = 0.0;
    for (int j = 0; j < x.size(); ++j) t += std::abs(violation(chain.joints[static_cast<std::size_t>(j)], x[j]));
    return t;
  };
  double best_total = total(q);
  for (int it = 0; it < steps && best_total > 0.0; ++it) {
    rows.residual(q, e, &J);
    for (int j = 0; j < q.size(); ++j) {
      const ChainJoint& Jt = chain.joints[static_cast<std::size_t>(j)];
      const double m = std::isfinite(Jt.upper - Jt.lower) ? 0.02 * (Jt.upper - Jt.lower) : 0.0;
      ChainJoint inner = Jt;
      inner.lower += m, inner.upper -= m;
      v[j] = violation(inner, q[j]);
    }
    const Eigen::PartialPivLU<RowMat> lu(J * J.transpose());
    const VecN null_step = v - J.transpose() * lu.solve(J * v);
    q += J.transpose() * lu.solve(e) - null_step;
    if (!q.allFinite()) break;
    const double t = total(q);
    if (t < best_total) best = q, best_total = t;
  }
  return best;
}

}  // namespace

std::optional<VecN> solve_start(const Chain& chain, const StartTarget& target, const VecN& q0,
                                const StartSolveOptions& o) {
  const std::optional<VecN> q = place_on_target(chain, target, q0, o);
  if (!q || !o.respect_limits || within_limits(chain, *q)) return q;
  // Every candidate is put back on the target by place_on_target (which checks the residual) and
  // kept only within the limits. A 2 pi shift is the same pose in space; for a planar target it is
  // not (the start's angle row counts turns), so planar starts are only pulled.
  const auto on_target_within = [&](const VecN& from) -> std::optional<VecN> {
    std::optional<VecN> c = place_on_target(chain, target, from, o);
    return c && within_limits(chain, *c) ? c : std::nullopt;
  };
  const auto moved_from = [&](VecN from) -> std::optional<VecN> {
    if (!target.planar) {
      shift_into_limits(chain, from);
      if (within_limits(chain, from))
        if (std::optional<VecN> c = on_target_within(from)) return c;
    }
    return on_target_within(pull_into_limits(chain, target, from, o.limit_steps));
  };
  if (std::optional<VecN> c = moved_from(*q)) return c;
  // again from the middle of the limits (joints without both limits: the guess's value)
  VecN centre = q0;
  for (int j = 0; j < centre.size(); ++j) {
    const ChainJoint& J = chain.joints[static_cast<std::size_t>(j)];
    if (std::isfinite(J.lower) && std::isfinite(J.upper)) centre[j] = 0.5 * (J.lower + J.upper);
  }
  const auto from_guess = [&](const VecN& guess) -> std::optional<VecN> {
    if (const std::optional<VecN> c = place_on_target(chain, target, guess, o)) {
      if (within_limits(chain, *c)) return c;
      if (std::optional<VecN> m = moved_from(*c)) return m;
    }
    return std::nullopt;
  };
  if (std::optional<VecN> c = from_guess(centre)) return c;
  // again from guesses spread over the limits: the other branches of the inverse kinematics
  for (int k = 1; k <= o.restarts; ++k) {
    VecN guess = q0;
    for (int j = 0; j < guess.size(); ++j) {
      const ChainJoint& J = chain.joints[static_cast<std::size_t>(j)];
      const double u = radical_inverse(k, kPrimes[static_cast<std::size_t>(j)]);
      if (std::isfinite(J.lower) && std::isfinite(J.upper)) guess[j] = J.lower + u * (J.upper - J.lower);
      else if (J.type == JointType::revolute) guess[j] = q0[j] + (2.0 * u - 1.0) * 3.14159265358979323846;
    }
    if (std::optional<VecN> c = from_guess(guess)) return c;
  }
  // none within the limits: the spatial start as the same pose nearest to them, else the first
  if (!target.planar) {
    VecN shifted = *q;
    shift_into_limits(chain, shifted);
    if (std::optional<VecN> c = place_on_target(chain, target, shifted, o)) return c;
  }
  return q;
}

VecN planar_start_guess(int n) {
  VecN q(n);
  for (int i = 0; i < n; ++i) q[i] = i == 0 ? 0.5 : (i % 2 == 1 ? 1.0 : -1.0);
  return q;
}

}  // namespace ks
