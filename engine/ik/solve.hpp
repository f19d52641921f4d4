#pragma once
// Numerical inverse kinematics (seed 001): Newton, Levenberg-Marquardt (fixed and
// adaptive damping), Halley (the seed's form and the true one) and the closed form, on any
// problem description of ik/problem.hpp.
//
//   Summary<N, M> solve(const P& problem, const Vec<N>& q0, const Options& options);
//
// Input: the problem, a start q0 (units of the problem's unknowns), options. Output: a Summary
// with the final q, status, iterations, final error, the known solution reached and the whole
// iteration history. A solve never throws on bad numbers: trouble is a Status.
//
// Stop rule (the seed's): after update k, stop as converged when ||F(q_k)|| < tolerance;
// iterations = number of updates (0 when the start already solves the problem).
//
// Converged angles: every revolute joint whose limits the solve does not enforce (a problem without
// limits, a joint without finite limits, or Options::joint_limits = none) is returned wrapped to
// (-pi, pi]; joints whose limits are enforced keep their value (clamp: within them; reject: moved by
// a multiple of 2 pi into them). F and the error are those of the iterate as computed (before the
// wrap), the history holds the iterates as computed.
//
// Restarts (Options::restarts = R > 0): when an attempt ends in any status but converged,
// unsupported or no_solution, the solve starts again from a configuration drawn uniformly within
// the joint limits (revolute joints without finite limits: (-pi, pi); prismatic ones without them:
// q0's value), at most R times. The draws come from std::mt19937_64 seeded with
// Options::restart_seed (raw 64-bit draws mapped to (0, 1) as ((x >> 11) + 0.5) 2^-53, one per joint
// in joint order), so a solve is a pure function of its inputs. The Summary then reports the last
// attempt (status, q, F, error, solution), iterations and rejected summed over all attempts,
// min_rcond over all attempts, restarts_used = attempts - 1, and a history of every attempt one
// after the other (each attempt's first row is its start, with step 0). R = 0: one attempt.
#include <cstdint>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "common/domain.hpp"
#include "ik/planar_problems.hpp"
#include "ik/problem.hpp"
#include "ik/scara.hpp"

namespace ks::ik {

/// Iteration q <- q + delta. F = residual, J = dF/dq at q; solves are LU/Cholesky, never inverses.
enum class Method {
  newton,         ///< delta = -J^-1 F; minimum-norm -J^T (J J^T)^-1 F when M < N, Gauss-Newton when M > N
  lm,             ///< delta = -(J^T J + lambda I)^-1 J^T F, fixed lambda (the seed's Levenberg-Marquardt)
  lm_adaptive,    ///< the same with lambda adapted per step (Madsen-Nielsen: gain ratio rho,
                  ///< accept if rho > 0 and lambda *= max(1/3, 1 - (2 rho - 1)^3), nu = 2;
                  ///< else reject, lambda *= nu, nu *= 2)
  halley_thesis,  ///< the seed's Eq. 38: delta = -(I - L/2)^-1 J^-1 F, L = J^-1 H^T, H = dJ/dq1
                  ///< (square problems only; converges linearly)
  halley,         ///< true Halley: a = -J^-1 F, T[a]_ij = sum_k d2F_i/dq_j dq_k a_k,
                  ///< (J + T[a]/2) delta = -F (cubic; minimum-norm solves when M < N)
  analytic,       ///< the problem's closed-form solution nearest to q0 (mod 2 pi); 0 iterations
};

enum class Status {
  converged,    ///< ||F|| < tolerance
  stalled,      ///< ||delta|| < step_floor before convergence (a non-root minimum of ||F||, or roundoff),
                ///< or ||F|| not halved over Options::stall_window updates
  singular,     ///< the matrix to solve had reciprocal condition < rcond_min (see Options)
  max_iter,     ///< max_iter updates without convergence
  cycle,        ///< an iterate came back to one of the last cycle_window iterates (see Options)
  diverged,     ///< a non-finite q or F, or ||q|| > divergence_bound
  unsupported,  ///< the method does not apply to the problem (halley_thesis with M != N, analytic
                ///< without a closed form, Halley without second derivatives)
  no_solution,  ///< analytic: the closed form says the target is out of reach
  out_of_limits,  ///< ||F|| < tolerance at a q outside the joint limits (JointLimits::reject)
};

/// What a solve does with the problem's joint limits (problems without limits ignore this).
enum class JointLimits {
  none,    ///< iterate and report freely
  clamp,   ///< clamp every iterate onto [lower, upper] after the step (lm_adaptive: every trial point)
  reject,  ///< iterate freely; a converged q outside the limits (revolute joints: no 2 pi shift of
           ///< it inside) ends as Status::out_of_limits
};

std::string_view to_string(Method m);
std::string_view to_string(Status s);
std::string_view to_string(JointLimits l);
/// Parse a name; false when unknown.
bool parse(std::string_view name, Method& out);
bool parse(std::string_view name, Status& out);
bool parse(std::string_view name, JointLimits& out);

/// Options of one solve. Defaults are the seed's where it has one.
struct Options {
  Method method = Method::newton;
  double tolerance = 1e-6;        ///< stop when ||F|| < tolerance (units of F; the seed's 1e-6 mm)
  int max_iter = 1000;            ///< at most this many updates (lm_adaptive: rejected trials do not count)
  double step_floor = 1e-14;      ///< stalled when ||delta|| falls below this (units of q)
  double lambda = 0.1;            ///< lm: the fixed damping (the seed runs 0.1 and 10) [units of J^2]
  double lambda_scale = 1e-3;     ///< lm_adaptive: initial lambda = lambda_scale * max diag(J^T J)
  /// singular when the reciprocal condition number (1-norm; exact for up to 3 unknowns, the LU
  /// estimate beyond) of the matrix solved at a step is below this: J (newton, halley,
  /// halley_thesis), I - L/2, J + T[a]/2, J^T J + lambda I. For minimum-norm (M < N) and
  /// least-squares (M > N) steps the Gram matrix is solved and sqrt of its rcond is compared.
  /// Note sin(-pi) = -1.2e-16, not 0: a singular configuration is near-singular numerically.
  double rcond_min = 1e-12;
  double divergence_bound = 1e8;  ///< diverged when ||q|| exceeds this
  /// cycle when q_k is within cycle_tolerance * max(1, ||q_k||) (revolute joints mod 2 pi) of one of
  /// q_{k-2} ... q_{k-cycle_window} (at most 16) while the path between them is 1000 times longer
  /// (so a slowly converging sequence is not a cycle); only iterates whose ||F|| agrees to 0.1 % are
  /// compared, and none while ||F|| keeps halving its best value. cycle_window = 0: no check.
  int cycle_window = 8;
  double cycle_tolerance = 1e-8;
  /// stalled when, after every stall_window-th update of an attempt, ||F|| is above half of its value
  /// stall_window updates earlier: an attempt stuck near a non-root minimum of ||F|| ends early (and,
  /// with restarts, gives way to the next attempt). 0: no check (the seed's behaviour: such an attempt
  /// runs to max_iter).
  int stall_window = 0;
  /// max |q - q*| (max-norm, mod 2 pi) to name the known solution q* reached. Generous on purpose: a
  /// converged q is only within about tolerance / sigma_min(J) of q*, while distinct solutions are
  /// far apart except near a singularity.
  double match_tolerance = 1e-3;
  bool keep_history = true;       ///< record the history (off: no allocation at all in a solve)
  JointLimits joint_limits = JointLimits::none;  ///< use of the problem's joint limits, if it has any
  int restarts = 0;               ///< at most this many random restarts after a failed attempt (header comment)
  std::uint64_t restart_seed = 0; ///< seed of the restarts' draws (header comment)

  /// The rules on the fields (checked by IsValid; the study schema reports them at the key).
  static constexpr Domain tolerance_rule = Domain::positive();
  static constexpr Domain max_iter_rule = Domain::within(1, 1e9);  ///< an int, with room to spare
  static constexpr Domain lambda_rule = Domain::nonnegative();
  static constexpr Domain step_floor_rule = Domain::nonnegative();
  static constexpr Domain lambda_scale_rule = Domain::positive();
  static constexpr Domain rcond_min_rule = Domain::nonnegative();
  static constexpr Domain divergence_bound_rule = Domain::positive();
  static constexpr Domain cycle_tolerance_rule = Domain::nonnegative();
  static constexpr Domain match_tolerance_rule = Domain::positive();
  static constexpr Domain restarts_rule = Domain::within(0, 1e6);
  static constexpr Domain stall_window_rule = Domain::within(0, 1e6);
  static constexpr int max_cycle_window = 16;

  /// True when every field is finite and within its rule (cycle_window within [0, 16], joint_limits
  /// one of the named values); otherwise
  /// false, with `why` (when given) naming the field and the rule, e.g. "tolerance = 0; expected tolerance > 0".
  bool IsValid(std::string* why = nullptr) const;
};

/// Iteration history: row k is iterate k (k = 0 the start). lm_adaptive records accepted iterates.
template <int N, int M>
struct History {
  std::vector<Vec<N>> q;         ///< iterate q_k
  std::vector<Vec<M>> F;         ///< residual F(q_k)
  std::vector<double> error;     ///< ||F(q_k)||
  std::vector<double> step;      ///< ||q_k - q_{k-1}|| (0 at k = 0)
  std::vector<double> lambda;    ///< damping used for the step to q_k (lm, lm_adaptive; 0 otherwise;
                                 ///< lm_adaptive row 0: the initial damping)
  std::size_t size() const { return q.size(); }
  void clear() {
    q.clear(), F.clear(), error.clear(), step.clear(), lambda.clear();
  }
  void reserve(std::size_t n) {
    q.reserve(n), F.reserve(n), error.reserve(n), step.reserve(n), lambda.reserve(n);
  }
  void push(const Vec<N>& qk, const Vec<M>& Fk, double e, double s, double l) {
    q.push_back(qk), F.push_back(Fk), error.push_back(e), step.push_back(s), lambda.push_back(l);
  }
};

/// Outcome of one solve.
template <int N, int M>
struct Summary {
  Method method = Method::newton;
  Status status = Status::max_iter;
  Vec<N> q = Vec<N>::Zero();      ///< final iterate (converged: unenforced revolute joints wrapped, see above)
  Vec<M> F = Vec<M>::Zero();      ///< F(q)
  double error = 0.0;             ///< ||F(q)||
  int iterations = 0;             ///< updates made (summed over all attempts)
  int rejected = 0;               ///< lm_adaptive: rejected trial steps (summed over all attempts)
  int restarts_used = 0;          ///< random restarts made (attempts - 1)
  int solution = -1;              ///< index into problem.known_solutions() matched by q, -1 if none
  double min_rcond = 1.0;         ///< smallest reciprocal condition of a matrix solved (inf: none was)
  History<N, M> history;

  bool converged() const { return status == Status::converged; }
  /// One line: method, status, iterations, error, solution, q.
  std::string brief() const;
  /// brief() then the history table (k, q, ||F||, ||step||, lambda).
  std::string report() const;
};

template <int N, int M>
std::ostream& operator<<(std::ostream& os, const Summary<N, M>& s);

/// Solve problem from q0. summary's history capacity is reused across calls (no allocation once
/// it is large enough). See the header comment for the stop rule.
template <Problem P>
void solve(const P& problem, const Vec<P::unknowns>& q0, const Options& options,
           Summary<P::unknowns, P::residuals>& summary);

/// Convenience form returning a fresh Summary.
template <Problem P>
Summary<P::unknowns, P::residuals> solve(const P& problem, const Vec<P::unknowns>& q0, const Options& options) {
  Summary<P::unknowns, P::residuals> s;
  solve(problem, q0, options, s);
  return s;
}

// The engine's problems are compiled once in ik/solve.cpp; a new problem includes ik/solve_impl.hpp.
extern template void solve(const ScaraPosition&, const Vec<3>&, const Options&, Summary<3, 3>&);
extern template void solve(const PlanarPose&, const Vec<3>&, const Options&, Summary<3, 3>&);
extern template void solve(const PlanarPosition&, const Vec<3>&, const Options&, Summary<3, 2>&);
extern template struct Summary<3, 3>;
extern template struct Summary<3, 2>;
extern template std::ostream& operator<<(std::ostream&, const Summary<3, 3>&);
extern template std::ostream& operator<<(std::ostream&, const Summary<3, 2>&);

}  // namespace ks::ik
