#pragma once
// Definitions of ik/solve.hpp. Include this (instead of solve.hpp) in the one .cpp that instantiates
// solve() for a new problem description; the engine's problems are instantiated in ik/solve.cpp.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <ostream>
#include <random>

#include "ik/cycle_watch.hpp"
#include "ik/small_dense.hpp"
#include "ik/solve.hpp"

namespace ks::ik {
namespace detail {

/// Reciprocal condition below which a matrix is treated as singular; NaN counts as singular.
inline bool too_singular(double rcond, double rcond_min) { return !(rcond >= rcond_min); }

/// Reciprocal condition number of a square matrix in the 1-norm, 1 / (|A|_1 |A^-1|_1): exact and
/// cheap for N <= 3 (|A^-1|_1 = |adj A|_1 / |det A|), the LU estimate (LAPACK's) beyond. 0 for an
/// exactly singular A, NaN for a non-finite one.
template <int N>
inline double rcond1(const Mat<N, N>& A) {
  if constexpr (N == 1) {
    return A(0, 0) != 0.0 ? 1.0 : (A(0, 0) == 0.0 ? 0.0 : A(0, 0));
  } else if constexpr (N == 2) {
    const double det = A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
    const double n1 = std::max(std::abs(A(0, 0)) + std::abs(A(1, 0)), std::abs(A(0, 1)) + std::abs(A(1, 1)));
    const double ni = std::max(std::abs(A(1, 1)) + std::abs(A(1, 0)), std::abs(A(0, 1)) + std::abs(A(0, 0)));
    return det == 0.0 ? 0.0 : std::abs(det) / (n1 * ni);
  } else if constexpr (N == 3) {
    Mat<3, 3> C;  // cofactors; adj A = C^T, so |adj A|_1 = max row sum of |C|
    C(0, 0) = A(1, 1) * A(2, 2) - A(1, 2) * A(2, 1);
    C(0, 1) = A(1, 2) * A(2, 0) - A(1, 0) * A(2, 2);
    C(0, 2) = A(1, 0) * A(2, 1) - A(1, 1) * A(2, 0);
    C(1, 0) = A(0, 2) * A(2, 1) - A(0, 1) * A(2, 2);
    C(1, 1) = A(0, 0) * A(2, 2) - A(0, 2) * A(2, 0);
    C(1, 2) = A(0, 1) * A(2, 0) - A(0, 0) * A(2, 1);
    C(2, 0) = A(0, 1) * A(1, 2) - A(0, 2) * A(1, 1);
    C(2, 1) = A(0, 2) * A(1, 0) - A(0, 0) * A(1, 2);
    C(2, 2) = A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
    const double det = A(0, 0) * C(0, 0) + A(0, 1) * C(0, 1) + A(0, 2) * C(0, 2);
    const double n1 = A.cwiseAbs().colwise().sum().maxCoeff();
    const double ni = C.cwiseAbs().rowwise().sum().maxCoeff();
    return det == 0.0 ? 0.0 : std::abs(det) / (n1 * ni);
  } else {
    return lu_rcond<N>(A);
  }
}

/// Solve A x = b in Newton's sense for an M x N matrix A: exact (M = N, LU), minimum-norm
/// x = A^T (A A^T)^-1 b (M < N) or least squares x = (A^T A)^-1 A^T b (M > N). Returns the
/// reciprocal condition of A (for M != N the square root of that of the Gram matrix solved).
template <int M, int N>
inline double newton_solve(const Mat<M, N>& A, const Vec<M>& b, Vec<N>& x) {
  if constexpr (M == N) {
    x = SmallLu<N>(A).solve(b);
    return rcond1<N>(A);
  } else if constexpr (M < N) {
    const Mat<M, M> G = A * A.transpose();
    const Vec<M> y = SmallLlt<M>(G).solve(b);
    x = A.transpose() * y;
    return std::sqrt(rcond1<M>(G));
  } else {
    const Mat<N, N> G = A.transpose() * A;
    x = SmallLlt<N>(G).solve(A.transpose() * b);
    return std::sqrt(rcond1<N>(G));
  }
}

template <int N, int M>
inline bool all_finite(const Vec<N>& q, const Vec<M>& F) {
  return q.allFinite() && F.allFinite();
}

/// True when the solve enforces joint j's limits (the problem has them, joint j has a finite one and
/// Options::joint_limits is not none): its converged angle is not wrapped.
template <Problem P>
inline bool limits_enforced(const P& pb, int j, const Options& o) {
  if constexpr (HasLimitBounds<P>) {
    return o.joint_limits != JointLimits::none && (std::isfinite(pb.lower[j]) || std::isfinite(pb.upper[j]));
  } else {
    (void)pb, (void)j, (void)o;
    return false;
  }
}

/// A restart's start: per joint one draw u in (0, 1) from rng (see ik/solve.hpp), mapped into the
/// joint's finite limits, else (-pi, pi) for a revolute joint; a prismatic joint without finite
/// limits keeps q0's value.
template <Problem P>
inline Vec<P::unknowns> restart_start(const P& pb, const Vec<P::unknowns>& q0, std::mt19937_64& rng) {
  constexpr double kPi = 3.14159265358979323846;
  Vec<P::unknowns> q = q0;
  for (int j = 0; j < P::unknowns; ++j) {
    const double u = (static_cast<double>(rng() >> 11) + 0.5) * 0x1p-53;
    double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
    if constexpr (HasLimitBounds<P>) lo = pb.lower[j], hi = pb.upper[j];
    if (std::isfinite(lo) && std::isfinite(hi)) q[j] = lo + (hi - lo) * u;
    else if (pb.revolute[j]) q[j] = kPi - 2.0 * kPi * u;
  }
  return q;
}

/// One attempt of solve() from q0 (see ik/solve.hpp); `append` keeps the history of the attempts
/// before it.
template <Problem P>
void solve_attempt(const P& pb, const Vec<P::unknowns>& q0, const Options& o, Summary<P::unknowns, P::residuals>& s,
                   bool append) {
  constexpr int N = P::unknowns, M = P::residuals;
  using VecN = Vec<N>;
  using VecM = Vec<M>;
  using MatMN = Mat<M, N>;
  using MatNN = Mat<N, N>;

  s.method = o.method;
  s.status = Status::max_iter;
  s.iterations = 0;
  s.rejected = 0;
  s.solution = -1;
  s.min_rcond = std::numeric_limits<double>::infinity();
  if (!append) s.history.clear();
  const bool keep = o.keep_history;
  if (keep) s.history.reserve(s.history.size() + static_cast<std::size_t>(std::max(o.max_iter, 0)) + 1);

  VecN q = q0;
  VecM F;
  MatMN J;
  pb.evaluate(q, F, J);
  double e = F.norm();

  // lm_adaptive state (Madsen, Nielsen & Tingleff, "Methods for non-linear least squares problems", 2004).
  double mu = 0.0, nu = 2.0;
  if (o.method == Method::lm_adaptive) {
    const double d = (J.transpose() * J).diagonal().maxCoeff();
    mu = o.lambda_scale * (d > 0.0 && std::isfinite(d) ? d : 1.0);
  }
  const double lambda0 = o.method == Method::lm ? o.lambda : mu;
  if (keep) s.history.push(q, F, e, 0.0, lambda0);

  // Joint limits: only problems that declare them (HasJointLimits) see Options::joint_limits.
  bool clamping = false, rejecting = false;
  if constexpr (HasJointLimits<P>) {
    clamping = o.joint_limits == JointLimits::clamp;
    rejecting = o.joint_limits == JointLimits::reject;
  }

  auto finish = [&](Status st) {
    if constexpr (HasJointLimits<P>) {
      if (st == Status::converged && rejecting && !pb.admit(q)) st = Status::out_of_limits;
    }
    if (st == Status::converged)
      for (int j = 0; j < N; ++j)
        if (pb.revolute[j] && !limits_enforced(pb, j, o)) q[j] = wrap_angle(q[j]);
    s.status = st;
    s.q = q;
    s.F = F;
    s.error = e;
    if constexpr (HasKnownSolutions<P>) s.solution = match_solution<N>(pb.known_solutions(), q, pb.revolute, o.match_tolerance);
  };
  auto rcond_ok = [&](double rc) {
    s.min_rcond = std::min(s.min_rcond, rc);
    return !detail::too_singular(rc, o.rcond_min);
  };

  if (!detail::all_finite<N, M>(q, F)) return finish(Status::diverged);

  if (o.method == Method::analytic) {
    if constexpr (HasKnownSolutions<P>) {
      const SolutionSet<N> set = pb.known_solutions();
      if (set.count == 0) return finish(set.continuum ? Status::unsupported : Status::no_solution);
      int best = 0;
      double best_d = std::numeric_limits<double>::infinity();
      for (int i = 0; i < set.count; ++i) {
        const double d = joint_difference<N>(set.q[i], q0, pb.revolute).norm();
        if (d < best_d) best = i, best_d = d;
      }
      q = set.q[best];
      pb.evaluate(q, F, J);
      e = F.norm();
      return finish(Status::converged);
    } else {
      return finish(Status::unsupported);
    }
  }
  if (o.method == Method::halley || o.method == Method::halley_thesis) {
    if constexpr (!HasSecondDerivatives<P>) return finish(Status::unsupported);
    if (o.method == Method::halley_thesis && M != N) return finish(Status::unsupported);
  }
  if (e < o.tolerance) return finish(Status::converged);

  detail::CycleWatch<N> watch;
  watch.window = std::clamp(o.cycle_window, 0, detail::CycleWatch<N>::kCapacity - 1);
  watch.push(q, 0.0, e);
  watch.best_error = e;

  double e_checkpoint = e;  // ||F|| at the last multiple of stall_window updates
  VecN delta = VecN::Zero();
  VecN qt = q;             // clamping: the (clamped) next iterate
  VecM Fn = VecM::Zero();  // lm_adaptive trial point
  MatMN Jn = MatMN::Zero();
  while (s.iterations < o.max_iter) {
    double lambda_used = 0.0;
    switch (o.method) {
      case Method::newton: {
        if (!rcond_ok(detail::newton_solve<M, N>(J, F, delta))) return finish(Status::singular);
        delta = -delta;
        break;
      }
      case Method::lm: {
        MatNN A = J.transpose() * J;
        A.diagonal().array() += o.lambda;
        if (!rcond_ok(detail::rcond1<N>(A))) return finish(Status::singular);
        const SmallLlt<N> llt(A);
        if (!llt.ok()) return finish(Status::singular);
        delta = -llt.solve(J.transpose() * F);
        lambda_used = o.lambda;
        break;
      }
      case Method::lm_adaptive: {
        const MatNN A = J.transpose() * J;
        const VecN g = J.transpose() * F;
        const double f2 = e * e;
        for (;;) {  // trial steps until one is accepted
          MatNN Am = A;
          Am.diagonal().array() += mu;
          if (!rcond_ok(detail::rcond1<N>(Am))) return finish(Status::singular);
          const SmallLlt<N> llt(Am);
          if (!llt.ok()) return finish(Status::singular);
          delta = -llt.solve(g);
          if (!(delta.norm() >= o.step_floor)) return finish(Status::stalled);
          double predicted = 0.0;  // 2 (L(0) - L(d)), L(d) = |F + J d|^2 / 2, for the step d taken
          if (clamping) {
            if constexpr (HasJointLimits<P>) {
              qt = q + delta;
              pb.project(qt);
              const VecN d = qt - q;
              predicted = -2.0 * g.dot(d) - d.dot(A * d);
              pb.evaluate(qt, Fn, Jn);
            }
          } else {
            pb.evaluate(q + delta, Fn, Jn);
            predicted = delta.dot(mu * delta - g);  // > 0 by the damped normal equations
          }
          const double en = Fn.norm();
          // a clamped step can predict an increase (predicted <= 0): rejected like a failed trial, so
          // that a larger mu turns it towards the projected gradient
          const double rho = std::isfinite(en) && predicted > 0.0 ? (f2 - en * en) / predicted : -1.0;
          if (rho > 0.0) {
            lambda_used = mu;
            const double t = 2.0 * rho - 1.0;
            mu *= std::max(1.0 / 3.0, 1.0 - t * t * t);
            nu = 2.0;
            break;
          }
          ++s.rejected;
          mu *= nu;
          nu *= 2.0;
          if (!(mu < 1e300)) return finish(Status::stalled);
        }
        break;
      }
      case Method::halley_thesis: {
        if constexpr (HasSecondDerivatives<P> && M == N) {
          const SecondDerivatives<M, N> D = pb.second_derivatives(q);
          MatNN Ht;  // H^T, H = dJ/dq1: H(i, j) = d2F_i/dq_j dq_1
          for (int i = 0; i < M; ++i) Ht.col(i) = D[i].col(0);
          if (!rcond_ok(detail::rcond1<N>(J))) return finish(Status::singular);
          const SmallLu<N> lu(J);
          const MatNN B = MatNN::Identity() - 0.5 * lu.solve(Ht);  // I - L/2, L = J^-1 H^T
          if (!rcond_ok(detail::rcond1<N>(B))) return finish(Status::singular);
          const SmallLu<N> luB(B);
          delta = -luB.solve(lu.solve(F));
        }
        break;
      }
      case Method::halley: {
        if constexpr (HasSecondDerivatives<P>) {
          VecN a;
          if (!rcond_ok(detail::newton_solve<M, N>(J, F, a))) return finish(Status::singular);
          a = -a;  // the Newton step
          const SecondDerivatives<M, N> D = pb.second_derivatives(q);
          MatMN K = J;  // J + T[a] / 2, T[a]_ij = sum_k d2F_i/dq_j dq_k a_k
          for (int i = 0; i < M; ++i) K.row(i) += 0.5 * (D[i] * a).transpose();
          if (!rcond_ok(detail::newton_solve<M, N>(K, F, delta))) return finish(Status::singular);
          delta = -delta;
        }
        break;
      }
      case Method::analytic:
        break;  // handled above
    }

    double step = 0.0;
    if (clamping) {
      if constexpr (HasJointLimits<P>) {
        if (o.method != Method::lm_adaptive) {  // lm_adaptive clamped its trial point already
          qt = q + delta;
          pb.project(qt);
        }
        step = (qt - q).norm();
        q = qt;
      }
    } else {
      step = delta.norm();
      q += delta;
    }
    if (o.method == Method::lm_adaptive) {
      F = Fn;
      J = Jn;
    } else {
      pb.evaluate(q, F, J);
    }
    e = F.norm();
    ++s.iterations;
    if (keep) s.history.push(q, F, e, step, lambda_used);

    if (!detail::all_finite<N, M>(q, F) || !(q.norm() <= o.divergence_bound)) return finish(Status::diverged);
    if (e < o.tolerance) return finish(Status::converged);
    if (!(step >= o.step_floor)) return finish(Status::stalled);
    if (o.stall_window > 0 && s.iterations % o.stall_window == 0) {
      if (!(e <= 0.5 * e_checkpoint)) return finish(Status::stalled);
      e_checkpoint = e;
    }
    watch.push(q, step, e);
    if (watch.window > 0 && watch.returned(pb.revolute, o.cycle_tolerance)) return finish(Status::cycle);
  }
  finish(Status::max_iter);
}

}  // namespace detail

template <Problem P>
void solve(const P& pb, const Vec<P::unknowns>& q0, const Options& o, Summary<P::unknowns, P::residuals>& s) {
  s.restarts_used = 0;
  detail::solve_attempt(pb, q0, o, s, false);
  auto done = [&] {
    return s.status == Status::converged || s.status == Status::unsupported || s.status == Status::no_solution;
  };
  if (o.restarts <= 0 || o.method == Method::analytic || done()) return;
  std::mt19937_64 rng(o.restart_seed);
  int iterations = s.iterations, rejected = s.rejected;
  double min_rcond = s.min_rcond;
  for (int r = 1; r <= o.restarts && !done(); ++r) {
    detail::solve_attempt(pb, detail::restart_start(pb, q0, rng), o, s, true);
    iterations += s.iterations, rejected += s.rejected;
    min_rcond = std::min(min_rcond, s.min_rcond);
    s.restarts_used = r;
  }
  s.iterations = iterations, s.rejected = rejected, s.min_rcond = min_rcond;
}

template <int N, int M>
std::string Summary<N, M>::brief() const {
  char buf[256];
  std::string out;
  std::snprintf(buf, sizeof buf, "%s: %s after %d iteration%s", std::string(to_string(method)).c_str(),
                std::string(to_string(status)).c_str(), iterations, iterations == 1 ? "" : "s");
  out += buf;
  if (rejected > 0) out += " (" + std::to_string(rejected) + " rejected)";
  std::snprintf(buf, sizeof buf, ", |F| = %.3e, solution %d, min rcond %.2e, q = (", error, solution, min_rcond);
  out += buf;
  for (int j = 0; j < N; ++j) {
    std::snprintf(buf, sizeof buf, "%s%.10g", j ? ", " : "", q[j]);
    out += buf;
  }
  return out + ")";
}

template <int N, int M>
std::string Summary<N, M>::report() const {
  std::string out = brief() + "\n";
  char buf[128];
  out += "    k";
  for (int j = 0; j < N; ++j) {
    std::snprintf(buf, sizeof buf, "               q%d", j + 1);
    out += buf;
  }
  out += "          |F|       |step|       lambda\n";
  for (std::size_t k = 0; k < history.size(); ++k) {
    std::snprintf(buf, sizeof buf, "%5zu", k);
    out += buf;
    for (int j = 0; j < N; ++j) {
      std::snprintf(buf, sizeof buf, " %16.9f", history.q[k][j]);
      out += buf;
    }
    std::snprintf(buf, sizeof buf, " %12.5e %12.5e %12.5e\n", history.error[k], history.step[k], history.lambda[k]);
    out += buf;
  }
  return out;
}

template <int N, int M>
std::ostream& operator<<(std::ostream& os, const Summary<N, M>& s) {
  return os << s.brief();
}

}  // namespace ks::ik
