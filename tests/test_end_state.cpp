// The end-state metrics (methods/metrics/sample_metrics.hpp): end_qd_max and end_kinetic_energy of a run equal
// max_i |qd_i| and qd^T M(q) qd / 2 recomputed from the run's stored last sample, with M(q) from
// Orocos KDL (an independent model of the same arm), in every trajectory loop: the closed-form 3R
// kernel (local and vertex_alpha runs), the fixed-size planar-chain loop, the general chain loop,
// and the path-global measure on the seed arm and on a chain; a global run ending at rest ends with
// zero joint rates.
#include <gtest/gtest.h>

#include <cmath>
#include <kdl/chaindynparam.hpp>
#include <numbers>

#include "kdl_arm.hpp"
#include "kdl_chain.hpp"
#include "methods/chain/trajectory.hpp"
#include "methods/path_global/solve_closed_form.hpp"
#include "methods/path_global/chain.hpp"
#include "methods/metrics/sample_metrics.hpp"
#include "methods/closed_form/seed_cases.hpp"
#include "methods/base/trajectory.hpp"

using namespace ks;

namespace {

constexpr int kQdMax = sample_metric_index("end_qd_max");
constexpr int kKinetic = sample_metric_index("end_kinetic_energy");
static_assert(kQdMax >= 0 && kKinetic >= 0);

/// qd^T M(q) qd / 2 with M from KDL's ChainDynParam (no gravity needed for M) [J].
double kdl_kinetic_energy(const KDL::Chain& chain, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  KDL::ChainDynParam param(chain, KDL::Vector(0, -9.81, 0));
  const int n = static_cast<int>(q.size());
  KDL::JntArray kq(n);
  for (int j = 0; j < n; ++j) kq(j) = q[j];
  KDL::JntSpaceInertiaMatrix M(n);
  EXPECT_GE(param.JntToMass(kq, M), 0);
  double e = 0;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) e += qd[a] * M(a, b) * qd[b];
  return 0.5 * e;
}

/// Checks a run's end metrics against its history's last column (the last sample computed is always
/// stored). The kinetic energy: relative 1e-12 (the closed forms agree with KDL to about 1e-13) plus
/// an absolute 1e-12 J for a run ending near rest.
template <class History>
void expect_end_state(const TrajectoryMetrics& m, const History& h, const KDL::Chain& kdl) {
  ASSERT_GT(h.size, 0);
  const Eigen::Index last = h.size - 1;
  const Eigen::VectorXd q = h.q.col(last), qd = h.qd.col(last);
  EXPECT_EQ(m.sampled[kQdMax], qd.cwiseAbs().maxCoeff());
  const double ke = kdl_kinetic_energy(kdl, q, qd);
  EXPECT_NEAR(m.sampled[kKinetic], ke, 1e-12 * ke + 1e-12);
  EXPECT_GE(m.sampled[kKinetic], 0.0);
}

}  // namespace

// The closed-form 3R loop: every seed case (local weighted / unweighted, vertex_alpha), and RK4.
TEST(EndState, ClosedForm3RMatchesKdlAtTheLastSample) {
  const Path2 square = seed_square();
  const PlanarArm3 arm = PlanarArm3::seed();
  const KDL::Chain kdl = test::kdl_chain(arm);
  for (const SeedCase& c : seed_cases()) {
    for (Integrator integrator : {Integrator::semi_implicit_euler, Integrator::rk4}) {
      SCOPED_TRACE(std::string(c.name) + " " + std::string(to_string(integrator)));
      TrajectoryOptions o = c.options();
      o.integrator = integrator;
      TrajectoryHistory h;
      h.stride = 100;
      const TrajectoryMetrics m = simulate(arm, square, o, &h);
      ASSERT_EQ(m.samples, 2001u);
      expect_end_state(m, h, kdl);
      EXPECT_GT(m.sampled[kQdMax], 0.0);  // open-loop local runs end moving in their self-motion
    }
  }
}

// A run that stops early (diverged: a torque bound below its peak torque) reports the state of its
// last computed sample.
TEST(EndState, RunStoppedEarlyReportsItsLastSample) {
  const PlanarArm3 arm = PlanarArm3::seed();
  TrajectoryOptions o;
  o.alpha1A = -20.0 * std::numbers::pi / 180.0;
  const TrajectoryMetrics whole = simulate(arm, seed_square(), o);
  o.torque_bound = 0.95 * whole.tau_inf.maxCoeff();
  TrajectoryHistory h;
  const TrajectoryMetrics m = simulate(arm, seed_square(), o, &h);
  ASSERT_EQ(m.status, RunStatus::diverged);
  ASSERT_GT(m.samples, 1u);
  ASSERT_LT(m.samples, 2001u);
  expect_end_state(m, h, test::kdl_chain(arm));
}

// The chain loops: a planar 5R (the fixed-size planar loop) and an RPR chain with a prismatic joint
// (the general loop), position and pose tasks.
TEST(EndState, ChainLoopsMatchKdlAtTheLastSample) {
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
      h.stride = 250;
      const TrajectoryMetrics m = simulate(*chain, ChainTask(space, path, o.dt), planar_start_guess(chain->dof()), o, &h);
      ASSERT_GT(m.samples, 0u);
      expect_end_state(m, h, test::kdl_chain(*chain));
    }
}

// Path-global runs: the measure of the optimum on the seed arm (closed form) and on a planar 4R chain,
// free at the end and at rest (where the end rates are zero up to rounding).
TEST(EndState, PathGlobalRunsMatchKdlAndEndAtRestWhenAsked) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const SampledPath path(seed_square(), 2e-3);
  const Chain r4 = planar_chain(planar_bars({1, 1, 0.5, 0.5}, {5, 2, 0.5, 0.5}, 0.1));
  const ChainTask task(TaskSpace::planar_position, seed_square(), 2e-3);
  for (EndState end : {EndState::free, EndState::rest}) {
    SCOPED_TRACE(static_cast<int>(end));
    TrajectoryOptions o;
    o.method = TrajectoryMethod::global_spline;
    o.dt = 2e-3;
    o.alpha1A = -20.0 * std::numbers::pi / 180.0;
    o.global.knots = 8;
    o.global.end = end;
    o.global.max_evaluations = 15;  // the measure at the best point so far: enough for the check
    TrajectoryHistory h;
    h.stride = 50;
    const TrajectoryMetrics m = solve_global_spline(arm, path, o, &h);
    ASSERT_GT(m.samples, 0u);
    expect_end_state(m, h, test::kdl_chain(arm));
    ChainHistory hc;
    hc.stride = 50;
    o.alpha1A = 4.0 * std::numbers::pi / 180.0;
    const TrajectoryMetrics mc = solve_global_spline_chain(r4, task, planar_start_guess(4), o, &hc);
    ASSERT_GT(mc.samples, 0u);
    expect_end_state(mc, hc, test::kdl_chain(r4));
    if (end == EndState::rest) {
      // alpha'(T) = 0 and the path at rest: qd = J3^-1 (0, 0, 0) up to the rounding of the spline's
      // end derivative (a sum of coefficients of order 1 rad times 1/dt-sized weights)
      EXPECT_LT(m.sampled[kQdMax], 1e-9);
      EXPECT_LT(mc.sampled[kQdMax], 1e-9);
    }
  }
}
