#pragma once
// What an inverse-kinematics problem is, for the solvers of ik/solve.hpp (seed 001).
//
// A problem is a small struct describing a residual F: R^N -> R^M (F(q) = 0 at a solution) and its
// derivatives. The solvers only see this description, so adding a robot means writing one such
// struct; nothing in the solvers changes. Required members:
//
//   static constexpr int unknowns;                          // N: joint variables q
//   static constexpr int residuals;                         // M: task equations F(q)
//   std::array<bool, N> revolute;                           // angles: matched and compared mod 2 pi
//                                                           // (static constexpr, or a data member
//                                                           // when it depends on the robot)
//   void evaluate(const Vec<N>& q, Vec<M>& F, Mat<M, N>& J) const;   // F(q) and J = dF/dq
//
// Optional members (a method that needs a missing one returns Status::unsupported):
//
//   SecondDerivatives<M, N> second_derivatives(const Vec<N>& q) const;
//       // d2F_i/dq_j dq_k as one symmetric N x N matrix per residual i (halley, halley_thesis)
//   SolutionSet<N> known_solutions() const;
//       // the exact solutions, when they are isolated and known in closed form (analytic; and the
//       // Summary's solution index); mark a continuum with SolutionSet::continuum = true.
//   void project(Vec<N>& q) const;
//       // clamp q onto the joint limits [lower, upper] in place (Options::joint_limits = clamp)
//   bool admit(Vec<N>& q) const;
//       // true when q lies within the joint limits, after moving each revolute joint by a multiple
//       // of 2 pi into them where one exists (Options::joint_limits = reject)
//   Vec<N> lower, upper;
//       // the limits themselves (+-infinity: none); with project and admit they also say which
//       // joints the solve enforces (angle wrapping) and where restarts draw (ik/solve.hpp)
//
// Units are the problem's own (the SCARA problem works in mm and rad, the planar arm in m and rad);
// the solver tolerances are in the same units.
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <concepts>

#include "common/angles.hpp"

namespace ks::ik {

template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int R, int C>
using Mat = Eigen::Matrix<double, R, C>;

/// Second-derivative tensor: element [i](j, k) = d2 F_i / dq_j dq_k (each matrix symmetric).
template <int M, int N>
using SecondDerivatives = std::array<Mat<N, N>, M>;

/// Capacity of a SolutionSet (enough for any 6R arm: at most 16 isolated solutions).
inline constexpr int kMaxKnownSolutions = 16;

/// The known exact solutions of a problem, fixed capacity (no allocation).
template <int N>
struct SolutionSet {
  std::array<Vec<N>, kMaxKnownSolutions> q{};  ///< the first `count` entries are valid
  int count = 0;                               ///< isolated solutions held (0: none, or a continuum)
  bool continuum = false;                      ///< the solutions form a manifold (e.g. position-only 3R)

  void add(const Vec<N>& s) {
    if (count < kMaxKnownSolutions) q[count++] = s;
  }
};

using ks::wrap_angle;  // common/angles.hpp: x wrapped to (-pi, pi]

/// a - b, with the revolute components wrapped to (-pi, pi] (distance on the joint torus).
template <int N>
inline Vec<N> joint_difference(const Vec<N>& a, const Vec<N>& b, const std::array<bool, N>& revolute) {
  Vec<N> d = a - b;
  for (int j = 0; j < N; ++j)
    if (revolute[j]) d[j] = wrap_angle(d[j]);
  return d;
}

/// Index of the known solution nearest to q (max-norm of joint_difference), -1 when none is
/// within tolerance.
template <int N>
inline int match_solution(const SolutionSet<N>& set, const Vec<N>& q, const std::array<bool, N>& revolute,
                          double tolerance) {
  int best = -1;
  double best_d = tolerance;
  for (int i = 0; i < set.count; ++i) {
    const double d = joint_difference<N>(q, set.q[i], revolute).cwiseAbs().maxCoeff();
    if (d <= best_d) best = i, best_d = d;
  }
  return best;
}

/// The required part of a problem description (see the header comment).
template <class P>
concept Problem = requires(const P& p, const Vec<P::unknowns>& q, Vec<P::residuals>& F,
                           Mat<P::residuals, P::unknowns>& J) {
  { P::unknowns } -> std::convertible_to<int>;
  { P::residuals } -> std::convertible_to<int>;
  { p.revolute } -> std::convertible_to<std::array<bool, P::unknowns>>;
  p.evaluate(q, F, J);
};

/// The problem provides d2F/dq2 (needed by halley and halley_thesis).
template <class P>
concept HasSecondDerivatives = Problem<P> && requires(const P& p, const Vec<P::unknowns>& q) {
  { p.second_derivatives(q) } -> std::convertible_to<SecondDerivatives<P::residuals, P::unknowns>>;
};

/// The problem provides its exact solutions (needed by analytic and by solution matching).
template <class P>
concept HasKnownSolutions = Problem<P> && requires(const P& p) {
  { p.known_solutions() } -> std::convertible_to<SolutionSet<P::unknowns>>;
};

/// The problem has joint limits: it can clamp an iterate onto them (JointLimits::clamp) and test a
/// solution against them (JointLimits::reject).
template <class P>
concept HasJointLimits = Problem<P> && requires(const P& p, Vec<P::unknowns>& q) {
  p.project(q);
  { p.admit(q) } -> std::convertible_to<bool>;
};

/// The problem has joint limits and exposes them as `lower` and `upper` (one entry per joint,
/// +-infinity where a joint has none).
template <class P>
concept HasLimitBounds = HasJointLimits<P> && requires(const P& p) {
  { p.lower[0] } -> std::convertible_to<double>;
  { p.upper[0] } -> std::convertible_to<double>;
};

}  // namespace ks::ik
