// Chain kinematics (model/chain_kinematics.hpp) against Orocos KDL, finite differences and the
// closed-form planar 3R kinematics.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacdotsolver.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include "chain_fixtures.hpp"
#include "kdl_chain.hpp"
#include "model/chain_kinematics.hpp"
#include "model/kinematics.hpp"
#include "robot/urdf.hpp"

using namespace ks;

namespace {

Chain planar4r() {
  return planar_chain(planar_bars({0.8, 0.8, 0.7, 0.5}, {3.2, 3.2, 2.8, 2.0}, 0.05), 9.81, "planar4r");
}

std::vector<Chain> chains() {
  return {planar4r(), test::test_chain_prismatic(),
          load_urdf(KS_SOURCE_DIR "/studies/robots/arm7.urdf", "base_link", "tool", Eigen::Vector3d(0, 0, -9.81))};
}

Frame tip_frame(const Chain& c, const VecN& q) {
  ChainData d;
  forward_kinematics(c, d, q);
  return d.tip;
}

Mat6N jacobian(const Chain& c, const VecN& q) {
  ChainData d;
  forward_kinematics(c, d, q);
  Mat6N J;
  tip_jacobian(c, d, J);
  return J;
}

// The rotation vector of R (axis times angle).
Eigen::Vector3d rotation_vector(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.axis() * aa.angle();
}

}  // namespace

TEST(ChainKinematics, Predicates) {
  EXPECT_TRUE(planar4r().planar());
  EXPECT_TRUE(planar4r().planar_fast_path);
  EXPECT_FALSE(test::test_chain_prismatic().planar());
  for (const Chain& c : chains()) {
    std::string why;
    EXPECT_TRUE(c.IsValid(&why)) << why;
  }
  Chain bad = planar4r();
  bad.joints[2].axis = Eigen::Vector3d(0, 0, 2);
  std::string why;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("joint 2"), std::string::npos) << why;
  bad = planar4r();
  bad.joints[1].inertia(0, 0) = -1.0;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("positive semi-definite"), std::string::npos) << why;
  bad = planar4r();
  bad.joints[0].mass = -1.0;
  EXPECT_FALSE(bad.IsValid());
  bad = planar4r();
  bad.joints[3].lower = 1.0;
  bad.joints[3].upper = 0.0;
  EXPECT_FALSE(bad.IsValid());
  bad = planar4r();
  bad.joints.clear();
  EXPECT_FALSE(bad.IsValid());
  bad = planar4r();
  bad.gravity.z() = 1.0;
  EXPECT_FALSE(bad.planar());
  EXPECT_THROW(planar_bars({1, 1}, {1}, 0.1), std::invalid_argument);
}

TEST(ChainKinematics, ForwardKinematicsAndJacobianMatchKdl) {
  for (const Chain& c : chains()) {
    const KDL::Chain k = test::kdl_chain(c);
    ASSERT_EQ(static_cast<int>(k.getNrOfJoints()), c.dof());
    KDL::ChainFkSolverPos_recursive fk(k);
    KDL::ChainJntToJacSolver jac(k);
    test::RandomJoints r;
    for (int n = 0; n < 1000; ++n) {
      const VecN q = r.q(c.dof());
      const Frame f = tip_frame(c, q);
      KDL::Frame kf;
      ASSERT_GE(fk.JntToCart(test::kdl_array(q), kf), 0);
      for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(f.p[a], kf.p[a], 1e-12);
        for (int b = 0; b < 3; ++b) EXPECT_NEAR(f.R(a, b), kf.M(a, b), 1e-12);
      }
      const Mat6N J = jacobian(c, q);
      KDL::Jacobian kj(c.dof());
      ASSERT_GE(jac.JntToJac(test::kdl_array(q), kj), 0);
      EXPECT_LT((J - test::from_kdl(kj)).norm(), 1e-12 * (1 + J.norm())) << c.name;
    }
  }
}

// Column i: d(tip position)/dq_i and the rotation vector of R(q + h e_i) R(q - h e_i)^T / (2h).
TEST(ChainKinematics, JacobianIsDerivativeOfForwardKinematics) {
  const double h = 1e-6;
  for (const Chain& c : chains()) {
    test::RandomJoints r;
    for (int n = 0; n < 200; ++n) {
      const VecN q = r.q(c.dof());
      const Mat6N J = jacobian(c, q);
      for (int i = 0; i < c.dof(); ++i) {
        VecN qp = q, qm = q;
        qp[i] += h;
        qm[i] -= h;
        const Frame fp = tip_frame(c, qp), fm = tip_frame(c, qm);
        Vec6 col;
        col.head<3>() = (fp.p - fm.p) / (2 * h);
        col.tail<3>() = rotation_vector(fp.R * fm.R.transpose()) / (2 * h);
        EXPECT_LT((J.col(i) - col).norm(), 1e-7 * (1 + col.norm())) << c.name << " column " << i;
      }
    }
  }
}

// KDL's hybrid representation (base axes, reference point at the end effector) is the derivative
// of the same Jacobian; its J̇ q̇ is the tip's acceleration at q̈ = 0.
TEST(ChainKinematics, BiasAccelerationMatchesKdlJacDot) {
  for (const Chain& c : chains()) {
    const KDL::Chain k = test::kdl_chain(c);
    KDL::ChainJntToJacDotSolver jd(k);
    jd.setHybridRepresentation();
    test::RandomJoints r;
    double worst = 0;
    for (int n = 0; n < 1000; ++n) {
      const VecN q = r.q(c.dof()), qd = r.v(c.dof());
      ChainData d;
      const Vec6 b = tip_bias_acceleration(c, d, q, qd);
      KDL::Twist t;
      ASSERT_GE(jd.JntToJacDot(KDL::JntArrayVel(test::kdl_array(q), test::kdl_array(qd)), t), 0);
      Vec6 kb;
      kb << t.vel.x(), t.vel.y(), t.vel.z(), t.rot.x(), t.rot.y(), t.rot.z();
      worst = std::max(worst, (b - kb).norm() / (1 + kb.norm()));
    }
    EXPECT_LT(worst, 1e-12) << c.name;
  }
}

// J̇ q̇ = d/dt J(q + t q̇) q̇ at t = 0, by central differences.
TEST(ChainKinematics, BiasAccelerationIsDerivativeOfJacobianAlongVelocity) {
  const double h = 1e-6;
  for (const Chain& c : chains()) {
    test::RandomJoints r;
    for (int n = 0; n < 200; ++n) {
      const VecN q = r.q(c.dof()), qd = r.v(c.dof());
      const Vec6 fd = (jacobian(c, q + h * qd) - jacobian(c, q - h * qd)) * qd / (2 * h);
      ChainData d;
      const Vec6 b = tip_bias_acceleration(c, d, q, qd);
      EXPECT_LT((b - fd).norm(), 1e-6 * (1 + fd.norm())) << c.name;
    }
  }
}

TEST(ChainKinematics, SeedPlanarChainEqualsClosedForm3R) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const Chain c = planar_chain(planar_bars({1, 1, 1}, {5, 2, 1}, 0.1), 9.81);
  test::RandomJoints r;
  for (int n = 0; n < 1000; ++n) {
    const VecN q = r.q(3), qd = r.v(3);
    const Vec3 q3 = q, qd3 = qd;
    const JointTrig t = joint_trig(q3);
    ChainData d;
    forward_kinematics(c, d, q);
    const ArmPose pose = forward_kinematics(arm, q3);
    EXPECT_NEAR(d.tip.p.x(), pose.tip.x(), 1e-12);
    EXPECT_NEAR(d.tip.p.y(), pose.tip.y(), 1e-12);
    EXPECT_NEAR(d.tip.p.z(), 0.0, 1e-12);
    EXPECT_NEAR(d.tip.R(0, 0), std::cos(pose.alpha), 1e-12);
    EXPECT_NEAR(d.tip.R(1, 0), std::sin(pose.alpha), 1e-12);
    EXPECT_NEAR(d.joint[1].p.x(), pose.elbow.x(), 1e-12);
    EXPECT_NEAR(d.joint[2].p.y(), pose.wrist.y(), 1e-12);
    Mat6N J;
    tip_jacobian(c, d, J);
    const Mat3 J3 = jacobian_with_alpha(arm, t);
    EXPECT_LT((J.topRows<2>() - J3.topRows<2>()).norm(), 1e-12);
    EXPECT_LT((J.row(5) - J3.row(2)).norm(), 1e-12);
    EXPECT_LT(J.middleRows<3>(2).norm(), 1e-12);
    const Vec6 b = tip_bias_acceleration(c, d, q, qd);
    const Vec2 b2 = jacobian_dot_times_qd(arm, t, qd3);
    EXPECT_NEAR(b[0], b2.x(), 1e-12 * (1 + b2.norm()));
    EXPECT_NEAR(b[1], b2.y(), 1e-12 * (1 + b2.norm()));
    EXPECT_LT(b.tail<4>().norm(), 1e-12);
  }
}
