// Numerical IK of seed 001: the seed's Tables 3-7, the true Halley step's cubic rate,
// statuses (singular, max_iter, cycle, diverged, stalled, unsupported), history, names.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>

#include "ik/solve_impl.hpp"  // the test problems below instantiate solve() themselves

using namespace ks;
using namespace ks::ik;

namespace {
constexpr double kPi = std::numbers::pi;

const Vec<3> kSeedStart{kPi / 3.0, kPi / 4.0, 50.0};  // NOTES 001: Table 2's pi/2 is a misprint
// The two exact solutions printed by the seed (NOTES 001), theta only, mod 2 pi.
const Vec2 kSeedSolutionA{-0.216236265, -2.675505056};  // reached by NR, LM 0.1, Halley
const Vec2 kSeedSolutionB{-1.808157758, 2.675505056};   // reached by LM 10

Options seed_options(Method m, double lambda = 0.1) {
  Options o;
  o.method = m;
  o.tolerance = 1e-6;
  o.lambda = lambda;
  return o;
}

// max |theta_i - expected_i| mod 2 pi over the two angles [rad].
double theta_distance(const Vec<3>& q, const Vec2& expected) {
  return std::max(std::abs(wrap_angle(q[0] - expected[0])), std::abs(wrap_angle(q[1] - expected[1])));
}

// Index of a seed solution in the problem's known set.
int known_index(const ScaraPosition& p, const Vec2& theta) {
  const SolutionSet<3> set = p.known_solutions();
  for (int i = 0; i < set.count; ++i)
    if (theta_distance(set.q[i], theta) < 1e-8) return i;
  return -1;
}

// A row of the seed's tables: FK [mm] and theta [rad] of iterate k as printed, compared at the
// printed precision (5 decimals for FK, truncated or rounded; 4 for theta). NaN: not compared, where
// the printed value contradicts the rest of its own row (see the misprint notes at each table).
constexpr double kSkip = std::numeric_limits<double>::quiet_NaN();
struct PrintedIterate {
  int k;
  double x, y, z, t1, t2;
  double fk_tol = 1e-5, theta_tol = 1e-4;
};

void expect_iterate(const Summary<3, 3>& s, const ScaraPosition& p, const PrintedIterate& r) {
  ASSERT_LT(static_cast<std::size_t>(r.k), s.history.size());
  const Vec<3>& q = s.history.q[r.k];
  const Vec<3> fk = p.forward(q);
  const double expected[5] = {r.x, r.y, r.z, r.t1, r.t2};
  const double got[5] = {fk[0], fk[1], fk[2], q[0], q[1]};  // raw theta: the seed never wraps in the loop
  const char* names[5] = {"x", "y", "z", "theta1", "theta2"};
  for (int i = 0; i < 5; ++i) {
    if (std::isnan(expected[i])) continue;
    EXPECT_NEAR(got[i], expected[i], i < 3 ? r.fk_tol : r.theta_tol) << "iterate " << r.k << ", " << names[i];
  }
}
}  // namespace

// ------------------------------------------------------------ the seed's tables (thesis z mode)

TEST(IkSeed, KnownSolutionsAreTheSeeds) {
  const ScaraPosition p;
  const SolutionSet<3> set = p.known_solutions();
  ASSERT_EQ(set.count, 2);
  EXPECT_GE(known_index(p, kSeedSolutionA), 0);
  EXPECT_GE(known_index(p, kSeedSolutionB), 0);
  for (int i = 0; i < set.count; ++i) {
    EXPECT_NEAR(set.q[i][2], 10.0, 1e-12);  // thesis z mode: q3 = z
    EXPECT_LT((p.forward(set.q[i]) - p.target).norm(), 1e-10);
  }
}

TEST(IkSeed, NewtonTable3) {
  const ScaraPosition p;
  const auto s = solve(p, kSeedStart, seed_options(Method::newton));
  EXPECT_EQ(s.status, Status::converged) << s.report();
  EXPECT_EQ(s.iterations, 8) << s.report();
  // First iterate, to the digits NOTES 001 gives.
  expect_iterate(s, p, {1, 45.51929942, -336.11052531, 10.0, -1.65137913, 6.78708794, 1e-6, 1e-6});
  // Table 3's later rows, at their printed precision.
  expect_iterate(s, p, {2, -231.73447, 261.02091, 10.0, -4.0503, 12.7156});
  expect_iterate(s, p, {3, 53.243325, -24.48239, 10.0, -18.8139, 47.3006});
  expect_iterate(s, p, {4, 35.19584, -77.70044, 10.0, -19.2369, 47.5256});
  expect_iterate(s, p, {8, 50.0, -80.0, 10.0, -19.0658, 47.5900});
  EXPECT_LT(theta_distance(s.q, kSeedSolutionA), 1e-6);
  EXPECT_EQ(s.solution, known_index(p, kSeedSolutionA));
  EXPECT_LT(s.error, 1e-6);
  EXPECT_LT(s.error, 1e-10);  // NOTES: final error ~ 5e-13 (quadratic convergence)
}

TEST(IkSeed, LmLambda01Table4) {
  const ScaraPosition p;
  const auto s = solve(p, kSeedStart, seed_options(Method::lm, 0.1));
  EXPECT_EQ(s.status, Status::converged) << s.report();
  EXPECT_EQ(s.iterations, 8) << s.report();
  // Misprint: Table 4 prints theta = (-1.6414, 6.7769) and (-4.0379, 12.7182) at iterates 1 and 2,
  // but those angles put the tip at (47.48, -336.27) and (-235.22, 257.84), not at the FK printed
  // on the same rows; the printed FK (8 digits) and the later rows are reproduced.
  expect_iterate(s, p, {1, 45.52070, -336.11749, 13.63636, kSkip, kSkip});
  expect_iterate(s, p, {2, -231.71838, 261.00893, 10.33057, kSkip, kSkip});
  expect_iterate(s, p, {3, 46.16355, 39.17841, 10.03005, -18.6533, 46.9264});
  expect_iterate(s, p, {4, 80.63309, -73.12574, 10.00273, -18.7550, 47.6896});
  expect_iterate(s, p, {8, 50.0, -80.0, 10.0, -19.0658, 47.5899});
  EXPECT_LT(theta_distance(s.q, kSeedSolutionA), 1e-6);
  EXPECT_EQ(s.solution, known_index(p, kSeedSolutionA));
  for (std::size_t k = 1; k < s.history.size(); ++k) EXPECT_EQ(s.history.lambda[k], 0.1);
}

TEST(IkSeed, LmLambda10Table5) {
  const ScaraPosition p;
  const auto s = solve(p, kSeedStart, seed_options(Method::lm, 10.0));
  EXPECT_EQ(s.status, Status::converged) << s.brief();
  EXPECT_EQ(s.iterations, 184) << s.brief();
  // Table 5 iterate 1 prints y = -336.79444 where the iterate whose x, z and theta match the row
  // has -336.79446 (a last-digit misprint): y is compared at 5e-5 mm only.
  expect_iterate(s, p, {1, 45.65733, kSkip, 46.36363, -1.6442, 6.7705});
  expect_iterate(s, p, {1, kSkip, -336.79444, kSkip, kSkip, kSkip, 5e-5});
  expect_iterate(s, p, {2, -229.41017, 259.05195, 43.05785, -4.1180, 12.8710});
  expect_iterate(s, p, {3, 160.55386, 120.09280, 40.05259, -11.1563, 29.4643});
  expect_iterate(s, p, {184, 50.0, -80.0, 10.0, -1.8081, -9.8908});
  EXPECT_LT(theta_distance(s.q, kSeedSolutionB), 1e-6);
  EXPECT_EQ(s.solution, known_index(p, kSeedSolutionB));
  // NOTES' explanation: the decoupled z residual shrinks by lambda / (1 + lambda) per update.
  for (std::size_t k = 1; k < s.history.size(); ++k)
    EXPECT_NEAR(s.history.F[k][2], s.history.F[k - 1][2] * 10.0 / 11.0, 1e-12 * std::abs(s.history.F[k - 1][2]) + 1e-14);
  EXPECT_EQ(s.iterations, static_cast<int>(std::ceil(std::log(1e-6 / 40.0) / std::log(10.0 / 11.0))));
}

TEST(IkSeed, HalleyThesisTable6) {
  const ScaraPosition p;
  const auto s = solve(p, kSeedStart, seed_options(Method::halley_thesis));
  EXPECT_EQ(s.status, Status::converged) << s.report();
  EXPECT_EQ(s.iterations, 27) << s.report();
  // Table 6 prints some FK with a shifted decimal comma (376,32722 for 37.632722 at iterate 1;
  // 74,05977 for 7.405977 and -61,23766 for -6.123766 at iterates 2-3) and theta2 = -8.0283 at
  // iterate 2, where its own x = 228.56857 needs -8.0248: those entries are not compared.
  expect_iterate(s, p, {1, kSkip, 168.29472, 10.0, 0.5343, -10.4179});
  expect_iterate(s, p, {2, 228.56857, kSkip, 10.0, 0.7352, kSkip});
  expect_iterate(s, p, {3, 64.42906, kSkip, 10.0, 0.4828, kSkip});
  expect_iterate(s, p, {27, 50.0, -80.0, 10.0, -0.2163, -8.9586});
  EXPECT_LT(theta_distance(s.q, kSeedSolutionA), 1e-6);
  EXPECT_EQ(s.solution, known_index(p, kSeedSolutionA));
}

TEST(IkSeed, PhysicalZModeConverges) {
  ScaraPosition p;
  p.z_mode = ScaraZ::physical;
  const SolutionSet<3> set = p.known_solutions();
  ASSERT_EQ(set.count, 2);
  EXPECT_NEAR(set.q[0][2], 100.0 - 40.0 - 10.0, 1e-12);  // d = d1 - d3 - z
  for (const Method m : {Method::newton, Method::lm, Method::lm_adaptive, Method::halley, Method::halley_thesis}) {
    const auto s = solve(p, kSeedStart, seed_options(m));
    EXPECT_EQ(s.status, Status::converged) << s.brief();
    EXPECT_GE(s.solution, 0) << s.brief();
    EXPECT_NEAR(p.forward(s.q)[2], 10.0, 1e-6);
    EXPECT_NEAR(s.q[2], 50.0, 1e-6);
  }
}

TEST(IkSeed, AnalyticReturnsTheNearestClosedForm) {
  const ScaraPosition p;
  for (const Vec2& theta : {kSeedSolutionA, kSeedSolutionB}) {
    const Vec<3> near(theta[0] + 0.3 + 2.0 * kPi, theta[1] - 0.2, 50.0);  // near this one, mod 2 pi
    const auto s = solve(p, near, seed_options(Method::analytic));
    EXPECT_EQ(s.status, Status::converged);
    EXPECT_EQ(s.iterations, 0);
    EXPECT_LT(s.error, 1e-10);
    EXPECT_EQ(s.solution, known_index(p, theta));
    EXPECT_LT(theta_distance(s.q, theta), 1e-8);
    EXPECT_NEAR(s.q[2], 10.0, 1e-12);
  }
}

// ------------------------------------------------------------------------ the true Halley step

TEST(IkHalley, FarFewerIterationsThanTheThesisForm) {
  const ScaraPosition p;
  const auto h = solve(p, kSeedStart, seed_options(Method::halley));
  const auto t = solve(p, kSeedStart, seed_options(Method::halley_thesis));
  ASSERT_EQ(h.status, Status::converged) << h.report();
  ASSERT_EQ(t.status, Status::converged);
  EXPECT_LE(3 * h.iterations, t.iterations) << h.report();
  EXPECT_LE(h.iterations, 8) << h.report();  // no worse than Newton from the seed's start
  EXPECT_GE(h.solution, 0);
}

// Convergence order from the distance to the exact (closed-form) root: with e_k = |q_k - q*|,
// p_k = log(e_{k+1} / e_k) / log(e_k / e_{k-1}) -> 3 for Halley, 2 for Newton.
namespace {
std::vector<double> order_estimates(const Summary<3, 3>& s, const SolutionSet<3>& set, double floor) {
  std::vector<double> e;
  for (const auto& q : s.history.q) e.push_back(joint_difference<3>(q, set.q[s.solution], ScaraPosition::revolute).norm());
  std::vector<double> p;
  for (std::size_t k = 1; k + 1 < e.size(); ++k)
    if (e[k - 1] < 0.5 && e[k + 1] > floor) p.push_back(std::log(e[k + 1] / e[k]) / std::log(e[k] / e[k - 1]));
  return p;
}
}  // namespace

TEST(IkHalley, CubicRateOnTheLastIterates) {
  const ScaraPosition p;
  const SolutionSet<3> set = p.known_solutions();
  Options o = seed_options(Method::halley);
  o.tolerance = 1e-11;  // run into the asymptotic regime
  int estimated = 0;
  for (int i = 0; i < set.count; ++i)
    for (const Vec<3>& dq : {Vec<3>(0.6, -0.7, 0.0), Vec<3>(1.0, -1.0, 0.0), Vec<3>(-0.5, 0.8, 20.0)}) {
      const Vec<3> q0 = set.q[i] + dq;
      o.method = Method::halley;
      const auto h = solve(p, q0, o);
      ASSERT_EQ(h.status, Status::converged) << h.report();
      ASSERT_GE(h.solution, 0);
      const auto orders = order_estimates(h, set, 1e-13);
      if (!orders.empty()) {
        ++estimated;
        EXPECT_NEAR(orders.back(), 3.0, 0.4) << h.report();
      }
      // The residual form of the same statement: |F_{k+1}| <= C |F_k|^3 with a modest C [1/mm^2].
      for (std::size_t k = 0; k + 1 < h.history.size(); ++k)
        if (h.history.error[k] < 1.0) {
          EXPECT_LE(h.history.error[k + 1], 1.0 * std::pow(h.history.error[k], 3) + 1e-12) << h.report();
        }

      o.method = Method::newton;  // the same measure tells Newton's quadratic rate
      const auto n = solve(p, q0, o);
      if (n.status != Status::converged) continue;
      const auto newton_orders = order_estimates(n, set, 1e-13);
      if (!newton_orders.empty()) {
        EXPECT_NEAR(newton_orders.back(), 2.0, 0.4) << n.report();
      }
    }
  EXPECT_GE(estimated, 2);
}

// --------------------------------------------------------------------------------- statuses

TEST(IkStatus, SingularStartIsAStatusNotACrash) {
  const ScaraPosition p;
  for (const double t2 : {0.0, kPi, -kPi}) {  // det J = a1 a2 sin(theta2); sin(pi) = 1.2e-16
    const Vec<3> q0(0.3, t2, 50.0);
    for (const Method m : {Method::newton, Method::halley, Method::halley_thesis}) {
      const auto s = solve(p, q0, seed_options(m));
      EXPECT_EQ(s.status, Status::singular) << s.brief();
      EXPECT_EQ(s.iterations, 0);
      EXPECT_LT(s.min_rcond, 1e-12);
      EXPECT_EQ(s.q, q0);
      EXPECT_EQ(s.history.size(), 1u);
    }
    // Levenberg-Marquardt is not singular there (J^T J + lambda I is positive definite).
    for (const Method m : {Method::lm, Method::lm_adaptive}) {
      const auto s = solve(p, q0, seed_options(m));
      EXPECT_NE(s.status, Status::singular) << s.brief();
      EXPECT_EQ(s.status, Status::converged) << s.brief();
    }
  }
}

TEST(IkStatus, MaxIterStopsAtTheCap) {
  const ScaraPosition p;
  Options o = seed_options(Method::lm, 10.0);  // needs 184 updates
  o.max_iter = 100;
  const auto s = solve(p, kSeedStart, o);
  EXPECT_EQ(s.status, Status::max_iter);
  EXPECT_EQ(s.iterations, 100);
  EXPECT_EQ(s.history.size(), 101u);
  EXPECT_EQ(s.solution, -1);
  EXPECT_GT(s.error, 1e-6);
}

namespace {
// A one-line problem defined outside the engine (so the solvers cannot know it): f(x) = x^3 - 2x + 2,
// whose Newton iteration from 0 is the textbook attracting 2-cycle 0 -> 1 -> 0; the other two
// unknowns are linear. No second derivatives, no known solutions.
struct CubicCycle {
  static constexpr int unknowns = 3, residuals = 3;
  static constexpr std::array<bool, 3> revolute{false, false, false};
  void evaluate(const Vec<3>& q, Vec<3>& F, Mat<3, 3>& J) const {
    F << q[0] * q[0] * q[0] - 2.0 * q[0] + 2.0, q[1] - 1.0, 2.0 * q[2];
    J << 3.0 * q[0] * q[0] - 2.0, 0, 0, 0, 1, 0, 0, 0, 2;
  }
};
// atan has one root, but Newton from |x| > 1.39 overshoots further every step.
struct Arctan {
  static constexpr int unknowns = 3, residuals = 3;
  static constexpr std::array<bool, 3> revolute{false, false, false};
  void evaluate(const Vec<3>& q, Vec<3>& F, Mat<3, 3>& J) const {
    F << std::atan(q[0]), q[1], q[2];
    J << 1.0 / (1.0 + q[0] * q[0]), 0, 0, 0, 1, 0, 0, 0, 1;
  }
};
static_assert(Problem<CubicCycle> && !HasSecondDerivatives<CubicCycle> && !HasKnownSolutions<CubicCycle>);
static_assert(HasSecondDerivatives<ScaraPosition> && HasKnownSolutions<PlanarPose>);
}  // namespace

TEST(IkStatus, NewtonCycleIsDetected) {
  Options o;
  o.method = Method::newton;
  const auto s = solve(CubicCycle{}, Vec<3>(0.0, 5.0, 5.0), o);
  EXPECT_EQ(s.status, Status::cycle) << s.report();
  EXPECT_LE(s.iterations, 4);
  // And without the check the same solve runs to the cap: the cycle is real.
  o.cycle_window = 0;
  o.max_iter = 200;
  EXPECT_EQ(solve(CubicCycle{}, Vec<3>(0.0, 5.0, 5.0), o).status, Status::max_iter);
}

TEST(IkStatus, CyclesOfScaraNewtonAreRealCycles) {
  // Random starts on the seed's problem: every start flagged `cycle` must really fail to converge
  // when the check is off, and a converging start is never flagged.
  const ScaraPosition p;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(-kPi, kPi), d(-100.0, 100.0);
  Options o = seed_options(Method::newton);
  Options unchecked = o;
  unchecked.cycle_window = 0;
  int cycles = 0, converged = 0;
  for (int n = 0; n < 3000; ++n) {
    const Vec<3> q0(angle(rng), angle(rng), d(rng));
    const auto s = solve(p, q0, o);
    const auto u = solve(p, q0, unchecked);
    if (s.status == Status::cycle) {
      ++cycles;
      EXPECT_NE(u.status, Status::converged) << "start " << q0.transpose() << "\n" << u.report();
    } else {
      EXPECT_EQ(s.status, u.status);
      EXPECT_EQ(s.iterations, u.iterations);
    }
    converged += s.converged();
  }
  EXPECT_GT(converged, 2000);
  EXPECT_GT(cycles, 0);  // NOTES 001: some starts fall into attracting cycles
  std::cout << "newton on the seed's SCARA problem, 3000 random starts: " << converged << " converged, " << cycles
            << " cycles\n";
}

TEST(IkStatus, DivergenceAndBadNumbersAreStatuses) {
  Options o;
  o.method = Method::newton;
  const auto s = solve(Arctan{}, Vec<3>(2.0, 0.0, 0.0), o);
  EXPECT_EQ(s.status, Status::diverged) << s.report();
  const ScaraPosition p;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const Method m : {Method::newton, Method::lm, Method::lm_adaptive, Method::halley, Method::halley_thesis}) {
    o.method = m;
    EXPECT_EQ(solve(p, Vec<3>(nan, 0.5, 1.0), o).status, Status::diverged);
    EXPECT_EQ(solve(p, Vec<3>(0.5, std::numeric_limits<double>::infinity(), 1.0), o).status, Status::diverged);
  }
}

TEST(IkStatus, UnreachableTargetStallsAtTheNearestPoint) {
  PlanarPosition p;
  p.target = Vec2(5.0, 0.0);  // reach is 3 m
  Options o;
  o.method = Method::lm_adaptive;
  const auto s = solve(p, Vec<3>(0.3, 0.2, -0.1), o);
  EXPECT_EQ(s.status, Status::stalled) << s.brief();
  EXPECT_NEAR(s.error, 2.0, 1e-6);  // the stretched arm, 2 m short
  o.method = Method::analytic;
  EXPECT_EQ(solve(p, Vec<3>::Zero(), o).status, Status::no_solution);
}

TEST(IkStatus, MethodsThatDoNotApplyAreUnsupported) {
  Options o;
  PlanarPosition pos;
  pos.target = Vec2(1.5, 1.0);
  o.method = Method::halley_thesis;  // needs a square J
  EXPECT_EQ(solve(pos, Vec<3>(0.1, 0.2, 0.3), o).status, Status::unsupported);
  o.method = Method::analytic;  // a continuum, no closed form
  EXPECT_EQ(solve(pos, Vec<3>(0.1, 0.2, 0.3), o).status, Status::unsupported);
  o.method = Method::halley;  // no second derivatives
  EXPECT_EQ(solve(CubicCycle{}, Vec<3>(0.5, 0, 0), o).status, Status::unsupported);
  o.method = Method::analytic;  // no closed form
  EXPECT_EQ(solve(CubicCycle{}, Vec<3>(0.5, 0, 0), o).status, Status::unsupported);
  PlanarPose pose;
  pose.target = Vec2(2.9, 0.0);
  pose.alpha = kPi;  // wrist at 3.9 m: out of reach for this orientation
  EXPECT_EQ(solve(pose, Vec<3>::Zero(), o).status, Status::no_solution);
}

// ---------------------------------------------------------------------- history and summary

TEST(IkSummary, HistoryRowsAreTheIterates) {
  const ScaraPosition p;
  for (const Method m : {Method::newton, Method::lm, Method::lm_adaptive, Method::halley_thesis, Method::halley}) {
    const auto s = solve(p, kSeedStart, seed_options(m));
    ASSERT_EQ(s.status, Status::converged) << s.brief();
    const auto& h = s.history;
    ASSERT_EQ(h.size(), static_cast<std::size_t>(s.iterations) + 1);
    ASSERT_EQ(h.F.size(), h.size());
    ASSERT_EQ(h.error.size(), h.size());
    ASSERT_EQ(h.step.size(), h.size());
    ASSERT_EQ(h.lambda.size(), h.size());
    EXPECT_EQ(h.q.front(), kSeedStart);
    // the history keeps the iterates as taken; the result wraps the unlimited angles to (-pi, pi]
    for (int j = 0; j < 3; ++j)
      EXPECT_EQ(p.revolute[j] ? wrap_angle(h.q.back()[j]) : h.q.back()[j], s.q[j]) << j;
    EXPECT_EQ(h.error.back(), s.error);
    EXPECT_EQ(h.step.front(), 0.0);
    for (std::size_t k = 0; k < h.size(); ++k) {
      EXPECT_NEAR((p.forward(h.q[k]) - p.target - h.F[k]).norm(), 0.0, 1e-9);
      EXPECT_DOUBLE_EQ(h.error[k], h.F[k].norm());
      if (k > 0) {
        EXPECT_NEAR(h.step[k], (h.q[k] - h.q[k - 1]).norm(), 1e-9 * (1.0 + h.step[k]));
      }
      if (k + 1 < h.size()) {
        EXPECT_GE(h.error[k], 1e-6);  // the seed's stop rule: first time below tol
      }
    }
    EXPECT_LT(h.error.back(), 1e-6);
    if (m == Method::lm_adaptive)
      for (std::size_t k = 1; k < h.size(); ++k) {
        EXPECT_GT(h.lambda[k], 0.0);
        EXPECT_LT(h.error[k], h.error[k - 1]);  // accepted steps always descend
      }
  }
}

TEST(IkSummary, NoHistoryGivesTheSameSolve) {
  const ScaraPosition p;
  Options o = seed_options(Method::halley_thesis);
  Summary<3, 3> a, b;
  solve(p, kSeedStart, o, a);
  o.keep_history = false;
  solve(p, kSeedStart, o, b);
  EXPECT_EQ(b.history.size(), 0u);
  EXPECT_EQ(a.q, b.q);
  EXPECT_EQ(a.iterations, b.iterations);
  // Reusing a Summary: state from the previous solve does not leak.
  o.keep_history = true;
  o.method = Method::newton;
  solve(p, kSeedStart, o, a);
  EXPECT_EQ(a.iterations, 8);
  EXPECT_EQ(a.history.size(), 9u);
}

TEST(IkSummary, Prints) {
  const ScaraPosition p;
  const auto s = solve(p, kSeedStart, seed_options(Method::newton));
  std::ostringstream os;
  os << s;
  EXPECT_NE(os.str().find("newton: converged after 8 iterations"), std::string::npos) << os.str();
  const std::string r = s.report();
  EXPECT_EQ(std::count(r.begin(), r.end(), '\n'), 2 + 9) << r;  // brief, header, 9 rows
}

TEST(IkNames, RoundTrip) {
  for (const Method m : {Method::newton, Method::lm, Method::lm_adaptive, Method::halley_thesis, Method::halley,
                         Method::analytic}) {
    Method back{};
    ASSERT_TRUE(parse(to_string(m), back)) << to_string(m);
    EXPECT_EQ(back, m);
  }
  for (const Status st : {Status::converged, Status::stalled, Status::singular, Status::max_iter, Status::cycle,
                          Status::diverged, Status::unsupported, Status::no_solution}) {
    Status back{};
    ASSERT_TRUE(parse(to_string(st), back)) << to_string(st);
    EXPECT_EQ(back, st);
  }
  EXPECT_EQ(to_string(Method::lm_adaptive), "lm_adaptive");
  EXPECT_EQ(to_string(Method::halley_thesis), "halley_thesis");
  Method m{};
  EXPECT_FALSE(parse("Newton", m));
  EXPECT_FALSE(parse("", m));
}
