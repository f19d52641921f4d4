// geometry/link_capsules.hpp: the link capsules from the joint frame origins, the frame-origin
// Jacobians and min_clearance's gradient in q against central differences, on the seed's planar 3R
// (unit links), a spatial chain with prismatic joints and oblique axes (tests/chain_fixtures.hpp),
// the 7-joint arm7.urdf and the Puma 560 (puma560.urdf: joints 1 and 2, 5 and 6 and the tool share
// their origins, so three of its links are zero-length capsules, i.e. spheres), with spheres,
// oriented boxes and capsules as obstacles.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "chain_fixtures.hpp"
#include "geometry/link_capsules.hpp"
#include "robot/urdf.hpp"

using namespace ks;
using namespace ks::geometry;

namespace {

struct Robot {
  Chain chain;
  double reach;  ///< obstacles are placed within this distance of the base [m]
};

std::vector<Robot> robots() {
  return {{planar_chain(planar_bars({1, 1, 1}, {5, 2, 1}, 0.1), 9.81, "seed3r"), 2.5},
          {test::test_chain_prismatic(), 1.0},
          {load_urdf(KS_SOURCE_DIR "/studies/robots/arm7.urdf", "base_link", "tool", Eigen::Vector3d(0, 0, -9.81)), 1.2},
          {load_urdf(KS_SOURCE_DIR "/studies/robots/puma560.urdf", "base_link", "tool", Eigen::Vector3d(0, 0, -9.81)), 0.9}};
}

struct Random {
  std::mt19937_64 rng{20261206};
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
  Vec3 point(double r) { return {uniform(-r, r), uniform(-r, r), uniform(-r, r)}; }
  Mat3 rotation() {
    std::normal_distribution<double> n;
    return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
  }
  VecN q(const Chain& c) {
    VecN q(c.dof());
    for (int i = 0; i < c.dof(); ++i)
      q[i] = c.joints[i].type == JointType::revolute ? uniform(-3.0, 3.0) : uniform(-0.3, 0.3);
    return q;
  }
  /// 1 .. 4 obstacles of every kind within `reach` of the base.
  std::vector<Obstacle> obstacles(double reach) {
    std::vector<Obstacle> out;
    const int n = 1 + static_cast<int>(uniform(0.0, 4.0));
    for (int j = 0; j < n; ++j) {
      const double kind = uniform(0.0, 3.0), size = 0.1 * reach;
      if (kind < 1.0)
        out.push_back(Sphere{point(reach), uniform(0.2, 1.0) * size});
      else if (kind < 2.0)
        out.push_back(Box{point(reach), rotation(), Vec3(uniform(0.2, 1.0), uniform(0.2, 1.0), uniform(0.2, 1.0)) * size});
      else {
        const Vec3 a = point(reach);
        out.push_back(Capsule{a, a + point(0.5 * reach), uniform(0.2, 1.0) * size});
      }
    }
    return out;
  }
};

std::vector<double> radii(const Chain& c, double reach) { return std::vector<double>(c.dof(), 0.04 * reach); }

TEST(LinkCapsules, SegmentsJoinTheFrameOrigins) {
  for (const Robot& r : robots()) {
    const Chain& c = r.chain;
    Random rnd;
    ChainData data;
    forward_kinematics(c, data, rnd.q(c));
    std::array<Capsule, kMaxJoints> links;
    const std::vector<double> rad = radii(c, r.reach);
    link_capsules(c, data, rad, links);
    int zero_length = 0;
    for (int k = 0; k < c.dof(); ++k) {
      zero_length += links[k].a == links[k].b;
      EXPECT_EQ(links[k].a, data.joint[k].p);
      EXPECT_EQ(links[k].b, k + 1 < c.dof() ? data.joint[k + 1].p : data.tip.p);
      EXPECT_EQ(links[k].radius, rad[k]);
    }
    EXPECT_EQ(zero_length, c.name == "puma560" ? 3 : 0) << c.name;
  }
}

TEST(LinkCapsules, FrameOriginJacobianAgainstCentralDifferences) {
  for (const Robot& r : robots()) {
    const Chain& c = r.chain;
    Random rnd;
    for (int trial = 0; trial < 20; ++trial) {
      const VecN q = rnd.q(c);
      ChainData data;
      forward_kinematics(c, data, q);
      for (int k = 0; k <= c.dof(); ++k) {
        Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kMaxJoints> J;
        frame_origin_jacobian(c, data, k, J);
        for (int i = 0; i < c.dof(); ++i) {
          const double h = 1e-6;
          VecN qp = q, qm = q;
          qp[i] += h, qm[i] -= h;
          ChainData dp, dm;
          forward_kinematics(c, dp, qp);
          forward_kinematics(c, dm, qm);
          const Vec3 op = k < c.dof() ? dp.joint[k].p : dp.tip.p, om = k < c.dof() ? dm.joint[k].p : dm.tip.p;
          EXPECT_LT(((op - om) / (2 * h) - J.col(i)).norm(), 1e-8) << c.name << " frame " << k << " joint " << i;
        }
      }
    }
  }
}

TEST(MinClearance, LeastPairOfAllLinksAndObstacles) {
  for (const Robot& r : robots()) {
    const Chain& c = r.chain;
    Random rnd;
    ClearanceWorkspace ws;
    const std::vector<double> rad = radii(c, r.reach);
    for (int trial = 0; trial < 200; ++trial) {
      const VecN q = rnd.q(c);
      const std::vector<Obstacle> obs = rnd.obstacles(r.reach);
      const Clearance cl = min_clearance(c, q, rad, obs, ws);
      double least = std::numeric_limits<double>::infinity();
      for (int k = 0; k < c.dof(); ++k)
        for (const Obstacle& o : obs) least = std::min(least, capsule_obstacle(ws.links[k], o).distance);
      EXPECT_EQ(cl.distance, least);
      EXPECT_EQ(cl.distance, capsule_obstacle(ws.links[cl.link], obs[cl.obstacle]).distance);
    }
    const Clearance none = min_clearance(c, rnd.q(c), rad, {}, ws);
    EXPECT_TRUE(std::isinf(none.distance));
    EXPECT_EQ(none.link, -1);
    EXPECT_THROW(min_clearance(c, rnd.q(c), std::vector<double>(c.dof() + 1, 0.1), {}, ws), std::invalid_argument);
  }
}

TEST(MinClearance, GradientAgainstCentralDifferences) {
  for (const Robot& r : robots()) {
    const Chain& c = r.chain;
    Random rnd;
    ClearanceWorkspace ws;
    const std::vector<double> rad = radii(c, r.reach);
    int checked = 0, kinks = 0, touching = 0;
    for (int trial = 0; trial < 1000; ++trial) {
      const VecN q = rnd.q(c);
      const std::vector<Obstacle> obs = rnd.obstacles(r.reach);
      const Clearance cl = min_clearance(c, q, rad, obs, ws);
      if (cl.closest.core < 1e-3) {  // cores touching: no derivative
        ++touching;
        continue;
      }
      // one-sided differences that disagree: a switch of the least pair or of its witness (a
      // non-smooth point) within the step; skipped and counted
      constexpr double h = 1e-6;
      VecN fd(c.dof());
      bool kink = false;
      for (int i = 0; i < c.dof(); ++i) {
        VecN qp = q, qm = q;
        qp[i] += h, qm[i] -= h;
        const double fp = min_clearance(c, qp, rad, obs, ws).distance, fm = min_clearance(c, qm, rad, obs, ws).distance;
        kink = kink || std::abs((fp - cl.distance) - (cl.distance - fm)) / h > 1e-4;
        fd[i] = (fp - fm) / (2 * h);
      }
      if (kink) {
        ++kinks;
        continue;
      }
      ++checked;
      for (int i = 0; i < c.dof(); ++i)
        ASSERT_NEAR(fd[i], cl.gradient[i], 1e-6 * std::max(1.0, std::abs(cl.gradient[i])))
            << c.name << " trial " << trial << " joint " << i << " link " << cl.link << " obstacle " << cl.obstacle;
    }
    std::printf("%s: gradient compared at %d configurations (%d at a kink, %d with touching cores skipped)\n",
                c.name.c_str(), checked, kinks, touching);
    EXPECT_GT(checked, 900);
  }
}

}  // namespace
