// The fixed-size planar chain kernel (model/planar_chain_dynamics.hpp) against the general chain
// dynamics (model/chain_dynamics.hpp, spatial and planar algorithms) on a planar chain with every
// planar feature (an axis along -z, rotated and offset joint origins, a centre of mass off the link
// line, a rotated tip); its carried trig against direct evaluation; the fixed-size LDL^T against
// Eigen's; and a run of that chain through simulate() against the RNEA and the path.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "methods/chain/trajectory.hpp"
#include "methods/base/fixed_ldlt.hpp"
#include "methods/closed_form/seed_cases.hpp"
#include "model/chain_dynamics.hpp"
#include "model/planar_chain_dynamics.hpp"

using namespace ks;

namespace {

Eigen::Matrix3d rot_z(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }

/// A planar 5R (links of 0.7 m) with joint 2 about -z, joint 3's origin turned by 0.3 rad and off
/// the link line, the base joint away from the origin, joint 4's centre of mass off its link line,
/// and the tip turned by -0.4 rad.
Chain twisted_5r() {
  Chain c = planar_chain(planar_bars({0.7, 0.7, 0.7, 0.7, 0.7}, {4, 3, 2, 1.5, 1}, 0.1));
  c.joints[0].origin.p = {0.1, -0.2, 0.0};
  c.joints[1].axis = -Eigen::Vector3d::UnitZ();
  c.joints[2].origin.R = rot_z(0.3);
  c.joints[2].origin.p = {0.7, 0.05, 0.0};
  c.joints[3].com = {0.3, 0.04, 0.0};
  c.tip.R = rot_z(-0.4);
  c.tip.p = {0.7, 0.03, 0.0};
  c.prepare();
  return c;
}

}  // namespace

// M, c, g, the tip rows of J and J̇ q̇ and the tip position equal the general algorithms' (mapped from
// the kernel's coordinates u = sigma q), on random states.
TEST(PlanarChainKernel, MatchesTheGeneralDynamics) {
  constexpr int N = 5;
  Chain chain = twisted_5r();
  ASSERT_TRUE(chain.IsValid());
  ASSERT_TRUE(planar_revolute(chain));
  const PlanarChainConstants<N> k(chain);
  EXPECT_EQ(k.sigma[1], -1.0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), rate(-2.0, 2.0);
  ChainData data;
  ChainState ref;
  for (bool planar_algebra : {true, false}) {
    chain.planar_fast_path = planar_algebra;
    for (int trial = 0; trial < 50; ++trial) {
      VecN q(N), qd(N);
      double u[N], ud[N];
      for (int i = 0; i < N; ++i) {
        q[i] = angle(rng);
        qd[i] = rate(rng);
        u[i] = k.sigma[i] * q[i];
        ud[i] = k.sigma[i] * qd[i];
      }
      evaluate_dynamics(chain, data, q, qd, ref);
      PlanarChainTrig<N> trig;
      trig.reset(k, u);
      PlanarChainState<N, 3> st;
      planar_chain_state<N, 3>(k, trig.s, trig.c, ud, st);
      const double tol = 1e-12;
      for (int i = 0; i < N; ++i) {
        const double si = k.sigma[i];
        for (int j = 0; j < N; ++j) EXPECT_NEAR(si * k.sigma[j] * st.M[i][j], ref.M(i, j), tol * (1 + std::abs(ref.M(i, j))));
        EXPECT_NEAR(si * st.c[i], ref.c[i], tol * (1 + std::abs(ref.c[i])));
        EXPECT_NEAR(si * st.g[i], ref.g[i], tol * (1 + std::abs(ref.g[i])));
        EXPECT_NEAR(si * st.J[0][i], ref.J(0, i), tol);
        EXPECT_NEAR(si * st.J[1][i], ref.J(1, i), tol);
        EXPECT_NEAR(si * st.J[2][i], ref.J(5, i), tol);
      }
      EXPECT_NEAR(st.bias[0], ref.bias[0], tol * (1 + std::abs(ref.bias[0])));
      EXPECT_NEAR(st.bias[1], ref.bias[1], tol * (1 + std::abs(ref.bias[1])));
      EXPECT_EQ(st.bias[2], 0.0);
      EXPECT_NEAR(ref.bias[5], 0.0, tol);
      EXPECT_NEAR(st.px, ref.tip.p.x(), tol);
      EXPECT_NEAR(st.py, ref.tip.p.y(), tol);
    }
  }
}

// The carried sines and cosines stay within 1e-14 of direct evaluation over a long run of small
// steps, and a step of 0.01 rad or more is evaluated directly.
TEST(PlanarChainKernel, CarriedTrigStaysOnDirectEvaluation) {
  constexpr int N = 5;
  const PlanarChainConstants<N> k(twisted_5r());
  double u[N] = {0.3, -1.2, 2.0, 0.7, -0.4}, du[N];
  PlanarChainTrig<N> carried, direct;
  carried.reset(k, u);
  double worst = 0;
  for (int step = 0; step < 5000; ++step) {
    for (int i = 0; i < N; ++i) {
      du[i] = 1e-3 * std::sin(0.01 * step + i);  // prefix sums stay below 0.01
      u[i] += du[i];
    }
    carried.advance(k, u, du);
    direct.reset(k, u);
    for (int i = 0; i < N; ++i)
      worst = std::max({worst, std::abs(carried.s[i] - direct.s[i]), std::abs(carried.c[i] - direct.c[i])});
  }
  EXPECT_LT(worst, 1e-14);
  du[0] = 0.02;
  u[0] += du[0];
  carried.advance(k, u, du);
  direct.reset(k, u);
  for (int i = 0; i < N; ++i) {
    EXPECT_EQ(carried.s[i], direct.s[i]);
    EXPECT_EQ(carried.c[i], direct.c[i]);
  }
}

// Solves and the quadratic form agree with Eigen's LDL^T; a matrix that is not positive definite
// gives NaN.
TEST(FixedLdlt, MatchesEigenAndFlagsIndefiniteMatrices) {
  constexpr int N = 6;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> v(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::Matrix<double, N, N> B;
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) B(i, j) = v(rng);
    const Eigen::Matrix<double, N, N> A = B * B.transpose() + 0.1 * Eigen::Matrix<double, N, N>::Identity();
    double a[N][N];
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) a[i][j] = A(i, j);
    FixedLdlt<N> f;
    f.compute(a);
    Eigen::Matrix<double, N, 1> b;
    for (int i = 0; i < N; ++i) b[i] = v(rng);
    const Eigen::Matrix<double, N, 1> want = A.ldlt().solve(b);
    double x[N], z[N];
    for (int i = 0; i < N; ++i) x[i] = z[i] = b[i];
    f.solve(x);
    for (int i = 0; i < N; ++i) EXPECT_NEAR(x[i], want[i], 1e-10 * (1 + want.norm()));
    EXPECT_NEAR(f.inverse_quadratic_form(z), b.dot(want), 1e-10 * (1 + std::abs(b.dot(want))));
  }
  double indefinite[2][2] = {{1.0, 2.0}, {2.0, 1.0}};
  FixedLdlt<2> f;
  f.compute(indefinite);
  double x[2] = {1.0, 1.0};
  f.solve(x);
  EXPECT_TRUE(std::isnan(x[0]) && std::isnan(x[1]));
}

// A run of the twisted chain (planar_pose, local_weighted, RK4, K_N > 0): the history's torques are
// the RNEA's, its tip positions the path's to the open-loop drift, and mirroring joint 2's axis
// (with q0's sign) mirrors q, qd, qdd and tau and leaves the metrics unchanged.
TEST(PlanarChainKernel, RunObeysTheDynamicsAndMirrorsWithAnAxis) {
  const Chain chain = twisted_5r();
  Chain mirrored = chain;
  mirrored.joints[1].axis = Eigen::Vector3d::UnitZ();
  mirrored.prepare();
  TrajectoryOptions o;
  o.integrator = Integrator::rk4;
  o.alpha1A = 0.2;
  o.vertex_alpha = {0.5, 0.3, 0.0, 0.2};
  o.null_damping = 1.0;
  const Path2 square({Vec2(1.4, 0.9), Vec2(1.8, 0.9), Vec2(1.8, 1.3), Vec2(1.4, 1.3), Vec2(1.4, 0.9)}, {0.5, 0.5, 0.5, 0.5});
  const ChainTask task(TaskSpace::planar_pose, square, o.dt);
  VecN q0 = planar_start_guess(5), q0m = q0;
  q0m[1] = -q0m[1];
  ChainHistory h, hm;
  h.stride = hm.stride = 50;
  const TrajectoryMetrics m = simulate(chain, task, q0, o, &h);
  const TrajectoryMetrics mm = simulate(mirrored, task, q0m, o, &hm);
  ASSERT_EQ(m.status, RunStatus::ok);
  ASSERT_EQ(mm.status, RunStatus::ok);
  EXPECT_LT(m.max_tracking_error, 1e-6);
  ChainData data;
  for (Eigen::Index c = 0; c < h.size; ++c) {
    const VecN q = h.q.col(c), qd = h.qd.col(c), qdd = h.qdd.col(c);
    VecN tau;
    rnea(chain, data, q, qd, qdd, tau);
    EXPECT_LT((tau - VecN(h.tau.col(c))).norm(), 1e-9 * (1 + tau.norm())) << c;
  }
  ASSERT_EQ(hm.size, h.size);
  Eigen::VectorXd flip = Eigen::VectorXd::Ones(5);
  flip[1] = -1.0;
  const double tol = 1e-10;
  EXPECT_LT((hm.q.leftCols(h.size) - flip.asDiagonal() * h.q.leftCols(h.size)).cwiseAbs().maxCoeff(), tol);
  EXPECT_LT((hm.qd.leftCols(h.size) - flip.asDiagonal() * h.qd.leftCols(h.size)).cwiseAbs().maxCoeff(), tol);
  EXPECT_LT((hm.qdd.leftCols(h.size) - flip.asDiagonal() * h.qdd.leftCols(h.size)).cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_LT((hm.tau.leftCols(h.size) - flip.asDiagonal() * h.tau.leftCols(h.size)).cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_NEAR(mm.E, m.E, 1e-10 * m.E);
  EXPECT_NEAR(mm.E_M, m.E_M, 1e-10 * m.E_M);
  EXPECT_NEAR(mm.final_alpha, m.final_alpha, 1e-12);
}
