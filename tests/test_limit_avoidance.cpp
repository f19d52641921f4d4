// Joint position limits in the redundancy resolution: the start solve that places the tip on the
// first vertex within the robot's limits, and the null-space limit spring K_L (q - q_mid) of the
// local methods. Oracles: Orocos KDL's forward kinematics (the start is on the target), the URDF's
// limits as written, the null-space property J dqdd = 0 of the spring's contribution, and a joint
// written with its axis reversed and its limits mirrored (the same arm: every metric equal).
#include <gtest/gtest.h>

#include <kdl/chainfksolverpos_recursive.hpp>

#include <cmath>
#include <random>

#include "kdl_chain.hpp"
#include "methods/chain/resolution.hpp"
#include "methods/chain/start.hpp"
#include "methods/chain/trajectory.hpp"
#include "methods/closed_form/seed_cases.hpp"
#include "model/chain_dynamics.hpp"
#include "robot/urdf.hpp"

using namespace ks;

namespace {

Chain arm7() {
  return load_urdf(std::string(KS_SOURCE_DIR) + "/studies/robots/arm7.urdf", "base_link", "tool", {0.0, 0.0, -9.81});
}

bool within(const Chain& c, const VecN& q) {
  for (int j = 0; j < c.dof(); ++j)
    if (!(q[j] >= c.joints[j].lower && q[j] <= c.joints[j].upper)) return false;
  return true;
}

/// The studies/arm7_square.toml square (0.2 m, vertical plane x = 0.5 m), `side` seconds per side.
Path3 arm7_square(double side) {
  const Eigen::Vector3d a(0.5, -0.1, 0.4), b(0.5, 0.1, 0.4), c(0.5, 0.1, 0.6), d(0.5, -0.1, 0.6);
  return Path3({a, b, c, d, a}, {side, side, side, side});
}

/// For 200 guesses uniform in [-r, r] per joint: the start solved without and with the limits (found
/// both or neither) and, when found, KDL's tip frame of the limit-aware one, given to check.
template <class Check>
void for_random_starts(const Chain& c, const StartTarget& t, double r, std::uint64_t seed, Check&& check) {
  const KDL::Chain k = test::kdl_chain(c);
  KDL::ChainFkSolverPos_recursive fk(k);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-r, r);
  StartSolveOptions plain;
  plain.respect_limits = false;
  for (int i = 0; i < 200; ++i) {
    VecN q0(c.dof());
    for (int j = 0; j < c.dof(); ++j) q0[j] = u(rng);
    const std::optional<VecN> a = solve_start(c, t, q0, plain);
    const std::optional<VecN> b = solve_start(c, t, q0);
    ASSERT_EQ(a.has_value(), b.has_value());
    if (!b) continue;
    KDL::Frame f;
    ASSERT_GE(fk.JntToCart(test::kdl_array(*b), f), 0);
    check(q0, *a, *b, f);
  }
}

}  // namespace

// From random guesses the start solve ends on the target (KDL's forward kinematics, 1e-12 m) and
// within the URDF's limits wherever it returns; the plain solve (respect_limits = false) from the
// same guesses ends outside them for many, and a solution the plain solve finds within the limits
// is returned unchanged (bitwise).
TEST(LimitAwareStart, StartsOnTheTargetWithinTheLimits) {
  const Chain c = arm7();
  StartTarget t;
  t.planar = false;
  t.position = {0.5, -0.1, 0.4};
  int outside_plain = 0, found = 0, unchanged = 0;
  for_random_starts(c, t, 3.0, 20261203, [&](const VecN& q0, const VecN& a, const VecN& b, const KDL::Frame& f) {
    EXPECT_LT((Eigen::Vector3d(f.p.x(), f.p.y(), f.p.z()) - t.position).norm(), 1e-12);
    ++found;
    if (within(c, a)) {
      EXPECT_EQ(a, b);
      ++unchanged;
    } else {
      ++outside_plain;
    }
    EXPECT_TRUE(within(c, b)) << b.transpose() << " | plain " << a.transpose() << " | q0 " << q0.transpose();
  });
  EXPECT_GT(found, 150);
  EXPECT_GT(outside_plain, 50);  // the limits matter from these guesses
  EXPECT_GT(unchanged, 5);
}

// A planar target's angle row counts turns (a 2 pi shift is not the same start there): from random
// guesses every start returned puts the tip on the point (1e-12 m) with the joint sum equal to the
// target angle (1e-12 rad, unwrapped), within the limits whenever the plain solve's was not but
// a start within them was found.
TEST(LimitAwareStart, PlanarStartsStayOnTheTargetAngle) {
  Chain c = planar_chain(planar_bars({1.0, 0.5, 0.5, 0.5, 0.5}, {5, 1, 1, 0.5, 0.5}, 0.1));
  for (ChainJoint& j : c.joints) j.lower = -2.0, j.upper = 2.0;
  c.prepare();
  StartTarget t;
  t.position = {1.5, 1.2, 0.0};
  t.angle = 0.4;
  int moved = 0;
  for_random_starts(c, t, 6.0, 99, [&](const VecN&, const VecN& a, const VecN& b, const KDL::Frame& f) {
    EXPECT_LT(std::hypot(f.p.x() - 1.5, f.p.y() - 1.2), 1e-12);
    EXPECT_LT(std::abs(b.sum() - t.angle), 1e-12) << b.transpose();
    if (!within(c, a) && within(c, b)) ++moved;
  });
  EXPECT_GT(moved, 10);
}

// The spring's contribution to qdd lies in the null space of the task Jacobian: with and without
// it, J qdd = b (the task is unaffected), and it changes qdd.
TEST(LimitSpring, ActsInTheNullSpaceOnly) {
  const Chain c = arm7();
  ChainData data;
  ChainState st;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    VecN q(7), qd(7), w(7), g(7);
    for (int j = 0; j < 7; ++j) q[j] = 2.0 * u(rng), qd[j] = u(rng), w[j] = 5.0 * u(rng);
    evaluate_dynamics(c, data, q, qd, st);
    TaskJacobian<3> J = st.J.topRows(3);
    const TaskVec<3> b(u(rng), u(rng), u(rng));
    InertiaFactor Mf;
    Mf.compute(st.M, 7);
    for (int j = 0; j < 7; ++j) g[j] = st.c[j] + 0.5 * st.g[j];
    for (const Weighting wt : {Weighting::inertia, Weighting::inertia_squared}) {
      const VecN a = local_acceleration<3>(wt, Mf, J, b, g, 2.0, qd);
      const VecN s = local_acceleration<3>(wt, Mf, J, b, g, 2.0, qd, w.data());
      EXPECT_LT((J * a - b).norm(), 1e-10);
      EXPECT_LT((J * s - b).norm(), 1e-10);
      EXPECT_GT((s - a).norm(), 1e-3);
    }
  }
}

// On the 7-DOF arm's square (2 s per side, K_N = 20, k = 0): without the spring a joint leaves its
// position limit; with K_L = 8 every position, velocity and effort stays within the URDF's limits,
// the run is ok, and the tip still follows the path (RK4, open loop). The general chain loop.
TEST(LimitSpring, KeepsTheSevenJointArmWithinItsLimits) {
  const Chain c = arm7();
  TrajectoryOptions o;
  o.method = TrajectoryMethod::local_weighted;
  o.integrator = Integrator::rk4;
  o.null_damping = 20.0;
  o.k = 0.25;
  const ChainTask task(TaskSpace::spatial_position, arm7_square(2.0), o.dt);
  const VecN q0 = VecN::Constant(7, 0.3);  // the engine's automatic guess for this arm
  const TrajectoryMetrics free = simulate(c, task, q0, o);
  o.limit_centring = 8.0;
  ChainHistory h;
  const TrajectoryMetrics sprung = simulate(c, task, q0, o, &h);
  EXPECT_GT(free.max_q_limit_ratio, 1.0);
  EXPECT_EQ(free.status, RunStatus::out_of_limits);
  EXPECT_EQ(sprung.status, RunStatus::ok);
  EXPECT_LT(sprung.max_tracking_error, 1e-6);
  for (Eigen::Index col = 0; col < h.size; ++col)
    for (int j = 0; j < 7; ++j) {
      EXPECT_GE(h.q(j, col), c.joints[j].lower);
      EXPECT_LE(h.q(j, col), c.joints[j].upper);
      EXPECT_LE(std::abs(h.qd(j, col)), c.joints[j].velocity);
      EXPECT_LE(std::abs(h.tau(j, col)), c.joints[j].effort);
    }
}

// The fixed-size planar loop keeps its joints in coordinates u = sigma q: a planar 5R with one joint
// written about -z with its limits mirrored is the same arm, and with the spring acting every metric
// agrees with the +z version (the limits' middle is off zero: a spring centred in the wrong
// coordinates would pull the two arms to different places).
TEST(LimitSpring, PlanarLoopCentresInTheChainsCoordinates) {
  Chain a = planar_chain(planar_bars({1.0, 0.5, 0.5, 0.5, 0.5}, {5, 1, 1, 0.5, 0.5}, 0.1));
  const double lower[5] = {-1.0, -0.5, -2.6, -0.2, -2.0}, upper[5] = {2.0, 2.5, 0.6, 2.4, 1.5};
  for (int j = 0; j < 5; ++j) a.joints[j].lower = lower[j], a.joints[j].upper = upper[j];
  a.prepare();
  Chain b = a;
  b.joints[2].axis = -b.joints[2].axis;
  b.joints[2].lower = -upper[2], b.joints[2].upper = -lower[2];
  b.prepare();
  TrajectoryOptions o;
  o.method = TrajectoryMethod::local_weighted;
  o.alpha1A = 0.2;
  o.null_damping = 10.0;
  o.on_violation = OnViolation::ignore;
  const ChainTask task(TaskSpace::planar_position, seed_square(), o.dt);
  const VecN qa = planar_start_guess(5);
  VecN qb = qa;
  qb[2] = -qb[2];
  const TrajectoryMetrics free = simulate(a, task, qa, o);
  o.limit_centring = 10.0;
  const TrajectoryMetrics ma = simulate(a, task, qa, o), mb = simulate(b, task, qb, o);
  ASSERT_EQ(ma.status, RunStatus::ok);
  ASSERT_EQ(mb.status, RunStatus::ok);
  EXPECT_NEAR(ma.E, mb.E, 1e-9 * ma.E);
  EXPECT_NEAR(ma.max_q_limit_ratio, mb.max_q_limit_ratio, 1e-9);
  EXPECT_NEAR(ma.max_tracking_error, mb.max_tracking_error, 1e-9);
  EXPECT_GT(std::abs(ma.E - free.E), 1e-3 * free.E);  // the spring acts
}
