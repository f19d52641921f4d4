// fast_sincos against libm: within 2 ulp-scale error over the angles a simulation meets, and exact
// fallbacks for large and non-finite arguments.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Core>

#include "model/sincos.hpp"
#include "model/trig.hpp"

TEST(FastSincos, AgreesWithLibm) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-100.0, 100.0);
  double worst = 0;
  for (int i = 0; i < 200000; ++i) {
    const double x = i < 100 ? (i - 50) * M_PI / 4 : u(rng);  // include multiples of pi/4
    double s, c;
    ks::fast_sincos(x, s, c);
    worst = std::max({worst, std::abs(s - std::sin(x)), std::abs(c - std::cos(x))});
  }
  EXPECT_LT(worst, 4.5e-16);
}

TEST(FastSincos, FallsBackOutsideRange) {
  double s, c;
  ks::fast_sincos(1e7, s, c);
  EXPECT_DOUBLE_EQ(s, std::sin(1e7));
  ks::fast_sincos(std::numeric_limits<double>::quiet_NaN(), s, c);
  EXPECT_TRUE(std::isnan(s) && std::isnan(c));
}

// The tracker's trig stays within 2e-14 of direct evaluation along long random walks of small
// steps (all below 0.01: rotations only; up to 0.02: rotations and direct evaluations mixed) and
// through the large steps that force a direct evaluation.
TEST(TrigTracker, FollowsDirectEvaluation) {
  for (double width : {0.008, 0.02}) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> step(-width, width);
    Eigen::Vector3d q(0.3, -1.2, 2.5);
    ks::TrigTracker tr(q);
    double worst = 0;
    for (int i = 0; i < 20000; ++i) {
      Eigen::Vector3d dq(step(rng), step(rng), step(rng));
      if (i % 997 == 0) dq[1] = 0.3;  // not small: direct
      q += dq;
      tr.advance(q, dq);
      const ks::JointTrig d = ks::joint_trig(q), t = tr.trig();
      for (double e : {d.s1 - t.s1, d.c1 - t.c1, d.s2 - t.s2, d.c2 - t.c2, d.s3 - t.s3, d.c3 - t.c3, d.s123 - t.s123,
                       d.c123 - t.c123, d.s23 - t.s23, d.c12 - t.c12})
        worst = std::max(worst, std::abs(e));
    }
    EXPECT_LT(worst, 2e-14) << "steps up to " << width;  // 64 rotations between direct evaluations
  }
}
