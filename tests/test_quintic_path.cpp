// The quintic path: boundary conditions, derivatives by finite differences, the seed's square and polynomial.
#include <gtest/gtest.h>

#include "task/task_path.hpp"
#include "task/sampled_path.hpp"

using namespace ks;

TEST(QuinticPath, SeedSquareMatchesTheSeedPolynomials) {
  const Path2 p = seed_square();
  EXPECT_DOUBLE_EQ(p.duration(), 2.0);
  for (double t = 0; t <= 0.5; t += 0.01) {  // segment A as written in the seed's code (Appendix F)
    const auto s = p.sample(t);
    EXPECT_NEAR(s.p.y(), 1.5 + 40 * std::pow(t, 3) - 120 * std::pow(t, 4) + 96 * std::pow(t, 5), 1e-12);
    EXPECT_NEAR(s.v.y(), 120 * t * t - 480 * std::pow(t, 3) + 480 * std::pow(t, 4), 1e-11);
    EXPECT_NEAR(s.a.y(), 240 * t - 1440 * t * t + 1920 * std::pow(t, 3), 1e-10);
    EXPECT_DOUBLE_EQ(s.p.x(), 1.5);
  }
  const double td = 1.7;  // segment D: x = 2 - 40 u^3 + 120 u^4 - 96 u^5, u = t - 1.5
  const double u = td - 1.5;
  EXPECT_NEAR(p.sample(td).p.x(), 2 - 40 * std::pow(u, 3) + 120 * std::pow(u, 4) - 96 * std::pow(u, 5), 1e-12);
}

TEST(QuinticPath, SegmentChoiceFollowsTheSeed) {
  const Path2 p = seed_square();
  EXPECT_EQ(p.segment_at(0.0), 0u);
  EXPECT_EQ(p.segment_at(0.5), 0u);
  EXPECT_EQ(p.segment_at(0.5000001), 1u);
  EXPECT_EQ(p.segment_at(1.0), 1u);
  EXPECT_EQ(p.segment_at(2.0), 3u);
}

TEST(QuinticPath, RestAtEveryVertexAndDerivativesConsistent) {
  const Path2 p({Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 2), Eigen::Vector2d(-1, 0.5)}, {0.7, 1.3});
  double t = 0;
  for (std::size_t i = 0; i < p.vertices().size(); ++i) {
    const auto s = p.sample(t);
    EXPECT_LT((s.p - p.vertices()[i]).norm(), 1e-12);
    EXPECT_LT(s.v.norm(), 1e-12);
    EXPECT_LT(s.a.norm(), 1e-10);
    if (i < p.durations().size()) t += p.durations()[i];
  }
  const double h = 1e-6;
  for (double tt : {0.1, 0.35, 0.9, 1.6}) {
    const auto s = p.sample(tt), sp = p.sample(tt + h), sm = p.sample(tt - h);
    EXPECT_LT(((sp.p - sm.p) / (2 * h) - s.v).norm(), 1e-7);
    EXPECT_LT(((sp.v - sm.v) / (2 * h) - s.a).norm(), 1e-6);
  }
}

TEST(QuinticPath, RejectsBadShapes) {
  EXPECT_THROW(Path2({Eigen::Vector2d(0, 0)}, {}), std::invalid_argument);
  EXPECT_THROW(Path2({Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0)}, {0.0}), std::invalid_argument);
}

// SampledPath holds exactly what the seed's loop computes at t = i dt: same times, same segments,
// same values as sampling the path on the fly.
TEST(SampledPath, EqualsSamplingOnTheFly) {
  const Path2 p = seed_square();
  const SampledPath s(p, 1e-3);
  ASSERT_EQ(s.size(), 2001u);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double t = static_cast<double>(i) * 1e-3;
    const auto x = p.sample(t);
    ASSERT_EQ(s.time(i), t);
    ASSERT_EQ(s.segment(i), p.segment_at(t));
    ASSERT_EQ(s.position(i), x.p);
    ASSERT_EQ(s.acceleration(i), x.a);
  }
  EXPECT_EQ(s.segment(500), 0u);  // t = 0.5 still on side A (the seed's t <= 0.5 rule)
  EXPECT_EQ(s.segment(501), 1u);
  EXPECT_EQ(SampledPath(p, 0.3).size(), 7u);  // 0, 0.3, ..., 1.8
}
