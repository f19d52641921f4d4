// Planar chains in any plane of their base frame (model/chain_plane.hpp): the plane found, the chain
// in its plane's frame against the same chain in its base frame through the general 3-D algorithms
// (M, c, g, tip position, Jacobian, tip angle), the seed arm written in the base xz plane against the
// seed arm, chains already in the base xy plane kept bit for bit, and gravity normal to the plane.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <fstream>
#include <sstream>

#include "chain_fixtures.hpp"
#include "methods/chain/resolution.hpp"
#include "model/chain_dynamics.hpp"
#include "model/chain_kinematics.hpp"
#include "model/chain_plane.hpp"
#include "robot/urdf.hpp"

using namespace ks;
using Eigen::Vector3d;

namespace {

const std::string kRobots = KS_SOURCE_DIR "/studies/robots/";
const std::string kData = KS_SOURCE_DIR "/tests/data/";

std::string read(const std::string& file) {
  std::ifstream in(file);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

Chain seed_arm() { return planar_chain(planar_bars({1, 1, 1}, {5, 2, 1}, 0.1), 9.81); }

/// max |a - b| / max(1, max |b|)
/// (evaluated into heap matrices: GCC 12 misjudges the bounds of Eigen's vectorised reductions over
/// bounded-size expressions, -Warray-bounds / -Wmaybe-uninitialized)
template <class A, class B>
double rel(const A& a, const B& b) {
  const Eigen::MatrixXd x = a, y = b;
  return (x - y).cwiseAbs().maxCoeff() / std::max(1.0, y.cwiseAbs().maxCoeff());
}

Eigen::Matrix3d aligning(const Vector3d& from, const Vector3d& to) {
  return Eigen::Quaterniond::FromTwoVectors(from, to).toRotationMatrix();
}

/// A chain moving in the plane with normal R0 z through (0, 0, 0.2) rotated by R0: revolute joints
/// with oblique local axes (each joint frame turned so that its axis is +-n), one prismatic joint
/// along an in-plane direction, bodies offset along n, off-axis centres of mass, full inertias, a
/// tip frame turned about n and tilted, and gravity oblique to the plane.
Chain tilted_chain(bool with_prismatic) {
  const Eigen::Matrix3d R0 = test::rpy(0.7, -0.4, 1.1);
  struct Spec {
    JointType type;
    Vector3d local_axis, at;  // at: the joint's position in the plane's own coordinates (x, y, height)
    double turn, sign;
  };
  std::vector<Spec> specs = {{JointType::revolute, {0.3, -0.5, 0.8}, {0.1, -0.2, 0.2}, 0.4, 1},
                             {JointType::revolute, {0, 0, 1}, {0.6, 0.1, 0.35}, -0.9, -1},
                             {JointType::prismatic, {1, 1, 0}, {0.9, 0.4, 0.05}, 0.3, 1},
                             {JointType::revolute, {-0.2, 0.9, 0.1}, {1.2, 0.3, 0.1}, 2.0, 1}};
  if (!with_prismatic) specs.erase(specs.begin() + 2);
  Chain c;
  c.name = "tilted";
  c.source = "test";
  Frame prev;
  int k = 0;
  for (const Spec& s : specs) {
    ChainJoint j;
    j.name = "j" + std::to_string(++k);
    j.type = s.type;
    j.axis = s.local_axis.normalized();
    Frame f;  // the joint frame in the base frame at q = 0
    if (s.type == JointType::revolute) f.R = R0 * Eigen::AngleAxisd(s.turn, Vector3d::UnitZ()) * aligning(j.axis, s.sign * Vector3d::UnitZ());
    else f.R = R0 * Eigen::AngleAxisd(s.turn, Vector3d::UnitZ()) * aligning(j.axis, Vector3d::UnitX());
    f.p = R0 * s.at;
    j.origin.R = prev.R.transpose() * f.R;
    j.origin.p = prev.R.transpose() * (f.p - prev.p);
    j.mass = 0.5 + 0.3 * k;
    j.com = {0.1 * k, -0.05, 0.03 * k};
    const Eigen::Matrix3d Q = test::rpy(0.3 * k, -0.2, 0.5);
    j.inertia = Q * Vector3d(0.02, 0.03 + 0.01 * k, 0.04).asDiagonal() * Q.transpose();
    j.inertia = (0.5 * (j.inertia + j.inertia.transpose())).eval();
    if (s.type == JointType::prismatic) j.lower = -0.3, j.upper = 0.3;
    c.joints.push_back(j);
    prev = f;
  }
  Frame tip;
  tip.R = R0 * Eigen::AngleAxisd(0.6, Vector3d::UnitZ()) * test::rpy(0.2, 0.3, 0.0);  // x axis 17 deg off the plane
  tip.p = R0 * Vector3d(1.5, 0.2, 0.12);
  c.tip.R = prev.R.transpose() * tip.R;
  c.tip.p = prev.R.transpose() * (tip.p - prev.p);
  c.gravity = Vector3d(1.5, -2.0, -9.0);
  return c;
}

/// The in-plane dynamics and kinematics of `in_plane` (= in_plane_frame(base, plane)) equal those
/// of `base` through the general 3-D algorithms, on random states.
void expect_same_motion(const Chain& base, const ChainPlane& plane, const Chain& in_plane, double tol) {
  ASSERT_TRUE(in_plane.planar());
  EXPECT_TRUE(in_plane.planar_fast_path);
  EXPECT_FALSE(base.planar_fast_path);
  const int n = base.dof();
  Eigen::Matrix<double, 3, 3> P;  // base vectors -> (e1, e2, n) components
  P << plane.e1().transpose(), plane.e2().transpose(), plane.normal().transpose();
  const PlanarAngle angle(in_plane);
  test::RandomJoints r;
  for (int k = 0; k < 200; ++k) {
    const VecN q = r.q(n), qd = r.v(n);
    ChainData a, b;
    ChainState sa, sb;
    evaluate_dynamics(base, a, q, qd, sa);
    evaluate_dynamics(in_plane, b, q, qd, sb);
    EXPECT_LT(rel(sb.M, sa.M), tol) << k;
    EXPECT_LT(rel(sb.c, sa.c), tol) << k;
    EXPECT_LT(rel(sb.g, sa.g), tol) << k;
    double off = 0;
    const Eigen::Vector2d tip = plane.to_plane(sa.tip.p, &off);
    EXPECT_LT(rel(sb.tip.p.head<2>(), tip), tol) << k;
    EXPECT_NEAR(sb.tip.p.z(), 0.0, 1e-15);
    EXPECT_NEAR(off, 0.0, tol) << k;  // the tip stays in the plane
    const Eigen::Matrix<double, 2, Eigen::Dynamic> Jp = P.topRows<2>() * sa.J.topRows<3>();
    EXPECT_LT(rel(sb.J.topRows<2>(), Jp), tol) << k;
    EXPECT_LT(rel(sb.J.row(5), P.row(2) * sa.J.bottomRows<3>()), tol) << k;
    // the tip angle: the direction of the tip's x axis in the plane
    const Vector3d x = P * sa.tip.R.col(0);
    const double d = std::remainder(angle(q) - std::atan2(x.y(), x.x()), 2 * M_PI);
    EXPECT_NEAR(d, 0.0, tol) << k;
  }
}

}  // namespace

TEST(ChainPlane, SeedArmInTheXzPlaneIsTheSeedArm) {
  const Chain base = load_urdf(kData + "seed3r_xz.urdf", "base_link", "tool", Vector3d(0, 0, -9.81));
  EXPECT_FALSE(base.planar());
  const std::optional<ChainPlane> plane = motion_plane(base);
  ASSERT_TRUE(plane.has_value());
  // e1 = x, e2 = z, n = e1 x e2 = -y (the joint axes), the origin at the base origin
  EXPECT_LT((plane->e1() - Vector3d::UnitX()).norm(), 1e-15);
  EXPECT_LT((plane->e2() - Vector3d::UnitZ()).norm(), 1e-15);
  EXPECT_LT((plane->normal() + Vector3d::UnitY()).norm(), 1e-15);
  EXPECT_LT(plane->origin().norm(), 1e-15);
  const Chain c = in_plane_frame(base, *plane);
  expect_same_motion(base, *plane, c, 1e-12);
  // in plane coordinates (x, z) with gravity -z it is the seed arm (gravity along -y of its plane)
  EXPECT_LT((c.gravity - Vector3d(0, -9.81, 0)).norm(), 1e-15);
  const Chain seed = seed_arm();
  test::RandomJoints r;
  for (int k = 0; k < 200; ++k) {
    const VecN q = r.q(3), qd = r.v(3);
    ChainData a, b;
    ChainState sa, sb;
    evaluate_dynamics(c, a, q, qd, sa);
    evaluate_dynamics(seed, b, q, qd, sb);
    EXPECT_LT(rel(sa.M, sb.M) + rel(sa.c, sb.c) + rel(sa.g, sb.g), 1e-12) << k;
    EXPECT_LT((sa.tip.p - sb.tip.p).norm(), 1e-12) << k;
  }
  EXPECT_NEAR(PlanarAngle(c).offset, 0.0, 1e-15);
}

TEST(ChainPlane, ArmInTheBaseXyPlaneIsKeptBitForBit) {
  for (const Chain& chain : {load_urdf(kRobots + "seed3r.urdf", "base_link", "tool", Vector3d(0, -9.81, 0)),
                             load_urdf(kRobots + "planar5r.urdf", "base_link", "tool", Vector3d(0.3, -9.81, 0)), seed_arm()}) {
    SCOPED_TRACE(chain.name);
    const std::optional<ChainPlane> plane = motion_plane(chain);
    ASSERT_TRUE(plane.has_value());
    EXPECT_TRUE(plane->is_base_xy());
    const Chain c = in_plane_frame(chain, *plane);
    ASSERT_EQ(c.dof(), chain.dof());
    for (int i = 0; i < c.dof(); ++i) {
      const ChainJoint &a = c.joints[i], &b = chain.joints[i];
      EXPECT_TRUE(a.origin.R == b.origin.R && a.origin.p == b.origin.p && a.axis == b.axis && a.com == b.com &&
                  a.inertia == b.inertia && a.mass == b.mass && a.lower == b.lower && a.upper == b.upper)
          << i;
    }
    EXPECT_TRUE(c.tip.R == chain.tip.R && c.tip.p == chain.tip.p && c.gravity == chain.gravity);
    EXPECT_EQ(c.planar_fast_path, chain.planar_fast_path);
  }
}

TEST(ChainPlane, RotatedWorldLinkAroundTheSeedArm) {
  // seed3r.urdf (in its base_link's xy plane) under a world link turned by 90 deg about x: in the
  // world frame the arm moves in the xz plane, its axes along -y
  std::string text = read(kRobots + "seed3r.urdf");
  const std::string world =
      "<link name=\"world\"/>\n  <joint name=\"mount\" type=\"fixed\">\n    <parent link=\"world\"/>\n"
      "    <child link=\"base_link\"/>\n    <origin xyz=\"0 0.4 0.25\" rpy=\"1.5707963267948966 0 0\"/>\n  </joint>\n  ";
  text.insert(text.find("<link name=\"base_link\"/>"), world);
  const Chain base = parse_urdf(text, "world", "tool", Vector3d(0, 0, -9.81));
  const std::optional<ChainPlane> plane = motion_plane(base);
  ASSERT_TRUE(plane.has_value());
  EXPECT_LT((plane->normal() + Vector3d::UnitY()).norm(), 1e-15);
  EXPECT_LT((plane->origin() - Vector3d(0, 0.4, 0)).norm(), 1e-15);  // the tip's plane y = 0.4
  const Chain c = in_plane_frame(base, *plane);
  expect_same_motion(base, *plane, c, 1e-12);
  // the arm's base sits at plane coordinates (0, 0.25); shifted there it is the seed arm
  EXPECT_LT((c.joints[0].origin.p - Vector3d(0, 0.25, 0)).norm(), 1e-15);
  Chain shifted = c;
  shifted.joints[0].origin.p.setZero();
  shifted.prepare();
  ChainData a, b;
  MatN Ma, Mb;
  VecN ga, gb;
  const VecN q = joint_vector({0.3, -1.1, 0.7});
  crba(shifted, a, q, Ma);
  crba(seed_arm(), b, q, Mb);
  gravity_torques(shifted, a, q, ga);
  gravity_torques(seed_arm(), b, q, gb);
  EXPECT_LT(rel(Ma, Mb) + rel(ga, gb), 1e-12);
}

TEST(ChainPlane, TiltedPlaneWithOffsetsAndAPrismaticJoint) {
  for (bool prismatic : {false, true}) {
    SCOPED_TRACE(prismatic ? "with a prismatic joint" : "revolute only");
    Chain base = tilted_chain(prismatic);
    std::string why;
    ASSERT_TRUE(base.IsValid(&why)) << why;
    base.prepare();
    const std::optional<ChainPlane> plane = motion_plane(base);
    ASSERT_TRUE(plane.has_value());
    const Vector3d n = test::rpy(0.7, -0.4, 1.1) * Vector3d::UnitZ();
    EXPECT_LT(plane->normal().cross(n).norm(), 1e-14);
    EXPECT_NEAR(plane->e1().dot(plane->e2()), 0.0, 1e-15);
    expect_same_motion(base, *plane, in_plane_frame(base, *plane), 1e-12);
  }
}

TEST(ChainPlane, SpatialChainsHaveNoPlane) {
  EXPECT_FALSE(motion_plane(load_urdf(kRobots + "arm7.urdf", "base_link", "tool", Vector3d(0, 0, -9.81))).has_value());
  EXPECT_FALSE(motion_plane(test::test_chain_prismatic()).has_value());
  // a prismatic joint along the revolute axes moves out of the plane
  Chain c = tilted_chain(true);
  c.joints[2].axis = c.joints[2].origin.R.transpose() * c.joints[1].origin.R.transpose() * c.joints[0].origin.R.transpose() *
                     (test::rpy(0.7, -0.4, 1.1) * Vector3d::UnitZ());
  EXPECT_FALSE(motion_plane(c).has_value());
  // one axis 1e-6 rad off the others
  Chain d = seed_arm();
  d.joints[1].axis = Vector3d(1e-6, 0, 1).normalized();
  EXPECT_FALSE(motion_plane(d).has_value());
}

// Gravity normal to the plane (a horizontal arm) gives no joint torque: the chain in its plane's frame
// has zero gravity, and the chain in its base frame through the 3-D algorithms (qd = qdd = 0) agrees.
TEST(ChainPlane, GravityNormalToThePlaneGivesNoTorque) {
  const Chain horizontal[] = {load_urdf(kRobots + "seed3r.urdf", "base_link", "tool", Vector3d(0, 0, -9.81)),
                              load_urdf(kData + "seed3r_xz.urdf", "base_link", "tool", Vector3d(0, 9.81, 0))};
  for (const Chain& base : horizontal) {
    SCOPED_TRACE(base.name);
    const std::optional<ChainPlane> plane = motion_plane(base);
    ASSERT_TRUE(plane.has_value());
    const Chain c = in_plane_frame(base, *plane);
    EXPECT_TRUE(c.gravity == Vector3d::Zero());
    test::RandomJoints r;
    for (int k = 0; k < 100; ++k) {
      const VecN q = r.q(3), zero = VecN::Zero(3);
      ChainData d;
      VecN g, tau;
      gravity_torques(c, d, q, g);
      EXPECT_TRUE(g == VecN::Zero(3)) << g.transpose();
      rnea(base, d, q, zero, zero, tau);  // 3-D gravity, normal to the plane
      EXPECT_LT(tau.cwiseAbs().maxCoeff(), 1e-12) << k;
    }
  }
}
