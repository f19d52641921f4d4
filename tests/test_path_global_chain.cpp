// The path-global method on planar chains: the construction reproduces a configuration from its
// coordinates; on the seed's arm as a chain it agrees with the closed-form evaluator; its gradient
// matches finite differences; on a 4R and a 5R arm it ends on its path below the local runs.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "methods/path_global/alpha_basis.hpp"
#include "methods/chain/start.hpp"
#include "methods/path_global/solve_closed_form.hpp"
#include "methods/path_global/closed_form.hpp"
#include "methods/path_global/planar_chart.hpp"

using namespace ks;

namespace {
double wrap(double a) { return std::remainder(a, 2.0 * std::numbers::pi); }

/// The start configuration of `chain` on the seed square's first vertex with tip angle alpha.
VecN start_of(const Chain& chain, double alpha) {
  StartTarget t;
  t.position = {seed_square().vertices().front().x(), seed_square().vertices().front().y(), 0.0};
  t.angle = alpha;
  return *solve_start(chain, t, planar_start_guess(chain.dof()));
}
}  // namespace

TEST(PathGlobalChain, CoordinatesOfAConfigurationGiveItBack) {
  for (const Chain& chain : {planar_chain(planar_bars({1, 1, 0.5, 0.5}, {5, 2, 0.5, 0.5}, 0.1)),
                             planar_chain(planar_bars({1, 0.5, 0.5, 0.5, 0.5}, {5, 1, 1, 0.5, 0.5}, 0.1))}) {
    const ChainTask task(TaskSpace::planar_position, seed_square(), 1e-3);
    const VecN q = start_of(chain, -20.0 * std::numbers::pi / 180.0);
    for (Extension ext : {Extension::self_motion, Extension::alpha}) {
      double z[kMaxJoints];
      Elbow elbow;
      PlanarChartProblem(chain, task, Extension::alpha, Elbow::positive).coordinates_of(0, q, z, elbow);
      const PlanarChartProblem problem(chain, task, ext, elbow);
      problem.coordinates_of(0, q, z, elbow);
      double zz[kMaxJoints][3] = {};
      for (int k = 0; k < problem.coordinates(); ++k) zz[k][0] = z[k];
      ChainGlobalSample s;
      problem.sample(0, zz, s);
      EXPECT_EQ(s.violation, 0.0) << to_string(ext);
      for (int j = 0; j < chain.dof(); ++j) EXPECT_NEAR(wrap(s.q[j] - q[j]), 0.0, 1e-9) << to_string(ext) << " joint " << j;
      for (int j = 0; j < chain.dof(); ++j) EXPECT_NEAR(s.qd[j], 0.0, 1e-12);  // the path starts at rest
    }
  }
}

// The seed's arm as a planar chain: the chain construction with the chain's inverse dynamics gives
// the closed-form evaluator's E for the same self-motion spline (two independent implementations).
TEST(PathGlobalChain, SeedArmAsAChainMatchesTheClosedForm) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const Chain chain = planar_chain(planar_bars({1, 1, 1}, {5, 2, 1}, 0.1));
  const SampledPath path(seed_square(), 1e-3);
  const ChainTask task(TaskSpace::planar_position, seed_square(), 1e-3);
  const PathGlobalProblem closed(arm, path, Elbow::positive, 1e-9, Extension::self_motion);
  const PlanarChartProblem generic(chain, task, Extension::self_motion, Elbow::positive);
  const AlphaBasis b = cubic_spline_basis(path, 12);
  std::vector<double> c(12);
  for (int k = 0; k < 12; ++k) c[k] = closed.coordinate(0, -20.0 * std::numbers::pi / 180.0, Elbow::positive) + 0.2 * std::sin(k);
  for (GlobalObjective obj : {GlobalObjective::E, GlobalObjective::E_M, GlobalObjective::kinetic_energy}) {
    const double a = closed.objective(b, c.data(), obj, nullptr), g = generic.objective(b, c.data(), obj, nullptr);
    EXPECT_LT(std::abs(a / g - 1.0), 1e-9) << to_string(obj) << ": " << a << " vs " << g;
  }
}

TEST(PathGlobalChain, GradientMatchesFiniteDifferences) {
  const Chain chain = planar_chain(planar_bars({1, 1, 0.5, 0.5}, {5, 2, 0.5, 0.5}, 0.1));
  const ChainTask task(TaskSpace::planar_position, seed_square(), 1e-3);
  const VecN q = start_of(chain, -20.0 * std::numbers::pi / 180.0);
  double z[kMaxJoints];
  Elbow elbow;
  PlanarChartProblem(chain, task, Extension::alpha, Elbow::positive).coordinates_of(0, q, z, elbow);
  const PlanarChartProblem problem(chain, task, Extension::self_motion, elbow);
  problem.coordinates_of(0, q, z, elbow);
  const AlphaBasis b = cubic_spline_basis(task.path.size(), task.path.dt(), 2.0, 6);
  std::vector<double> c(12);
  for (int j = 0; j < 6; ++j) c[j] = z[0] + 0.05 * j, c[6 + j] = z[1] + 0.02 * j;  // near the start, within the chart
  ASSERT_EQ(problem.worst_violation(b, c.data()), 0.0);
  std::vector<double> g(12);
  problem.objective(b, c.data(), GlobalObjective::E, g.data());
  for (int k = 0; k < 12; ++k) {
    std::vector<double> up = c, down = c;
    up[k] += 1e-6, down[k] -= 1e-6;
    const double fd = (problem.objective(b, up.data(), GlobalObjective::E, nullptr) -
                       problem.objective(b, down.data(), GlobalObjective::E, nullptr)) / 2e-6;
    EXPECT_NEAR(g[k], fd, 1e-5 * std::max(1.0, std::abs(fd))) << k;
  }
}

// A 4R arm (the seed's with its last link split): the path-global run ends on its path, at rest,
// below every local run of both methods from the same start angle over k in [0, 0.3].
TEST(PathGlobalChain, FourLinkArmBeatsItsLocalRunsOnThePath) {
  const Chain chain = planar_chain(planar_bars({1, 1, 0.5, 0.5}, {5, 2, 0.5, 0.5}, 0.1));
  const ChainTask task(TaskSpace::planar_position, seed_square(), 1e-3);
  TrajectoryOptions o;
  o.method = TrajectoryMethod::global_spline;
  o.alpha1A = 4.0 * std::numbers::pi / 180.0;
  o.global.knots = 10;
  const TrajectoryMetrics m = solve_global_spline_chain(chain, task, planar_start_guess(4), o);
  ASSERT_EQ(m.status, RunStatus::ok);
  EXPECT_LT(m.max_tracking_error, 1e-9);
  double best_local = 1e300;
  for (TrajectoryMethod method : {TrajectoryMethod::local_weighted, TrajectoryMethod::local_unweighted})
    for (double k : {0.0, 0.1, 0.3}) {
      TrajectoryOptions lo = o;
      lo.method = method;
      lo.k = k;
      const TrajectoryMetrics l = simulate(chain, task, planar_start_guess(4), lo);
      if (l.status == RunStatus::ok) best_local = std::min(best_local, l.E);
    }
  EXPECT_LT(m.E, best_local);
  std::printf("4R: global %.4f Nm (%g evaluations), best local %.4f Nm\n", m.E, m.opt_evaluations, best_local);
}
