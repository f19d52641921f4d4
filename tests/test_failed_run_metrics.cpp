// A run that ends before its first sample computed no metric: every figure is NaN (not 0), whatever
// status ended it: finish_run over every status, the path-global measure ending at sample 0
// (infeasible, singular_extension), the global solve's refusals and a local run singular at once.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "methods/path_global/alpha_basis.hpp"
#include "methods/path_global/solve_closed_form.hpp"
#include "methods/path_global/closed_form.hpp"
#include "methods/metrics/sample_sums.hpp"
#include "methods/base/trajectory.hpp"

using namespace ks;

namespace {
constexpr double kDegree = 3.14159265358979323846 / 180.0;

void expect_no_metric(const TrajectoryMetrics& m, const char* what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(m.samples, 0u);
  for (double v : {m.E, m.E_M, m.min_manipulability, m.torque_sq_integral, m.power_sq_integral, m.max_tracking_error,
                   m.mean_tracking_error, m.final_alpha, m.max_q_limit_ratio, m.max_qd_limit_ratio,
                   m.max_tau_limit_ratio, m.E_force, m.max_orientation_error})
    EXPECT_TRUE(std::isnan(v)) << v;
  for (Eigen::Index j = 0; j < m.tau_inf.size(); ++j) EXPECT_TRUE(std::isnan(m.tau_inf[j])) << m.tau_inf[j];
  for (double v : m.sampled) EXPECT_TRUE(std::isnan(v)) << v;
}

TrajectoryOptions global_options() {
  TrajectoryOptions o;
  o.method = TrajectoryMethod::global_spline;
  o.global.knots = 10;
  o.global.start = GlobalStart::vertex;
  o.global.extension = Extension::alpha;
  o.alpha1A = -23.75 * kDegree;
  o.vertex_alpha = {13.30 * kDegree, 17.28 * kDegree, -12.44 * kDegree, -16.12 * kDegree};
  return o;
}
}  // namespace

TEST(FailedRunMetrics, NoSampleMeansNoMetricWhateverTheStatus) {
  const RunStatus all[] = {RunStatus::ok,           RunStatus::unreachable_start, RunStatus::singular,
                           RunStatus::diverged,     RunStatus::undersampled,      RunStatus::off_path,
                           RunStatus::out_of_limits, RunStatus::max_evaluations,  RunStatus::not_converged,
                           RunStatus::infeasible,   RunStatus::singular_extension};
  LimitTable limits;
  limits.n = 3;
  limits.any_position = limits.any_velocity = limits.any_effort = true;
  RunShape shape;
  shape.orientation = shape.prismatic = true;
  shape.limits = &limits;
  for (RunStatus s : all) {
    RunSums sums;  // the sums a loop leaves when it stops before its first sample
    sums.status = s;
    sums.last_alpha = 0.3;
    expect_no_metric(finish_run(sums, shape, TrajectoryOptions{}), std::string(to_string(s)).c_str());
  }
}

TEST(FailedRunMetrics, OneSampleGivesMetrics) {
  RunSums sums;
  sums.status = RunStatus::infeasible;
  sums.done = 1;
  sums.sumE = 2.0, sums.max_err2 = 0.25;
  const TrajectoryMetrics m = finish_run(sums, RunShape{}, TrajectoryOptions{});
  EXPECT_EQ(m.E, 2.0);
  EXPECT_EQ(m.max_tracking_error, 0.5);
}

TEST(FailedRunMetrics, GlobalMeasureEndingAtTheFirstSample) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const SampledPath path(seed_square(), 1e-3);
  const AlphaBasis basis = cubic_spline_basis(path, 10);
  TrajectoryOptions o = global_options();
  // alpha = -60 deg everywhere: the wrist cannot reach the first vertex (the seed's unreachable start)
  const std::vector<double> out_of_reach(basis.coefficients, -60.0 * kDegree);
  const PathGlobalProblem alpha(arm, path, Elbow::positive, o.singular_tolerance, Extension::alpha);
  TrajectoryMetrics m = alpha.measure(basis, out_of_reach.data(), o, nullptr);
  EXPECT_EQ(m.status, RunStatus::infeasible);
  expect_no_metric(m, "infeasible at sample 0");
  // a reachable alpha, every sample singular under a tolerance above any |det J3|
  o.singular_tolerance = 1e9;
  const PathGlobalProblem strict(arm, path, Elbow::positive, o.singular_tolerance, Extension::alpha);
  const std::vector<double> reachable(basis.coefficients, -23.75 * kDegree);
  m = strict.measure(basis, reachable.data(), o, nullptr);
  EXPECT_EQ(m.status, RunStatus::singular_extension);
  expect_no_metric(m, "singular_extension at sample 0");
  // the same alpha under the default tolerance: a run with metrics (the two above are not vacuous)
  o.singular_tolerance = TrajectoryOptions{}.singular_tolerance;
  m = alpha.measure(basis, reachable.data(), o, nullptr);
  EXPECT_GT(m.samples, 0u);
  EXPECT_TRUE(std::isfinite(m.E));
}

// A run that leaves the reach part-way: its metrics stop at the last sample within reach, whose tip
// angle (the joint angles' sum, as sample() gives them) is the run's final_alpha, wherever that
// sample falls in the measure's blocks.
TEST(FailedRunMetrics, GlobalMeasureEndingPartWayKeepsTheLastSamplesAngle) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const SampledPath path(seed_square(), 1e-3);
  const AlphaBasis basis = cubic_spline_basis(path, 10);
  const TrajectoryOptions o = global_options();
  const PathGlobalProblem alpha(arm, path, Elbow::positive, o.singular_tolerance, Extension::alpha);
  std::vector<double> c(basis.coefficients, -23.75 * kDegree);
  for (int k = 5; k < basis.coefficients; ++k) c[k] = -60.0 * kDegree;  // out of reach from mid-path on
  const TrajectoryMetrics m = alpha.measure(basis, c.data(), o, nullptr);
  ASSERT_EQ(m.status, RunStatus::infeasible);
  ASSERT_GT(m.samples, 1u);
  ASSERT_LT(m.samples, path.size());
  const std::size_t last = m.samples - 1;
  std::printf("the run ends at sample %zu (block row %zu)\n", last, last % kSampleBlock);
  double a, ad, add;
  basis.at(last, c.data(), a, ad, add);
  GlobalSample s;
  alpha.sample(last, a, ad, add, s);
  ASSERT_TRUE(s.reachable);
  EXPECT_EQ(m.final_alpha, s.q[0] + s.q[1] + s.q[2]) << "sample " << last;
}

TEST(FailedRunMetrics, GlobalSolveRefusals) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const SampledPath path(seed_square(), 1e-3);
  TrajectoryOptions o = global_options();
  o.alpha1A = -60.0 * kDegree;
  TrajectoryMetrics m = solve_global_spline(arm, path, o);
  EXPECT_EQ(m.status, RunStatus::unreachable_start);
  expect_no_metric(m, "unreachable_start");
}

TEST(FailedRunMetrics, LocalRunSingularAtOnce) {
  const PlanarArm3 arm = PlanarArm3::seed();
  TrajectoryOptions o;
  o.alpha1A = -23.75 * kDegree;
  o.singular_tolerance = 1e9;  // above any sqrt(det(J J^T)) of the arm
  const TrajectoryMetrics m = simulate(arm, seed_square(), o);
  EXPECT_EQ(m.status, RunStatus::singular);
  if (m.samples == 0) {
    expect_no_metric(m, "singular at sample 0");
  } else {  // the samples done before the singular one give metrics
    EXPECT_TRUE(std::isfinite(m.E));
    EXPECT_TRUE(std::isfinite(m.max_tracking_error));
  }
}
