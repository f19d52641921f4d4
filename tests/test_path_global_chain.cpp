// The path-global method on planar chains: the construction reproduces a configuration from its
// coordinates; on the seed's arm as a chain it agrees with the closed-form evaluator; its gradient
// matches finite differences; on a 4R and a 5R arm it ends on its path below the local runs.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "methods/alpha_basis.hpp"
#include "methods/chain_start.hpp"
#include "methods/global_spline.hpp"
#include "methods/path_global.hpp"
#include "methods/path_global_chain.hpp"

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
      ChainGlobalProblem(chain, task, Extension::alpha, Elbow::positive).coordinates_of(0, q, z, elbow);
      const ChainGlobalProblem problem(chain, task, ext, elbow);
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
