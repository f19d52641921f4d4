// The singularity tolerance relative to the arm's size (methods/base/singular_scale.hpp): the seed's arm
// and a planar 4R scaled down to millimetres and micrometres, on their path scaled alike, end as the
// metre-size arm does (the inertia-weighted resolution at k = 0 is invariant under a uniform scaling:
// the joint motion is the same), and a path that truly meets a singularity still stops there; arms
// reaching 1 m or more keep the tolerance as given.
#include <gtest/gtest.h>

#include <vector>

#include "methods/chain/start.hpp"
#include "methods/chain/trajectory.hpp"
#include "methods/closed_form/seed_cases.hpp"
#include "methods/base/singular_scale.hpp"
#include "methods/base/trajectory.hpp"

using namespace ks;

namespace {

Path2 scaled(const Path2& p, double s) {
  std::vector<Vec2> v;
  for (const Vec2& x : p.vertices()) v.push_back(s * x);
  return Path2(v, p.durations());
}

PlanarArm3 seed_scaled(double s) { return PlanarArm3::bars({s, s, s}, {5.0, 2.0, 1.0}, 0.1 * s); }

TrajectoryOptions weighted() {
  TrajectoryOptions o;
  o.method = TrajectoryMethod::local_weighted;
  o.alpha1A = -23.75 * M_PI / 180;
  return o;
}

}  // namespace

TEST(SingularScale, Factor) {
  EXPECT_EQ(singular_scale(1.0, 2), 1.0);
  EXPECT_EQ(singular_scale(3.0, 3), 1.0);
  EXPECT_DOUBLE_EQ(singular_scale(0.5, 2), 0.25);
  EXPECT_DOUBLE_EQ(singular_scale(0.1, 3), 1e-3);
  EXPECT_EQ(singular_scale(0.0, 2), 1.0);
  EXPECT_EQ(singular_scale(-1.0, 2), 1.0);
}

TEST(SingularScale, SeedArmScaledDownEndsAsTheMetreArm) {
  const TrajectoryOptions o = weighted();
  const TrajectoryMetrics ref = simulate(PlanarArm3::seed(), seed_square(), o);
  ASSERT_EQ(ref.status, RunStatus::ok);
  for (double s : {1e-3, 1e-6}) {
    SCOPED_TRACE(s);
    const TrajectoryMetrics m = simulate(seed_scaled(s), scaled(seed_square(), s), o);
    EXPECT_EQ(m.status, ref.status);
    EXPECT_EQ(m.samples, ref.samples);
    EXPECT_NEAR(m.min_manipulability / (s * s), ref.min_manipulability, 1e-6 * ref.min_manipulability);
  }
}

TEST(SingularScale, ScaledPathOutOfReachStillStopsAsSingular) {
  // the seed's arm at a reach of 1 m (links of 1/3 m), where the tolerance is as given, sent out of
  // reach; the same arm and path a million times smaller stop at the same sample
  const double base = 1.0 / 3.0;
  const Path2 out({Vec2(1.5, 1.5), Vec2(3.5, 0.5)}, {2.0});
  TrajectoryOptions o = weighted();
  o.singular_tolerance = 0.2 * base * base;  // met on the way out of reach
  o.torque_bound = 1e12;
  const TrajectoryMetrics ref = simulate(seed_scaled(base), scaled(out, base), o);
  ASSERT_EQ(ref.status, RunStatus::singular);
  const double s = 1e-6 * base;
  const TrajectoryMetrics m = simulate(seed_scaled(s), scaled(out, s), o);
  EXPECT_EQ(m.status, RunStatus::singular);
  EXPECT_NEAR(static_cast<double>(m.samples), static_cast<double>(ref.samples), 1.0);
}

TEST(SingularScale, PlanarChainScaledDownEndsAsTheMetreChain) {
  const TrajectoryOptions o = weighted();
  const auto run = [&](double s) {
    const Chain c = planar_chain(planar_bars({s, s, 0.5 * s, 0.5 * s}, {4, 3, 2, 1}, 0.1 * s));
    return simulate(c, ChainTask(TaskSpace::planar_position, scaled(seed_square(), s), o.dt), planar_start_guess(4), o);
  };
  const TrajectoryMetrics ref = run(1.0);
  ASSERT_EQ(ref.status, RunStatus::ok);
  for (double s : {1e-3, 1e-6}) {
    SCOPED_TRACE(s);
    const TrajectoryMetrics m = run(s);
    EXPECT_EQ(m.status, ref.status);
    EXPECT_EQ(m.samples, ref.samples);
  }
}
