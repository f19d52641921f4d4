// The path-global method with joint coordinates (any chain): the joint path is on the task path and
// its rates and accelerations are its time derivatives (central differences in time); the objective's
// gradient, the limit constraints' Jacobian and the limits' penalty's gradient match finite
// differences; the 7-DOF arm's global run
// is on its path, within its limits and below its local run; a limit the unconstrained optimum
// crosses is kept by the constrained one; the KKT residual is the non-negative least-squares optimum.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <Eigen/QR>

#include "methods/path_global/alpha_basis.hpp"
#include "methods/chain/start.hpp"
#include "methods/chain/trajectory.hpp"
#include "methods/path_global/slsqp.hpp"
#include "methods/path_global/joint_chart.hpp"
#include "robot/urdf.hpp"
#include "widest_raise.hpp"

using namespace ks;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

Chain arm7() {
  return load_urdf(std::string(KS_SOURCE_DIR) + "/studies/robots/arm7.urdf", "base_link", "tool", {0.0, 0.0, -9.81});
}

/// The first `sides` sides of studies/arm7_square.toml's square (2 s each).
Path3 arm7_path(int sides) {
  const std::vector<Eigen::Vector3d> v{{0.5, -0.1, 0.4}, {0.5, 0.1, 0.4}, {0.5, 0.1, 0.6}, {0.5, -0.1, 0.6}, {0.5, -0.1, 0.4}};
  return Path3(std::vector<Eigen::Vector3d>(v.begin(), v.begin() + sides + 1), std::vector<double>(sides, 2.0));
}

/// arm7_square's best start posture: q0_3 = 60 deg, q0_4 = -90 deg, the others the runner's automatic 0.3 rad.
VecN arm7_guess() {
  VecN q0 = VecN::Constant(7, 0.3);
  q0[2] = 60 * kDeg, q0[3] = -90 * kDeg;
  return q0;
}

/// The start configuration on the path's first vertex from guess q0.
VecN start_on(const Chain& chain, const ChainTask& task, const VecN& q0) {
  StartTarget t;
  t.position = task.path.path().vertices().front();
  t.planar = false;
  return *solve_start(chain, t, q0);
}

/// Coefficients near the start: coordinate k's value at the start plus a small smooth excursion.
std::vector<double> near_start(const JointExtensionProblem& p, const VecN& q, int K, double size) {
  std::vector<double> c(static_cast<std::size_t>(K) * p.coordinates());
  double z[kMaxJoints];
  Elbow e;
  p.coordinates_of(0, q, z, e);
  for (int k = 0; k < p.coordinates(); ++k)
    for (int j = 0; j < K; ++j) c[k * K + j] = z[k] + (j == 0 ? 0.0 : size * std::sin(1.0 + j + 2.0 * k));
  return c;
}

}  // namespace

/// The joint path of a fixed spline sampled at dt; the largest differences between qd (qdd) and the
/// central difference in time of q (qd).
struct TimeDerivativeErrors {
  double qd = 0, qdd = 0;
};
TimeDerivativeErrors joint_path(const Chain& chain, double dt, bool check_tau) {
  const ChainTask task(TaskSpace::spatial_position, arm7_path(2), dt);
  const VecN q = start_on(chain, task, arm7_guess());
  const JointExtensionProblem p(chain, task, {0, 1, 3}, q);
  EXPECT_EQ(p.coordinate_joints(), (std::vector<int>{2, 4, 5, 6}));
  const AlphaBasis b = cubic_spline_basis(task.path.size(), dt, 4.0, 6);
  const std::vector<double> c = near_start(p, q, 6, 0.2);
  const std::size_t n = p.samples();
  std::vector<ChainGlobalSample> s(n);
  double z[kMaxJoints][3];
  ChainData data;
  p.begin_pass();
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < p.coordinates(); ++k) b.at(i, c.data() + k * 6, z[k][0], z[k][1], z[k][2]);
    p.sample(i, z, s[i]);
    p.accept(i, z, s[i]);
    EXPECT_EQ(s[i].violation, 0.0) << i;
    forward_kinematics(chain, data, s[i].q);
    EXPECT_LT((data.tip.p - task.path.position(i)).norm(), 1e-12) << i;
  }
  EXPECT_LT((s[0].q - q).norm(), 1e-10);  // the start configuration: the coordinates are its joints
  if (check_tau) {  // tau: the chain's RNEA of the sample
    VecN tau;
    rnea(chain, data, s[n / 2].q, s[n / 2].qd, s[n / 2].qdd, tau);
    EXPECT_LT((tau - s[n / 2].tau).norm(), 1e-9 * tau.norm());
  }
  TimeDerivativeErrors e;
  for (std::size_t i = 1; i + 1 < n; ++i) {
    e.qd = std::max(e.qd, ((s[i + 1].q - s[i - 1].q) / (2 * dt) - s[i].qd).cwiseAbs().maxCoeff());
    e.qdd = std::max(e.qdd, ((s[i + 1].qd - s[i - 1].qd) / (2 * dt) - s[i].qdd).cwiseAbs().maxCoeff());
  }
  return e;
}

// The path's jerk and the spline's third derivative jump at vertices and knots, so a central
// difference is O(dt) there: halving dt halves the largest difference; a wrong rate or bias term
// would leave a difference that does not shrink.
TEST(PathGlobalJoints, TheJointPathIsOnThePathAndItsRatesAreItsTimeDerivatives) {
  const Chain chain = arm7();
  const TimeDerivativeErrors coarse = joint_path(chain, 1e-3, true), fine = joint_path(chain, 5e-4, false);
  std::printf("largest |qd - dq/dt|: %.3g, %.3g; |qdd - dqd/dt|: %.3g, %.3g (dt = 1, 0.5 ms)\n", coarse.qd, fine.qd,
              coarse.qdd, fine.qdd);
  EXPECT_LT(coarse.qd, 1e-4);
  EXPECT_LT(coarse.qdd, 1e-2);
  EXPECT_LT(fine.qd, 0.6 * coarse.qd);
  EXPECT_LT(fine.qdd, 0.6 * coarse.qdd);
}

/// The 7-DOF arm on the first side of its square at dt = 10 ms, joints 1, 2 and 4 solved, and
/// coefficients of K = 5 knots near its start: the problem the derivative tests evaluate.
class PathGlobalJointsDerivatives : public ::testing::Test {
 protected:
  static constexpr int K = 5;
  const Chain chain = arm7();
  const ChainTask task{TaskSpace::spatial_position, arm7_path(1), 1e-2};
  const VecN q = start_on(chain, task, arm7_guess());
  const JointExtensionProblem p{chain, task, {0, 1, 3}, q};
  const int size = K * p.coordinates();
  const AlphaBasis b = cubic_spline_basis(task.path.size(), 1e-2, 2.0, K);
  const std::vector<double> c = near_start(p, q, K, 0.1);
};

TEST_F(PathGlobalJointsDerivatives, GradientAndLimitJacobianMatchFiniteDifferences) {
  const LimitConstraints limits = LimitConstraints::of(chain, p.samples(), K);
  ASSERT_EQ(limits.count(), static_cast<unsigned>(K * 21));  // 7 joints x (position, velocity, effort)
  std::vector<double> grad(size), con(limits.count()), jac(limits.count() * static_cast<std::size_t>(size));
  p.objective(b, c.data(), GlobalObjective::E, grad.data(), &limits, con.data(), jac.data());
  const double h = 1e-6;
  for (int v = 0; v < size; ++v) {
    std::vector<double> up = c, down = c, con_up(con.size()), con_down(con.size());
    up[v] += h, down[v] -= h;
    const double fd = (p.objective(b, up.data(), GlobalObjective::E, nullptr, &limits, con_up.data()) -
                       p.objective(b, down.data(), GlobalObjective::E, nullptr, &limits, con_down.data())) / (2 * h);
    EXPECT_NEAR(grad[v], fd, 1e-5 * std::max(1.0, std::abs(fd))) << v;
    for (std::size_t row = 0; row < con.size(); ++row) {
      const double cd = (con_up[row] - con_down[row]) / (2 * h);
      EXPECT_NEAR(jac[row * size + v], cd, 1e-5 * std::max(1.0, std::abs(cd))) << "constraint " << row << ", variable " << v;
    }
  }
}

// The limits as a penalty (LimitConstraints::penalty): the objective gains penalty / N times the
// squared excess of every sample's ratios over 1 - margin; its gradient matches central differences.
// The margin is widened to 0.6 so that many samples and quantities are penalised.
TEST_F(PathGlobalJointsDerivatives, PenaltyGradientMatchesFiniteDifferences) {
  LimitConstraints penalty = LimitConstraints::of(chain, p.samples(), K);
  penalty.margin = 0.6;
  penalty.penalty = 50.0;
  std::vector<double> grad(size), plain(size);
  const double f = p.objective(b, c.data(), GlobalObjective::E, grad.data(), &penalty);
  const double e = p.objective(b, c.data(), GlobalObjective::E, plain.data());
  std::printf("E %.6f, with the penalty %.6f\n", e, f);
  ASSERT_GT(f - e, 0.01 * e);  // the penalty is active
  const double h = 1e-6;
  double differs = 0.0;  // the penalty's share of the gradient
  for (int v = 0; v < size; ++v) {
    std::vector<double> up = c, down = c;
    up[v] += h, down[v] -= h;
    const double fd = (p.objective(b, up.data(), GlobalObjective::E, nullptr, &penalty) -
                       p.objective(b, down.data(), GlobalObjective::E, nullptr, &penalty)) / (2 * h);
    EXPECT_NEAR(grad[v], fd, 1e-5 * std::max(1.0, std::abs(fd))) << v;
    differs = std::max(differs, std::abs(grad[v] - plain[v]));
  }
  EXPECT_GT(differs, 0.1);
}

// The first side of arm7_square's square from its best local run's start: the global run ends on its
// path, within every limit of the URDF, below the local run it starts from.
TEST(PathGlobalJoints, SevenDofArmBeatsItsLocalRunWithinItsLimits) {
  const Chain chain = arm7();
  TrajectoryOptions o;
  o.dt = 4e-3;
  o.integrator = Integrator::rk4;
  o.null_damping = 20;
  o.limit_centring = 8;
  const ChainTask task(TaskSpace::spatial_position, arm7_path(1), o.dt);
  o.method = TrajectoryMethod::local_weighted;
  const TrajectoryMetrics local = simulate(chain, task, arm7_guess(), o);
  ASSERT_EQ(local.status, RunStatus::ok);
  o.method = TrajectoryMethod::global_spline;
  o.global.extension = Extension::joints;
  o.global.start_method = StartMethod::local_weighted;
  o.global.knots = 6;
  const TrajectoryMetrics m = simulate(chain, task, arm7_guess(), o);
  // the unconstrained optimum leaves the limits; the penalty continuation ends within them
  // (test_path_global_limits_optimum checks such an end against another optimiser)
  ASSERT_EQ(m.status, RunStatus::ok) << to_string(m.status);
  EXPECT_LT(m.max_tracking_error, 1e-12);
  EXPECT_LE(m.max_q_limit_ratio, 1.0);
  EXPECT_LE(m.max_qd_limit_ratio, 1.0);
  EXPECT_LE(m.max_tau_limit_ratio, 1.0);
  EXPECT_LT(m.E, local.E);
  EXPECT_TRUE(m.opt_solved_joints >= 123 && m.opt_solved_joints <= 567) << m.opt_solved_joints;
  std::printf("arm7, one side: global %.4f Nm (%g evaluations, solved joints %g), local %.4f Nm\n", m.E,
              m.opt_evaluations, m.opt_solved_joints, local.E);
}

// A 4R planar arm one of whose joints gets a limit between the range its local run uses and the one
// the unconstrained global optimum uses: the constrained run keeps the limit, with a constraint active.
TEST(PathGlobalJoints, ALimitTheUnconstrainedOptimumCrossesIsKept) {
  Chain chain = planar_chain(planar_bars({1, 1, 0.5, 0.5}, {5, 2, 0.5, 0.5}, 0.1));
  const ChainTask task(TaskSpace::planar_position, seed_square(), 2e-3);
  TrajectoryOptions o;
  o.dt = 2e-3;
  o.alpha1A = 4 * kDeg;
  o.method = TrajectoryMethod::local_unweighted;
  ChainHistory local_h, free_h, kept_h;
  const TrajectoryMetrics local = simulate(chain, task, planar_start_guess(4), o, &local_h);
  ASSERT_EQ(local.status, RunStatus::ok);
  o.method = TrajectoryMethod::global_spline;
  o.global.extension = Extension::joints;
  o.global.knots = 8;
  const TrajectoryMetrics free = simulate(chain, task, planar_start_guess(4), o, &free_h);
  ASSERT_EQ(free.status, RunStatus::ok) << to_string(free.status) << " at " << free.stop_time << " s, E " << free.E;
  // the joint whose largest |q| the unconstrained optimum raises most above the local run's
  const auto [j, local_max, free_max] = widest_raise(local_h, free_h, 4);
  ASSERT_GT(free_max, local_max + 0.05) << "no limit between the two ranges";
  const double limit = 0.5 * (local_max + free_max);
  chain.joints[j].lower = -limit, chain.joints[j].upper = limit;
  const TrajectoryMetrics kept = simulate(chain, task, planar_start_guess(4), o, &kept_h);
  EXPECT_EQ(kept.status, RunStatus::ok);
  EXPECT_LE(kept_h.q.row(j).head(kept_h.size).cwiseAbs().maxCoeff(), limit);
  EXPECT_GE(kept.opt_active_limits, 1.0);
  std::printf("4R, |q%d| <= %.3f rad: constrained %.4f Nm (%g active), unconstrained %.4f Nm (|q| up to %.3f)\n", j + 1,
              limit, kept.E, kept.opt_active_limits, free.E, free_max);
}

// The KKT residual's non-negative least squares against an enumeration of the active sets: for every
// subset of the constraints, the least-squares multipliers when they are all non-negative; the best
// residual (2-norm) of those is the NNLS optimum.
TEST(PathGlobalJoints, KktResidualIsTheNonNegativeLeastSquaresOptimum) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> u;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 6, m = 1 + trial % 4;
    Eigen::MatrixXd J(m, n);
    for (int a = 0; a < m; ++a)
      for (int b = 0; b < n; ++b) J(a, b) = u(rng);
    Eigen::VectorXd g(n);
    for (int b = 0; b < n; ++b) g[b] = u(rng);
    if (trial % 3 == 0) {  // a stationary point: g = -J^T lambda with lambda >= 0
      Eigen::VectorXd lambda(m);
      for (int a = 0; a < m; ++a) lambda[a] = std::abs(u(rng));
      g = -J.transpose() * lambda;
    }
    double best2 = g.squaredNorm();
    Eigen::VectorXd best_r = g;
    for (unsigned mask = 1; mask < (1u << m); ++mask) {
      std::vector<int> S;
      for (int a = 0; a < m; ++a)
        if (mask & (1u << a)) S.push_back(a);
      Eigen::MatrixXd A(n, static_cast<Eigen::Index>(S.size()));
      for (std::size_t k = 0; k < S.size(); ++k) A.col(static_cast<Eigen::Index>(k)) = -J.row(S[k]).transpose();
      const Eigen::VectorXd l = A.colPivHouseholderQr().solve(g);
      if ((l.array() < 0).any()) continue;
      const Eigen::VectorXd r = g - A * l;
      if (r.squaredNorm() < best2) best2 = r.squaredNorm(), best_r = r;
    }
    std::vector<double> gv(g.data(), g.data() + n), jv(static_cast<std::size_t>(m * n));
    for (int a = 0; a < m; ++a)
      for (int b = 0; b < n; ++b) jv[static_cast<std::size_t>(a * n + b)] = J(a, b);
    const double kkt = kkt_residual(gv, jv, static_cast<std::size_t>(m));
    EXPECT_NEAR(kkt, best_r.cwiseAbs().maxCoeff(), 1e-9) << "trial " << trial;
    if (trial % 3 == 0) {
      EXPECT_LT(kkt, 1e-9) << "trial " << trial;
    }
  }
  EXPECT_EQ(kkt_residual({1.0, -3.0}, {}, 0), 3.0);  // no constraint: the gradient's norm
}
