// A tip error equal to tracking_bound is on the path; only an error above it is off_path: at one
// sample whose squared error rounds above the squared bound while its distance equals the bound, and
// on whole runs of every loop (closed-form 3R single and in lanes, planar chain) with the bound set
// to the run's own maximum error, then to the double just below it.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "methods/chain/trajectory.hpp"
#include "methods/metrics/sample_sums.hpp"
#include "methods/closed_form/seed_cases.hpp"
#include "methods/base/trajectory.hpp"
#include "methods/closed_form/lanes.hpp"
#include "model/chain_dynamics.hpp"

using namespace ks;

namespace {

SampleValues<double> one_sample(const double* zeros, double err2) {
  return SampleValues<double>{3, zeros, zeros, zeros, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, err2, 0.0, 0.0, 0.0};
}

double below(double x) { return std::nextafter(x, 0.0); }

}  // namespace

TEST(TrackingBoundEquality, DistanceEqualToTheBoundIsOnThePath) {
  const double bound = 0.01, err2 = std::nextafter(bound * bound, 1.0);
  // the case squares get wrong: the distance is the bound, its square rounds above the bound's square
  ASSERT_EQ(std::sqrt(err2), bound);
  ASSERT_GT(err2, bound * bound);
  const double zeros[3] = {0, 0, 0};
  const auto keep = [](double updated, double) { return updated; };
  SampleSums<double, 3> sums(bound, 1.0);
  EXPECT_FALSE(sums.add(0, 0.0, one_sample(zeros, err2), zeros, 3, keep));
  sums.mark(false);
  const TrajectoryMetrics m = finish_run(sums.of_lane(0, RunStatus::ok, 3), RunShape{}, TrajectoryOptions{});
  EXPECT_EQ(m.status, RunStatus::ok);
  EXPECT_EQ(m.max_tracking_error, bound);
  // the first squared error whose distance is above the bound crosses it
  double above = err2;
  while (!(std::sqrt(above) > bound)) above = std::nextafter(above, 1.0);
  SampleSums<double, 3> off(bound, 1.0);
  EXPECT_TRUE(off.add(0, 0.0, one_sample(zeros, above), zeros, 3, keep));
}

TEST(TrackingBoundEquality, RunAtItsOwnMaximumErrorIsNotOffPath) {
  const Path2 square = seed_square();
  const SampledPath sampled(square, 1e-3);
  for (const SeedCase& c : seed_cases()) {
    SCOPED_TRACE(c.name);
    TrajectoryOptions o = c.options();
    o.on_violation = OnViolation::ignore;
    const double worst = simulate(PlanarArm3::seed(), sampled, o).max_tracking_error;
    ASSERT_GT(worst, 0.0);
    o.on_violation = OnViolation::mark;
    o.orientation_bound = std::numeric_limits<double>::max();
    o.tracking_bound = worst;
    const TrajectoryMetrics at = simulate(PlanarArm3::seed(), sampled, o);
    EXPECT_NE(at.status, RunStatus::off_path);
    EXPECT_EQ(at.max_tracking_error, worst);
    o.tracking_bound = below(worst);
    EXPECT_EQ(simulate(PlanarArm3::seed(), sampled, o).status, RunStatus::off_path);
    const int lanes = supported_lanes();
    if (lanes > 1) {  // every lane at the bound equal to its run's maximum
      std::vector<TrajectoryOptions> opts(lanes, o);
      opts[0].tracking_bound = worst;
      std::vector<TrajectoryMetrics> together(lanes);
      simulate_lanes(lanes, PlanarArm3::seed(), sampled, opts.data(), lanes, together.data());
      EXPECT_NE(together[0].status, RunStatus::off_path);
      EXPECT_EQ(together[1].status, RunStatus::off_path);
    }
  }
}

TEST(TrackingBoundEquality, ChainRunAtItsOwnMaximumErrorIsNotOffPath) {
  const Chain chain = planar_chain(planar_bars({1.0, 0.5, 0.5, 0.5, 0.5}, {5, 1, 1, 0.5, 0.5}, 0.1));
  const Path3 path = lift_to_3d(seed_square());
  TrajectoryOptions o;
  o.alpha1A = 0.2;
  o.on_violation = OnViolation::ignore;
  const ChainTask task(TaskSpace::planar_position, path, o.dt);
  const double worst = simulate(chain, task, planar_start_guess(5), o).max_tracking_error;
  ASSERT_GT(worst, 0.0);
  o.on_violation = OnViolation::mark;
  o.tracking_bound = worst;
  EXPECT_NE(simulate(chain, task, planar_start_guess(5), o).status, RunStatus::off_path);
  o.tracking_bound = below(worst);
  EXPECT_EQ(simulate(chain, task, planar_start_guess(5), o).status, RunStatus::off_path);
}
