// The path-global method: its spline families, its evaluator against an independent composition of
// the model's functions and against the seed's integrated vertex_alpha, its gradient against finite
// differences, and its optimum on the seed's arm (below the local and the vertex-quintic optima,
// on the path, and not improved by small perturbations).
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "methods/path_global/alpha_basis.hpp"
#include "methods/path_global/solve_closed_form.hpp"
#include "methods/path_global/closed_form.hpp"
#include "methods/base/trajectory.hpp"
#include "model/dynamics.hpp"

using namespace ks;

namespace {
constexpr double kDegree = 3.14159265358979323846 / 180.0;
/// Case 4's optimum with the physical inertia (README: the pipeline's 45.33 Nm): alpha at vertices 1..5.
const std::vector<double> kCase4Physical{-23.75 * kDegree, 13.30 * kDegree, 17.28 * kDegree, -12.44 * kDegree,
                                         -16.12 * kDegree};

std::vector<double> random_coefficients(int n, double centre, double spread, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-spread, spread);
  std::vector<double> c(n);
  for (double& x : c) x = centre + u(rng);
  return c;
}

/// E of alpha(t) given as a TaskPath<1> through `vertices`, computed without the evaluator: the
/// analytic IK, the 3x3 Jacobian's LU solves with the full Jdot, and inverse_dynamics' dense M.
double independent_E(const PlanarArm3& arm, const SampledPath& path, const std::vector<double>& vertices,
                     double* max_tracking) {
  std::vector<Eigen::Matrix<double, 1, 1>> v;
  for (double a : vertices) v.emplace_back(a);
  const Profile1 alpha(std::move(v), path.path().durations());
  double sum = 0.0;
  *max_tracking = 0.0;
  for (std::size_t i = 0; i < path.size(); ++i) {
    const double t = path.time(i);
    const PathSample<2> x = path.path().sample_on(path.segment(i), t);
    const PathSample<1> a = alpha.sample_on(path.segment(i), t);
    const Vec3 q = *inverse_kinematics(arm, x.p, a.p[0]);
    const JointTrig trig = joint_trig(q);
    const Mat3 J3 = jacobian_with_alpha(arm, trig);
    const Vec3 qd = J3.fullPivLu().solve(Vec3(x.v.x(), x.v.y(), a.v[0]));
    const Vec2 jdqd = jacobian_dot(arm, trig, qd) * qd;
    const Vec3 qdd = J3.fullPivLu().solve(Vec3(x.a.x() - jdqd.x(), x.a.y() - jdqd.y(), a.a[0]));
    sum += inverse_dynamics(arm, q, qd, qdd).norm();
    *max_tracking = std::max(*max_tracking, (forward_kinematics(arm, q).tip - x.p).norm());
  }
  return sum / static_cast<double>(path.size());
}

TrajectoryOptions global_options(int knots, GlobalStart start) {
  TrajectoryOptions o;
  o.method = TrajectoryMethod::global_spline;
  o.alpha1A = kCase4Physical[0];
  o.vertex_alpha.assign(kCase4Physical.begin() + 1, kCase4Physical.end());
  o.global.knots = knots;
  o.global.start = start;
  o.global.extension = Extension::self_motion;
  return o;
}
}  // namespace

TEST(AlphaBasis, CubicIsAPartitionOfUnityAtRestAtBothEnds) {
  const SampledPath path(seed_square(), 1e-3);
  const AlphaBasis b = cubic_spline_basis(path, 9);
  ASSERT_EQ(b.coefficients, 9);
  const std::vector<double> ones(9, 1.0), c = random_coefficients(9, 0.0, 1.0, 7);
  for (std::size_t i = 0; i < path.size(); ++i) {
    double a, ad, add;
    b.at(i, ones.data(), a, ad, add);
    EXPECT_NEAR(a, 1.0, 1e-14);
    EXPECT_NEAR(ad, 0.0, 1e-12);
    EXPECT_NEAR(add, 0.0, 1e-10);
  }
  double a, ad, add;
  b.at(0, c.data(), a, ad, add);
  EXPECT_NEAR(a, c.front(), 1e-14);
  EXPECT_NEAR(ad, 0.0, 1e-12);
  b.at(path.size() - 1, c.data(), a, ad, add);
  EXPECT_NEAR(a, c.back(), 1e-12);
  EXPECT_NEAR(ad, 0.0, 1e-10);
}

TEST(AlphaBasis, CubicWithAFreeEndHasOneMoreCoefficientAndMovesThere) {
  const SampledPath path(seed_square(), 1e-3);
  const AlphaBasis b = cubic_spline_basis(path, 9, false);
  ASSERT_EQ(b.coefficients, 10);
  const std::vector<double> ones(10, 1.0), c = random_coefficients(10, 0.0, 1.0, 3);
  double a, ad, add;
  for (std::size_t i = 0; i < path.size(); i += 101) {
    b.at(i, ones.data(), a, ad, add);
    EXPECT_NEAR(a, 1.0, 1e-14);
  }
  b.at(0, c.data(), a, ad, add);
  EXPECT_NEAR(ad, 0.0, 1e-12);  // still at rest at the start
  b.at(path.size() - 1, c.data(), a, ad, add);
  EXPECT_NEAR(a, c.back(), 1e-12);
  EXPECT_GT(std::abs(ad), 1e-3);  // 3 (c[9] - c[8]) / knot spacing
}

TEST(AlphaBasis, CubicDerivativesMatchFiniteDifferences) {
  const SampledPath path(seed_square(), 1e-3);
  const AlphaBasis b = cubic_spline_basis(path, 12);
  const std::vector<double> c = random_coefficients(12, 0.0, 1.0, 11);
  const double dt = path.dt();
  for (std::size_t i = 1; i + 1 < path.size(); i += 37) {
    double a0, d0, s0, a1, d1, s1, a2, d2, s2;
    b.at(i - 1, c.data(), a0, d0, s0);
    b.at(i, c.data(), a1, d1, s1);
    b.at(i + 1, c.data(), a2, d2, s2);
    // central differences are off by dt^2 / 6 times the next derivative: ~1e-4 here
    EXPECT_NEAR((a2 - a0) / (2 * dt), d1, 1e-3 * std::max(1.0, std::abs(d1))) << i;
    EXPECT_NEAR((d2 - d0) / (2 * dt), s1, 1e-2 * std::max(1.0, std::abs(s1))) << i;
  }
}

TEST(AlphaBasis, VertexQuinticIsTheSeedsProfileAndFitsItself) {
  const SampledPath path(seed_square(), 1e-3);
  const AlphaBasis b = vertex_quintic_basis(path);
  ASSERT_EQ(b.coefficients, 5);
  std::vector<Eigen::Matrix<double, 1, 1>> v;
  for (double a : kCase4Physical) v.emplace_back(a);
  const Profile1 profile(std::move(v), path.path().durations());
  std::vector<double> alpha(path.size());
  for (std::size_t i = 0; i < path.size(); ++i) {
    const PathSample<1> p = profile.sample_on(path.segment(i), path.time(i));
    double ad, add;
    b.at(i, kCase4Physical.data(), alpha[i], ad, add);
    EXPECT_NEAR(alpha[i], p.p[0], 1e-14);
    EXPECT_NEAR(ad, p.v[0], 1e-13);
    EXPECT_NEAR(add, p.a[0], 1e-12);
  }
  const std::vector<double> fit = fit_basis(b, alpha.data(), alpha.size());
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(fit[k], kCase4Physical[k], 1e-12);
}

// The same evaluator, two parametrisations: the vertex-quintic family at case 4's physical optimum
// equals an independent composition of the model's functions to 1e-9, on the path, and the seed's own
// vertex_alpha integrated by RK4 to 1e-9; integrated as the seed does (semi-implicit Euler, open
// loop) it converges to it as dt shrinks.
TEST(PathGlobal, VertexQuinticEqualsIndependentCompositionAndTheIntegratedSeed) {
  const PlanarArm3 arm = PlanarArm3::seed();
  double gap_coarse = 0.0;
  for (double dt : {1e-3, 1e-4}) {
    const SampledPath path(seed_square(), dt);
    const PathGlobalProblem problem(arm, path, Elbow::positive, 1e-9, Extension::alpha);
    TrajectoryOptions o;
    o.dt = dt;
    const TrajectoryMetrics m = problem.measure(vertex_quintic_basis(path), kCase4Physical.data(), o, nullptr);
    ASSERT_EQ(m.status, RunStatus::ok);
    double tracking = 0.0;
    const double E = independent_E(arm, path, kCase4Physical, &tracking);
    EXPECT_LT(std::abs(m.E / E - 1.0), 1e-9) << "dt " << dt << ": " << m.E << " vs " << E;
    EXPECT_LT(m.max_tracking_error, 1e-12);
    EXPECT_LT(tracking, 1e-12);
    TrajectoryOptions seed;
    seed.method = TrajectoryMethod::vertex_alpha;
    seed.dt = dt;
    seed.alpha1A = kCase4Physical[0];
    seed.vertex_alpha.assign(kCase4Physical.begin() + 1, kCase4Physical.end());
    const TrajectoryMetrics integrated = simulate(arm, path, seed);
    const double gap = std::abs(integrated.E - m.E);
    // the seed's method integrated by RK4 (on the path to 2.3e-9 m at 1 ms): the same E to 1e-9
    seed.integrator = Integrator::rk4;
    const TrajectoryMetrics rk4 = simulate(arm, path, seed);
    EXPECT_LT(rk4.max_tracking_error, 1e-8);
    EXPECT_LT(std::abs(rk4.E / m.E - 1.0), 1e-9) << "dt " << dt << ": " << rk4.E << " vs " << m.E;
    if (dt == 1e-3) {
      gap_coarse = gap;
      EXPECT_NEAR(integrated.E, 45.33, 0.005);
    } else {
      EXPECT_LT(gap, gap_coarse / 5.0) << "the open-loop drift shrinks with dt";
    }
  }
}

// The self-motion chart: a tip angle and branch give back that tip angle and branch, and the joints
// move continuously as psi crosses the end of the arc, where the branch changes (the stretched arm).
TEST(PathGlobal, SelfMotionChartRoundTripsAndCrossesBranchesContinuously) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const SampledPath path(seed_square(), 1e-3);
  const PathGlobalProblem problem(arm, path, Elbow::positive, 1e-9, Extension::self_motion);
  ASSERT_TRUE(problem.chart_defined());
  for (std::size_t i : {std::size_t(0), std::size_t(700), std::size_t(1500)})
    for (double a_deg : {-20.0, 0.0, 15.0})
      for (Elbow e : {Elbow::positive, Elbow::negative}) {
        const double a = a_deg * kDegree;
        GlobalSample s;
        problem.sample(i, problem.coordinate(i, a, e), 0.0, 0.0, s);
        if (!inverse_kinematics(arm, path.position(i), a, e)) continue;  // not on the arc here
        ASSERT_TRUE(s.reachable);
        EXPECT_NEAR(std::remainder(s.q.sum() - a, 2 * std::numbers::pi), 0.0, 1e-12) << i << " " << a_deg;
        EXPECT_EQ(std::sin(s.q[1]) >= 0.0, e == Elbow::positive) << i << " " << a_deg;
      }
  for (double end : {std::numbers::pi / 2, -std::numbers::pi / 2}) {
    GlobalSample below, above;
    problem.sample(700, end - 1e-6, 0.0, 0.0, below);
    problem.sample(700, end + 1e-6, 0.0, 0.0, above);
    EXPECT_LT((above.q - below.q).cwiseAbs().maxCoeff(), 1e-4);  // ~ 2e-6 times dq/dpsi
    EXPECT_LT(std::sin(below.q[1]) * std::sin(above.q[1]), 0.0);  // the branch changes
  }
}

// Seed 3R, physical inertia, objective E, 20 knots, from case 4's alpha(t): below the best local run
// of the shipped landscape_alpha_k (36.74 Nm, 1.3 mm off its path) and below case 4's optimum (45.33),
// on the path; 1,000 small random perturbations of the optimum's coefficients do not lower E.
TEST(PathGlobal, OptimumBeatsLocalAndVertexQuinticAndResistsPerturbations) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const SampledPath path(seed_square(), 1e-3);
  TrajectoryOptions o = global_options(20, GlobalStart::vertex);
  o.global.tolerance = 1e-15;
  std::vector<double> c;
  const TrajectoryMetrics m = solve_global_spline(arm, path, o, nullptr, &c);
  ASSERT_EQ(m.status, RunStatus::ok);
  EXPECT_LE(m.E, 36.74);
  EXPECT_LE(m.E, 45.33);
  EXPECT_LE(m.max_tracking_error, 1e-6);
  EXPECT_EQ(m.samples, path.size());
  EXPECT_NEAR(m.E, m.opt_objective, 1e-12 * m.E);  // the same sum, in another order
  std::printf("E %.10f evaluations %g gradient norm %g\n", m.E, m.opt_evaluations, m.opt_gradient_norm);
  const PathGlobalProblem problem(arm, path, o.elbow, o.singular_tolerance, Extension::self_motion);
  const AlphaBasis b = cubic_spline_basis(path, 20);
  const double best = problem.objective(b, c.data(), GlobalObjective::E, nullptr);
  std::mt19937 rng(2026);
  std::uniform_real_distribution<double> u(-1e-3, 1e-3);
  int lower = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    std::vector<double> p = c;
    for (std::size_t k = 1; k < p.size(); ++k) p[k] += u(rng);  // alpha1A stays fixed
    if (problem.objective(b, p.data(), GlobalObjective::E, nullptr) < best - 1e-9) ++lower;
  }
  EXPECT_EQ(lower, 0);
}

TEST(PathGlobal, StatusesOfAnUnreachableStartAndAnExhaustedBudget) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const SampledPath path(seed_square(), 1e-3);
  TrajectoryOptions o = global_options(10, GlobalStart::vertex);
  o.alpha1A = -60.0 * kDegree;  // the wrist cannot reach the first vertex
  EXPECT_EQ(solve_global_spline(arm, path, o).status, RunStatus::unreachable_start);
  o = global_options(10, GlobalStart::vertex);
  o.global.max_evaluations = 3;
  const TrajectoryMetrics m = solve_global_spline(arm, path, o);
  EXPECT_EQ(m.status, RunStatus::max_evaluations);
  EXPECT_EQ(m.opt_evaluations, 3.0);
  EXPECT_TRUE(std::isfinite(m.E));
  o.global.max_evaluations = 0;
  EXPECT_THROW(solve_global_spline(arm, path, o), std::invalid_argument);
}
