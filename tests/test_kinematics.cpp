// Forward kinematics, Jacobians (vs KDL and finite differences), J-dot, analytic IK.
#include <gtest/gtest.h>

#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include "kdl_arm.hpp"
#include "model/kinematics.hpp"
#include "random_state.hpp"

using namespace ks;

TEST(Kinematics, ForwardKinematicsMatchesKdl) {
  const PlanarArm3 a = PlanarArm3::bars({0.9, 1.1, 0.6}, {1, 1, 1}, 0.1);
  const KDL::Chain chain = test::kdl_chain(a);
  KDL::ChainFkSolverPos_recursive fk(chain);
  test::RandomStates r;
  for (int n = 0; n < 500; ++n) {
    const Vec3 q = r.q();
    KDL::JntArray kq(3);
    for (int i = 0; i < 3; ++i) kq(i) = q[i];
    const ArmPose p = forward_kinematics(a, q);
    const Vec2* joints[3] = {&p.elbow, &p.wrist, &p.tip};
    for (int s = 0; s < 3; ++s) {
      KDL::Frame f;
      ASSERT_GE(fk.JntToCart(kq, f, s + 1), 0);
      EXPECT_NEAR(f.p.x(), joints[s]->x(), 1e-12);
      EXPECT_NEAR(f.p.y(), joints[s]->y(), 1e-12);
    }
    EXPECT_DOUBLE_EQ(p.alpha, q.sum());
  }
}

TEST(Kinematics, JacobianMatchesKdl) {
  const PlanarArm3 a = PlanarArm3::seed();
  const KDL::Chain chain = test::kdl_chain(a);  // solvers keep a reference: it must outlive them
  KDL::ChainJntToJacSolver js(chain);
  test::RandomStates r;
  for (int n = 0; n < 500; ++n) {
    const Vec3 q = r.q();
    KDL::JntArray kq(3);
    for (int i = 0; i < 3; ++i) kq(i) = q[i];
    KDL::Jacobian kj(3);
    ASSERT_GE(js.JntToJac(kq, kj), 0);
    const Mat3 J = jacobian_with_alpha(a, joint_trig(q));
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(J(0, j), kj(0, j), 1e-12);
      EXPECT_NEAR(J(1, j), kj(1, j), 1e-12);
      EXPECT_NEAR(J(2, j), kj(5, j), 1e-12);  // rotation about z
    }
  }
}

TEST(Kinematics, JacobianDotIsTimeDerivativeOfJacobian) {
  const PlanarArm3 a = PlanarArm3::seed();
  test::RandomStates r;
  const double h = 1e-6;
  for (int n = 0; n < 200; ++n) {
    const Vec3 q = r.q(), qd = r.v();
    const Mat23 fd = (jacobian(a, joint_trig(Vec3(q + h * qd))) - jacobian(a, joint_trig(Vec3(q - h * qd)))) / (2 * h);
    EXPECT_LT((jacobian_dot(a, joint_trig(q), qd) - fd).norm(), 1e-7);
  }
}

TEST(Kinematics, ManipulabilityVanishesWhenStretched) {
  const PlanarArm3 a = PlanarArm3::seed();
  EXPECT_LT(manipulability(jacobian(a, joint_trig(Vec3(0.4, 0, 0)))), 1e-12);
  EXPECT_GT(manipulability(jacobian(a, joint_trig(Vec3(0.4, 1.0, -0.5)))), 0.1);
}

TEST(Kinematics, AnalyticIkBothBranchesReachThePoint) {
  const PlanarArm3 a = PlanarArm3::seed();
  test::RandomStates r;
  int reached = 0;
  for (int n = 0; n < 500; ++n) {
    const Vec3 q = r.q();
    const ArmPose p = forward_kinematics(a, q);
    for (Elbow e : {Elbow::positive, Elbow::negative}) {
      const auto s = inverse_kinematics(a, p.tip, p.alpha, e);
      ASSERT_TRUE(s.has_value());
      const ArmPose ps = forward_kinematics(a, *s);
      EXPECT_LT((ps.tip - p.tip).norm(), 1e-9);
      EXPECT_NEAR(ps.alpha, p.alpha, 1e-12);
      EXPECT_GE(static_cast<int>(e) * std::sin((*s)[1]), 0.0);
      ++reached;
    }
  }
  EXPECT_EQ(reached, 1000);
}

TEST(Kinematics, AnalyticIkReportsUnreachable) {
  const PlanarArm3 a = PlanarArm3::seed();
  // The seed's start (1.5, 1.5): for alpha = -90 deg the wrist is at (1.5, 2.5), |wrist| = 2.92 > 2.
  EXPECT_FALSE(inverse_kinematics(a, Vec2(1.5, 1.5), -M_PI / 2).has_value());
  EXPECT_FALSE(inverse_kinematics(a, Vec2(5.0, 0.0), 0.0).has_value());
  EXPECT_TRUE(inverse_kinematics(a, Vec2(1.5, 1.5), 0.0).has_value());
}

TEST(Kinematics, JacobianDotTimesRatesAndTipFromJacobian) {
  const PlanarArm3 a = PlanarArm3::seed();
  test::RandomStates r;
  for (int n = 0; n < 200; ++n) {
    const Vec3 q = r.q(), qd = r.v();
    const JointTrig t = joint_trig(q);
    EXPECT_LT((jacobian_dot_times_qd(a, t, qd) - jacobian_dot(a, t, qd) * qd).norm(), 1e-12);
    EXPECT_LT((end_effector_from_jacobian(jacobian(a, t)) - forward_kinematics(a, q).tip).norm(), 1e-12);
  }
}
