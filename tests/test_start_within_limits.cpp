// The start solve (methods/chain/start.hpp) prefers a start within the joint limits when one with the
// same tip pose exists: on planar 4R and 5R arms with asymmetric limits, every target is the tip
// pose of a configuration drawn within the limits (so such a start exists by construction), and the
// start found from the default guess must be within the limits and on the target.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "methods/chain/resolution.hpp"
#include "methods/chain/start.hpp"
#include "model/chain_kinematics.hpp"

using namespace ks;

namespace {

struct Limits {
  double lower, upper;
};

Chain limited_arm(const std::vector<double>& l, const std::vector<Limits>& limits) {
  std::vector<double> m(l.size(), 1.0);
  std::vector<PlanarLink> links = planar_bars(l, m, 0.05);
  for (std::size_t i = 0; i < links.size(); ++i) links[i].lower = limits[i].lower, links[i].upper = limits[i].upper;
  return planar_chain(links);
}

bool within(const Chain& c, const VecN& q) {
  for (int j = 0; j < c.dof(); ++j)
    if (q[j] < c.joints[static_cast<std::size_t>(j)].lower || q[j] > c.joints[static_cast<std::size_t>(j)].upper)
      return false;
  return true;
}

/// Targets: the tip poses of `count` configurations drawn uniformly within the limits.
void check_arm(const Chain& chain, int count, unsigned seed) {
  std::mt19937 rng(seed);
  const PlanarAngle angle(chain);
  ChainData data;
  int outside = 0, failed = 0;
  for (int k = 0; k < count; ++k) {
    VecN q_star(chain.dof());
    for (int j = 0; j < chain.dof(); ++j) {
      const ChainJoint& J = chain.joints[static_cast<std::size_t>(j)];
      q_star[j] = std::uniform_real_distribution<double>(J.lower, J.upper)(rng);
    }
    forward_kinematics(chain, data, q_star);
    StartTarget t;
    t.position = data.tip.p;
    t.angle = angle(q_star);
    const std::optional<VecN> q = solve_start(chain, t, planar_start_guess(chain.dof()));
    if (!q) {
      ++failed;
      continue;
    }
    forward_kinematics(chain, data, *q);
    EXPECT_NEAR((data.tip.p - t.position).head<2>().norm(), 0.0, 1e-12) << "target " << k;
    EXPECT_NEAR(angle(*q), t.angle, 1e-12) << "target " << k;
    if (!within(chain, *q)) ++outside;
  }
  EXPECT_EQ(failed, 0);
  EXPECT_EQ(outside, 0) << "of " << count << " targets, each with a start within the limits";
}

}  // namespace

TEST(StartWithinLimits, PlanarFourRWithAsymmetricLimits) {
  const Chain arm = limited_arm({0.8, 0.7, 0.5, 0.4}, {{-1.0, 2.5}, {-2.6, 2.6}, {-2.0, 1.2}, {-1.6, 2.4}});
  check_arm(arm, 88, 44);
}

TEST(StartWithinLimits, PlanarFourRWithNarrowOneSidedRanges) {
  // elbows that bend one way only: the default guess's branch is often the other one
  const Chain arm = limited_arm({1.0, 0.8, 0.6, 0.3}, {{-0.5, 1.5}, {-2.5, -0.3}, {0.2, 2.2}, {-1.5, 0.5}});
  check_arm(arm, 60, 7);
}

TEST(StartWithinLimits, PlanarFiveR) {
  const Chain arm = limited_arm({0.6, 0.5, 0.5, 0.4, 0.3},
                                {{-0.8, 2.0}, {0.1, 2.4}, {-2.2, -0.2}, {-1.0, 1.8}, {-1.2, 0.6}});
  check_arm(arm, 60, 11);
}

TEST(StartWithinLimits, SolutionWithinTheLimitsIsKeptAsFound) {
  // a target whose first solution is within the limits: the restarts change nothing
  const Chain arm = limited_arm({0.8, 0.7, 0.5, 0.4}, {{-1.0, 2.5}, {-2.6, 2.6}, {-2.0, 1.2}, {-1.6, 2.4}});
  ChainData data;
  const VecN guess = planar_start_guess(4);
  forward_kinematics(arm, data, guess);
  StartTarget t;
  t.position = data.tip.p;
  t.angle = PlanarAngle(arm)(guess);
  StartSolveOptions none;
  none.restarts = 0;
  const std::optional<VecN> a = solve_start(arm, t, guess), b = solve_start(arm, t, guess, none);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(*a, *b);
}
