// The table of per-sample metrics (methods/metrics/sample_metrics.hpp): each entry's run value equals its
// reduction recomputed from the run's full history, in every trajectory loop (closed-form 3R, the
// fixed-size planar chain, the general chain) and lanes equal single runs bit for bit; every entry
// is a /runs column of every trajectory block.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <set>

#include "methods/chain/trajectory.hpp"
#include "methods/metrics/sample_metrics.hpp"
#include "methods/closed_form/seed_cases.hpp"
#include "methods/base/trajectory.hpp"
#include "methods/closed_form/lanes.hpp"
#include "model/chain_dynamics.hpp"
#include "schema/params.hpp"

using namespace ks;

namespace {

constexpr int kPower = sample_metric_index("peak_joint_power");
static_assert(kPower >= 0);

/// max over stored samples and joints of |tau_j qd_j|: the oracle of peak_joint_power.
template <class History>
double history_peak_power(const History& h) {
  double p = 0;
  for (Eigen::Index c = 0; c < h.size; ++c)
    for (Eigen::Index j = 0; j < h.tau.rows(); ++j) p = std::max(p, std::abs(h.tau(j, c) * h.qd(j, c)));
  return p;
}

}  // namespace

TEST(SampleMetrics, NamesAreUniqueAndFitTheMetricsStruct) {
  std::set<std::string_view> names;
  for_each_sample_metric([&](const auto& m, int k) {
    EXPECT_TRUE(names.insert(m.name).second) << m.name;
    EXPECT_EQ(sample_metric_index(m.name), k);
    EXPECT_FALSE(m.unit.empty()) << m.name;
  });
  EXPECT_LE(kSampleMetricCount, kMaxSampleMetrics);
  EXPECT_EQ(sample_metric_index("no such metric"), -1);
}

// The closed-form 3R loop, every seed case: the metric is the history's peak (every sample stored).
TEST(SampleMetrics, PeakPowerMatchesTheHistoryOfTheClosedForm3R) {
  const Path2 square = seed_square();
  for (const SeedCase& c : seed_cases()) {
    SCOPED_TRACE(c.name);
    TrajectoryHistory h;
    const TrajectoryMetrics m = simulate(PlanarArm3::seed(), square, c.options(), &h);
    ASSERT_EQ(h.size, static_cast<Eigen::Index>(m.samples));
    EXPECT_EQ(m.sampled[kPower], history_peak_power(h));
    EXPECT_GT(m.sampled[kPower], 0.0);
  }
}

// The chain loops: all-revolute planar 5R (the fixed-size planar loop) and an RPR chain with a
// prismatic joint (the general loop; tau q'd is then a force times a speed), position and pose tasks.
TEST(SampleMetrics, PeakPowerMatchesTheHistoryOfTheChainLoops) {
  Chain rpr = planar_chain(planar_bars({1.0, 1.0, 1.0}, {5, 2, 1}, 0.1));
  rpr.joints[1].type = JointType::prismatic;
  rpr.joints[1].axis = Eigen::Vector3d::UnitX();
  rpr.prepare();
  const Chain r5 = planar_chain(planar_bars({1.0, 0.5, 0.5, 0.5, 0.5}, {5, 1, 1, 0.5, 0.5}, 0.1));
  const Path3 path = lift_to_3d(seed_square());
  TrajectoryOptions o;
  o.alpha1A = 0.2;
  o.vertex_alpha = {0.5, 0.3, 0.0, 0.2};
  o.on_violation = OnViolation::ignore;
  for (const Chain* chain : {&r5, static_cast<const Chain*>(&rpr)})
    for (TaskSpace space : {TaskSpace::planar_position, TaskSpace::planar_pose}) {
      if (space == TaskSpace::planar_pose && chain->dof() == 3) continue;  // not redundant
      SCOPED_TRACE(chain->dof());
      ChainHistory h;
      const TrajectoryMetrics m =
          simulate(*chain, ChainTask(space, path, o.dt), planar_start_guess(chain->dof()), o, &h);
      ASSERT_EQ(h.size, static_cast<Eigen::Index>(m.samples));
      ASSERT_GT(m.samples, 0u);
      EXPECT_EQ(m.sampled[kPower], history_peak_power(h));
    }
}

// Lanes compute the table for each lane exactly as the single run does.
TEST(SampleMetrics, LanesEqualSingleRuns) {
  const int lanes = supported_lanes();
  if (lanes == 1) GTEST_SKIP() << "no SIMD lanes on this processor";
  const SampledPath sampled(seed_square(), 1e-3);
  for (TrajectoryMethod method : {TrajectoryMethod::local_unweighted, TrajectoryMethod::vertex_alpha}) {
    std::vector<TrajectoryOptions> opts(lanes);
    for (int i = 0; i < lanes; ++i) {
      opts[i].method = method;
      opts[i].alpha1A = (-20.0 + 7.0 * i) * M_PI / 180;
      opts[i].vertex_alpha = {0.1 * i, 0.2, -0.1, 0.05 * i};
      opts[i].k = 0.1 * i;
    }
    std::vector<TrajectoryMetrics> together(lanes);
    simulate_lanes(lanes, PlanarArm3::seed(), sampled, opts.data(), lanes, together.data());
    for (int i = 0; i < lanes; ++i) {
      const TrajectoryMetrics alone = simulate(PlanarArm3::seed(), sampled, opts[i]);
      for (int k = 0; k < kSampleMetricCount; ++k)
        EXPECT_TRUE(std::memcmp(&alone.sampled[k], &together[i].sampled[k], sizeof(double)) == 0) << i << " " << k;
    }
  }
}

// Every entry is a column of the trajectory table, with the entry's unit, for the seed arm and a chain.
TEST(SampleMetrics, EveryEntryIsARunsColumn) {
  for (bool chain : {false, true}) {
    KindContext ctx;
    ctx.robot.chain = chain;
    ctx.robot.joints = chain ? 5 : 3;
    const std::vector<MetricDef> table = metrics(BlockKind::trajectory, ctx);
    for_each_sample_metric([&](const auto& m, int) {
      const MetricDef* d = nullptr;
      for (const MetricDef& x : table)
        if (x.name == m.name) d = &x;
      ASSERT_NE(d, nullptr) << m.name;
      EXPECT_EQ(d->unit, m.unit);
    });
  }
}
