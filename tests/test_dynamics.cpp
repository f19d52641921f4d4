// M, c, g of the planar 3R arm: properties, finite differences, and Orocos KDL's Newton-Euler as oracle.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>

#include "kdl_arm.hpp"
#include "model/dynamics.hpp"
#include "random_state.hpp"

using namespace ks;

TEST(Dynamics, SeedInertiasAreThoseOfTable2) {
  const PlanarArm3 a = PlanarArm3::seed();
  EXPECT_NEAR(a.I[0], 0.4208, 5e-5);
  EXPECT_NEAR(a.I[1], 0.1683, 5e-5);
  EXPECT_NEAR(a.I[2], 0.0842, 5e-5);
  EXPECT_DOUBLE_EQ(a.lc[1], 0.5);
}

TEST(Dynamics, MassMatrixSymmetricPositiveDefinite) {
  test::RandomStates r;
  for (auto form : {InertiaForm::physical, InertiaForm::thesis_m11}) {
    PlanarArm3 a = PlanarArm3::seed();
    a.inertia_form = form;
    for (int n = 0; n < 1000; ++n) {
      const Mat3 M = mass_matrix(a, joint_trig(r.q()));
      EXPECT_EQ((M - M.transpose()).norm(), 0.0);
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat3>(M).eigenvalues().minCoeff(), 0.0);
    }
  }
}

// c_i = sum_jk Gamma_ijk qd_j qd_k with Gamma_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2,
// derivatives of M by central differences.
TEST(Dynamics, CoriolisIsChristoffelFormOfM) {
  const PlanarArm3 a = PlanarArm3::seed();
  test::RandomStates r;
  const double h = 1e-6;
  for (int n = 0; n < 200; ++n) {
    const Vec3 q = r.q(), qd = r.v();
    std::array<Mat3, 3> dM;
    for (int k = 0; k < 3; ++k) {
      Vec3 qp = q, qm = q;
      qp[k] += h;
      qm[k] -= h;
      dM[k] = (mass_matrix(a, joint_trig(qp)) - mass_matrix(a, joint_trig(qm))) / (2 * h);
    }
    Vec3 c = Vec3::Zero();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) c[i] += 0.5 * (dM[k](i, j) + dM[j](i, k) - dM[i](j, k)) * qd[j] * qd[k];
    EXPECT_LT((coriolis(a, joint_trig(q), qd) - c).norm(), 1e-6 * (1 + c.norm()));
  }
}

TEST(Dynamics, GravityIsGradientOfPotential) {
  const PlanarArm3 a = PlanarArm3::seed();
  test::RandomStates r;
  const double h = 1e-6;
  for (int n = 0; n < 200; ++n) {
    const Vec3 q = r.q();
    Vec3 grad;
    for (int k = 0; k < 3; ++k) {
      Vec3 qp = q, qm = q;
      qp[k] += h;
      qm[k] -= h;
      grad[k] = (potential_energy(a, joint_trig(qp)) - potential_energy(a, joint_trig(qm))) / (2 * h);
    }
    EXPECT_LT((gravity(a, joint_trig(q)) - grad).norm(), 1e-6);
  }
}

TEST(Dynamics, InverseDynamicsMatchesKdlRecursiveNewtonEuler) {
  for (const PlanarArm3& a : {PlanarArm3::seed(), PlanarArm3::bars({0.7, 1.3, 0.4}, {3.0, 1.5, 0.8}, 0.05, 9.81)}) {
    const KDL::Chain chain = test::kdl_chain(a);
    KDL::ChainIdSolver_RNE rne(chain, KDL::Vector(0, -a.g, 0));
    test::RandomStates r;
    double worst = 0;
    for (int n = 0; n < 1000; ++n) {
      const Vec3 q = r.q(), qd = r.v(), qdd = r.v();
      KDL::JntArray kq(3), kqd(3), kqdd(3), ktau(3);
      for (int i = 0; i < 3; ++i) kq(i) = q[i], kqd(i) = qd[i], kqdd(i) = qdd[i];
      KDL::Wrenches f(3, KDL::Wrench::Zero());
      ASSERT_GE(rne.CartToJnt(kq, kqd, kqdd, f, ktau), 0);
      const Vec3 tau = inverse_dynamics(a, q, qd, qdd);
      for (int i = 0; i < 3; ++i) worst = std::max(worst, std::abs(tau[i] - ktau(i)));
    }
    EXPECT_LT(worst, 1e-9);
  }
}

// The thesis' M differs from the physical one in M11 only, by (m2 - 1) m3 times the m3 bracket.
TEST(Dynamics, ThesisInertiaFormDiffersOnlyInM11) {
  PlanarArm3 t = PlanarArm3::seed();
  t.inertia_form = InertiaForm::thesis_m11;
  const PlanarArm3 p = PlanarArm3::seed();
  const Vec3 q(0.3, 0.0, 0.0);  // theta2 = theta3 = 0: bracket = (l1 + l2 + lc3)^2 = 6.25
  Mat3 d = mass_matrix(t, joint_trig(q)) - mass_matrix(p, joint_trig(q));
  EXPECT_NEAR(d(0, 0), (2.0 - 1.0) * 1.0 * 6.25, 1e-12);
  d(0, 0) = 0;
  EXPECT_EQ(d.norm(), 0.0);
}

// SymInverse3 (adjugate / determinant) against Eigen's LU on the mass matrices the simulation meets.
TEST(SymInverse3, SolvesLikeLuAndGivesTheInverseQuadraticForm) {
  test::RandomStates r;
  for (auto form : {InertiaForm::physical, InertiaForm::thesis_m11}) {
    PlanarArm3 a = PlanarArm3::seed();
    a.inertia_form = form;
    const DynamicsCoefficients d(a);
    for (int n = 0; n < 1000; ++n) {
      const JointTrig t = joint_trig(r.q());
      const Sym3 M = mass_matrix_sym(d, t);
      const Mat3 Md = M.dense();
      const SymInverse3 Mi(M);
      const Vec3 b = r.v();
      const Vec3 x = Md.lu().solve(b);
      EXPECT_NEAR(Mi.det, Md.determinant(), 1e-12 * std::abs(Md.determinant()));
      EXPECT_LT((Mi.solve(b) - x).norm(), 1e-12 * (1 + x.norm()));
      EXPECT_NEAR(Mi.inverse_quadratic_form(b), b.dot(x), 1e-12 * (1 + b.dot(x)));
      EXPECT_LT((M * b - Md * b).norm(), 1e-13 * (1 + (Md * b).norm()));
      EXPECT_NEAR(M.quadratic_form(b), b.dot(Md * b), 1e-12 * (1 + b.dot(Md * b)));
    }
  }
}
