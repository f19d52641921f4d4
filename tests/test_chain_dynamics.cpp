// Chain dynamics (model/chain_dynamics.hpp) against Orocos KDL (ChainDynParam, ChainIdSolver_RNE),
// the closed-form planar 3R dynamics, and against itself (one pass vs the separate algorithms,
// the planar specialisation vs the spatial algorithms).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <atomic>
#include <cstdlib>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <new>

#include "chain_fixtures.hpp"
#include "kdl_chain.hpp"
#include "model/chain_dynamics.hpp"
#include "model/dynamics.hpp"
#include "robot/urdf.hpp"

// Counts global operator new calls while `counting` is set (the per-call no-allocation check).
namespace {
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
}  // namespace
void* operator new(std::size_t size) {
  if (counting) ++allocations;
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

using namespace ks;

namespace {

Chain planar4r() {
  return planar_chain(planar_bars({0.8, 0.8, 0.7, 0.5}, {3.2, 3.2, 2.8, 2.0}, 0.05), 9.81, "planar4r");
}

Chain seed_chain() { return planar_chain(planar_bars({1, 1, 1}, {5, 2, 1}, 0.1), 9.81, "seed"); }

// A planar chain beyond planar_chain: origins rotated about z, a joint about -z, a prismatic joint
// in the plane, centres of mass off the links (and off the plane), inertias with xz and yz products
// (which act out of the plane only), gravity oblique in the plane.
Chain planar_mixed() {
  Chain c = planar4r();
  c.name = "planar_mixed";
  c.joints[1].origin.R = test::rpy(0, 0, 0.4);
  c.joints[1].axis = -Eigen::Vector3d::UnitZ();
  c.joints[2].type = JointType::prismatic;
  c.joints[2].axis = Eigen::Vector3d(0.6, 0.8, 0.0);
  c.joints[2].origin.R = test::rpy(0, 0, -1.1);
  c.joints[3].origin.p.y() = 0.2;
  c.joints[0].com = Eigen::Vector3d(0.3, 0.05, 0.02);
  c.joints[3].com = Eigen::Vector3d(0.2, -0.04, -0.03);
  c.joints[1].inertia(0, 2) = c.joints[1].inertia(2, 0) = 0.01;
  c.joints[3].inertia(1, 2) = c.joints[3].inertia(2, 1) = -0.005;
  c.tip.R = test::rpy(0, 0, 0.7);
  c.tip.p = Eigen::Vector3d(0.5, 0.1, 0.0);
  c.gravity = Eigen::Vector3d(3.0, -9.0, 0.0);
  c.prepare();
  return c;
}

Chain arm7() {
  return load_urdf(KS_SOURCE_DIR "/studies/robots/arm7.urdf", "base_link", "tool", Eigen::Vector3d(0, 0, -9.81));
}

Chain spatial_copy(Chain c) {
  c.planar_fast_path = false;
  return c;
}

template <class A, class B>
double relative_error(const A& ours, const B& oracle) {
  return (ours - oracle).norm() / (oracle.norm() + 1e-12);
}

struct KdlOracle {
  KDL::Chain chain;
  KDL::ChainDynParam param;
  KDL::ChainIdSolver_RNE rne;
  explicit KdlOracle(const Chain& c)
      : chain(test::kdl_chain(c)), param(chain, test::kdl_vector(c.gravity)), rne(chain, test::kdl_vector(c.gravity)) {}
};

// Worst relative errors of M, c, g and tau against KDL over 1,000 random states.
void expect_matches_kdl(const Chain& c) {
  KdlOracle k(c);
  const int n = c.dof();
  ASSERT_EQ(static_cast<int>(k.chain.getNrOfJoints()), n);
  test::RandomJoints r;
  double worst_M = 0, worst_c = 0, worst_g = 0, worst_tau = 0;
  for (int s = 0; s < 1000; ++s) {
    const VecN q = r.q(n), qd = r.v(n), qdd = r.a(n);
    const KDL::JntArray kq = test::kdl_array(q), kqd = test::kdl_array(qd), kqdd = test::kdl_array(qdd);
    ChainData d;
    MatN M;
    VecN cor, g, tau;
    crba(c, d, q, M);
    coriolis_torques(c, d, q, qd, cor);
    gravity_torques(c, d, q, g);
    rnea(c, d, q, qd, qdd, tau);
    KDL::JntSpaceInertiaMatrix kM(n);
    KDL::JntArray kc(n), kg(n), ktau(n);
    KDL::Wrenches f_ext(k.chain.getNrOfSegments(), KDL::Wrench::Zero());
    ASSERT_GE(k.param.JntToMass(kq, kM), 0);
    ASSERT_GE(k.param.JntToCoriolis(kq, kqd, kc), 0);
    ASSERT_GE(k.param.JntToGravity(kq, kg), 0);
    ASSERT_GE(k.rne.CartToJnt(kq, kqd, kqdd, f_ext, ktau), 0);
    worst_M = std::max(worst_M, relative_error(M, test::from_kdl(kM)));
    worst_c = std::max(worst_c, relative_error(cor, test::from_kdl(kc)));
    worst_g = std::max(worst_g, relative_error(g, test::from_kdl(kg)));
    worst_tau = std::max(worst_tau, relative_error(tau, test::from_kdl(ktau)));
  }
  EXPECT_LT(worst_M, 1e-9) << c.name;
  EXPECT_LT(worst_c, 1e-9) << c.name;
  EXPECT_LT(worst_g, 1e-9) << c.name;
  EXPECT_LT(worst_tau, 1e-9) << c.name;
}

std::vector<Chain> all_chains() { return {planar4r(), planar_mixed(), seed_chain(), test::test_chain_prismatic(), arm7()}; }

}  // namespace

TEST(ChainDynamics, Planar4RMatchesKdl) { expect_matches_kdl(planar4r()); }
TEST(ChainDynamics, PlanarMixedMatchesKdl) { expect_matches_kdl(planar_mixed()); }
TEST(ChainDynamics, Arm7MatchesKdl) { expect_matches_kdl(arm7()); }
TEST(ChainDynamics, PrismaticChainMatchesKdl) { expect_matches_kdl(test::test_chain_prismatic()); }
TEST(ChainDynamics, SpatialAlgorithmsOnPlanarChainMatchKdl) { expect_matches_kdl(spatial_copy(planar_mixed())); }

TEST(ChainDynamics, SeedChainEqualsClosedForm3R) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const DynamicsCoefficients dc(arm);
  for (const Chain& c : {seed_chain(), spatial_copy(seed_chain())}) {
    test::RandomJoints r;
    for (int s = 0; s < 1000; ++s) {
      const VecN q = r.q(3), qd = r.v(3), qdd = r.a(3);
      const Vec3 q3 = q, qd3 = qd, qdd3 = qdd;
      const JointTrig t = joint_trig(q3);
      ChainData d;
      ChainState st;
      evaluate_dynamics(c, d, q, qd, st);
      EXPECT_LT((st.M - mass_matrix(dc, t)).norm(), 1e-12);
      EXPECT_LT((st.c - coriolis(dc, t, qd3)).norm(), 1e-12);
      EXPECT_LT((st.g - gravity(dc, t)).norm(), 1e-12);
      VecN tau;
      rnea(c, d, q, qd, qdd, tau);
      EXPECT_LT((tau - inverse_dynamics(arm, q3, qd3, qdd3)).norm(), 1e-12);
    }
  }
}

TEST(ChainDynamics, EvaluateDynamicsEqualsSeparateFunctions) {
  for (const Chain& c : all_chains()) {
    test::RandomJoints r;
    for (int s = 0; s < 300; ++s) {
      const int n = c.dof();
      const VecN q = r.q(n), qd = r.v(n), qdd = r.a(n);
      ChainData d;
      ChainState st;
      evaluate_dynamics(c, d, q, qd, st);
      MatN M;
      VecN cor, g, tau;
      Mat6N J;
      crba(c, d, q, M);
      coriolis_torques(c, d, q, qd, cor);
      gravity_torques(c, d, q, g);
      rnea(c, d, q, qd, qdd, tau);
      const Vec6 bias = tip_bias_acceleration(c, d, q, qd);
      tip_jacobian(c, d, J);
      EXPECT_LT(relative_error(st.M, M), 1e-13) << c.name;
      EXPECT_LT(relative_error(st.c, cor), 1e-13) << c.name;
      EXPECT_LT(relative_error(st.g, g), 1e-13) << c.name;
      EXPECT_LT(relative_error(st.J, J), 1e-13) << c.name;
      EXPECT_LT(relative_error(st.bias, bias), 1e-13) << c.name;
      EXPECT_LT((st.tip.p - d.tip.p).norm() + (st.tip.R - d.tip.R).norm(), 1e-13) << c.name;
      EXPECT_LT(relative_error(VecN(st.M * qdd + st.c + st.g), tau), 1e-12) << c.name;
    }
  }
}

TEST(ChainDynamics, MassMatrixSymmetricPositiveDefinite) {
  for (const Chain& c : all_chains()) {
    test::RandomJoints r;
    for (int s = 0; s < 1000; ++s) {
      ChainData d;
      MatN M;
      crba(c, d, r.q(c.dof()), M);
      EXPECT_EQ((M - M.transpose()).norm(), 0.0);
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M).eigenvalues().minCoeff(), 0.0) << c.name;
    }
  }
}

TEST(ChainDynamics, PlanarSpecialisationEqualsSpatialAlgorithms) {
  for (const Chain& c : {planar4r(), planar_mixed(), seed_chain()}) {
    ASSERT_TRUE(c.planar_fast_path);
    const Chain s = spatial_copy(c);
    test::RandomJoints r;
    for (int k = 0; k < 1000; ++k) {
      const int n = c.dof();
      const VecN q = r.q(n), qd = r.v(n), qdd = r.a(n);
      ChainData d1, d2;
      ChainState a, b;
      evaluate_dynamics(c, d1, q, qd, a);
      evaluate_dynamics(s, d2, q, qd, b);
      EXPECT_LT(relative_error(a.M, b.M), 1e-13) << c.name;
      EXPECT_LT(relative_error(a.c, b.c), 1e-13) << c.name;
      EXPECT_LT(relative_error(a.g, b.g), 1e-13) << c.name;
      EXPECT_LT(relative_error(a.J, b.J), 1e-13) << c.name;
      EXPECT_LT(relative_error(a.bias, b.bias), 1e-13) << c.name;
      EXPECT_LT((a.tip.p - b.tip.p).norm() + (a.tip.R - b.tip.R).norm(), 1e-13) << c.name;
      forward_kinematics(c, d1, q);
      forward_kinematics(s, d2, q);
      for (int i = 0; i < n; ++i) {
        EXPECT_LT((d1.joint[i].p - d2.joint[i].p).norm() + (d1.joint[i].R - d2.joint[i].R).norm(), 1e-13);
        EXPECT_LT((d1.axis[i] - d2.axis[i]).norm(), 1e-13);
      }
      VecN t1, t2;
      rnea(c, d1, q, qd, qdd, t1);
      rnea(s, d2, q, qd, qdd, t2);
      EXPECT_LT(relative_error(t1, t2), 1e-13) << c.name;
    }
  }
}

TEST(ChainDynamics, NoHeapAllocationPerCall) {
  for (const Chain& c : all_chains()) {
    test::RandomJoints r;
    const int n = c.dof();
    const VecN q = r.q(n), qd = r.v(n), qdd = r.a(n);
    ChainData d;
    ChainState st;
    MatN M;
    VecN v;
    Mat6N J;
    counting = true;
    evaluate_dynamics(c, d, q, qd, st);
    rnea(c, d, q, qd, qdd, v);
    crba(c, d, q, M);
    gravity_torques(c, d, q, v);
    coriolis_torques(c, d, q, qd, v);
    forward_kinematics(c, d, q);
    tip_jacobian(c, d, J);
    tip_bias_acceleration(c, d, q, qd);
    counting = false;
    EXPECT_EQ(allocations.load(), 0) << c.name;
  }
}
