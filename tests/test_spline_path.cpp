// The spline shapes of TaskPath (natural and clamped cubic splines through timed waypoints). Oracles:
// the spline's 4n polynomial coefficients solved from the full dense system of its conditions
// (interpolation, C1 and C2 at interior waypoints, the two end conditions) by Eigen's FullPivLU, a
// formulation independent of the path's tridiagonal system in second derivatives; closed forms for two
// waypoints (a line; 3 s^2 - 2 s^3); finite differences for the derivatives.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <random>

#include "task/sampled_path.hpp"
#include "task/task_path.hpp"

using namespace ks;

namespace {

/// One coordinate's spline by the dense oracle: coefficients (a, b, c, d) of segment i, p = a + b u +
/// c u^2 + d u^3 with u the time since the segment's start [s].
struct DenseSpline {
  std::vector<double> h;
  Eigen::VectorXd coef;  // 4 per segment
  DenseSpline(const std::vector<double>& y, const std::vector<double>& durations, bool clamped) : h(durations) {
    const int n = static_cast<int>(h.size());
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(4 * n, 4 * n);
    Eigen::VectorXd r = Eigen::VectorXd::Zero(4 * n);
    int row = 0;
    for (int i = 0; i < n; ++i) {  // p_i(0) = y_i, p_i(h_i) = y_{i+1}
      const double u = h[i];
      A(row, 4 * i) = 1, r(row++) = y[i];
      A(row, 4 * i) = 1, A(row, 4 * i + 1) = u, A(row, 4 * i + 2) = u * u, A(row, 4 * i + 3) = u * u * u;
      r(row++) = y[i + 1];
    }
    for (int i = 0; i + 1 < n; ++i) {  // p_i'(h_i) = p_{i+1}'(0), p_i''(h_i) = p_{i+1}''(0)
      const double u = h[i];
      A(row, 4 * i + 1) = 1, A(row, 4 * i + 2) = 2 * u, A(row, 4 * i + 3) = 3 * u * u, A(row++, 4 * i + 5) = -1;
      A(row, 4 * i + 2) = 2, A(row, 4 * i + 3) = 6 * u, A(row++, 4 * i + 6) = -2;
    }
    const double e = h[n - 1];
    if (clamped) {  // p_0'(0) = 0, p_{n-1}'(h) = 0
      A(row++, 1) = 1;
      A(row, 4 * (n - 1) + 1) = 1, A(row, 4 * (n - 1) + 2) = 2 * e, A(row++, 4 * (n - 1) + 3) = 3 * e * e;
    } else {  // p_0''(0) = 0, p_{n-1}''(h) = 0
      A(row++, 2) = 2;
      A(row, 4 * (n - 1) + 2) = 2, A(row++, 4 * (n - 1) + 3) = 6 * e;
    }
    coef = Eigen::FullPivLU<Eigen::MatrixXd>(A).solve(r);
  }
  /// value, first and second derivative at time t [s] from 0 (the segment that holds t)
  std::array<double, 3> at(double t) const {
    std::size_t i = 0;
    double start = 0;
    while (i + 1 < h.size() && t > start + h[i]) start += h[i++];
    const double u = t - start, a = coef(4 * i), b = coef(4 * i + 1), c = coef(4 * i + 2), d = coef(4 * i + 3);
    return {a + u * (b + u * (c + u * d)), b + u * (2 * c + 3 * d * u), 2 * c + 6 * d * u};
  }
};

/// Seed 002 section 7.3's first SCARA path: waypoints (x, y, z) [m], one per second.
Path3 scara_path(PathShape shape) {
  const std::vector<Eigen::Vector3d> w = {{0.4, 0, -0.3},    {0.4, -0.1, -0.3}, {0.2, -0.1, -0.3}, {0.2, -0.2, -0.3},
                                          {0.4, -0.25, -0.3}, {0.4, -0.2, -0.3}, {0.2, -0.25, -0.3}};
  return Path3(w, std::vector<double>(6, 1.0), shape);
}

/// Uneven waypoints in the plane at uneven times.
Path2 uneven_path(PathShape shape) {
  return Path2({{0.0, 1.0}, {0.7, 1.4}, {1.1, 0.2}, {0.3, -0.5}, {-0.4, 0.1}}, {0.35, 1.2, 0.6, 0.9}, shape);
}

template <int Dim>
void expect_matches_dense_oracle(const TaskPath<Dim>& p) {
  const bool clamped = p.shape() == PathShape::clamped_spline;
  for (int k = 0; k < Dim; ++k) {
    std::vector<double> y;
    for (const auto& v : p.vertices()) y.push_back(v[k]);
    const DenseSpline oracle(y, p.durations(), clamped);
    for (int j = 0; j <= 400; ++j) {
      const double t = p.duration() * j / 400.0;
      const PathSample<Dim> s = p.sample(t);
      const auto o = oracle.at(t);
      EXPECT_NEAR(s.p[k], o[0], 1e-12) << "coordinate " << k << ", t = " << t;
      EXPECT_NEAR(s.v[k], o[1], 1e-11) << "coordinate " << k << ", t = " << t;
      EXPECT_NEAR(s.a[k], o[2], 1e-10) << "coordinate " << k << ", t = " << t;
    }
  }
}

}  // namespace

TEST(SplinePath, MatchesTheDenseOracle) {
  for (PathShape shape : {PathShape::natural_spline, PathShape::clamped_spline}) {
    SCOPED_TRACE(std::string(to_string(shape)));
    expect_matches_dense_oracle(scara_path(shape));
    expect_matches_dense_oracle(uneven_path(shape));
  }
}

TEST(SplinePath, MatchesTheDenseOracleOnRandomWaypoints) {
  std::mt19937_64 gen(11);
  std::uniform_real_distribution<double> x(-2.0, 2.0), d(0.05, 3.0);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 2 + trial % 9;
    std::vector<Eigen::Vector3d> v;
    std::vector<double> h;
    for (int i = 0; i < n; ++i) v.emplace_back(x(gen), x(gen), x(gen));
    for (int i = 0; i + 1 < n; ++i) h.push_back(d(gen));
    for (PathShape shape : {PathShape::natural_spline, PathShape::clamped_spline}) {
      SCOPED_TRACE("trial " + std::to_string(trial) + ", " + std::string(to_string(shape)));
      expect_matches_dense_oracle(Path3(v, h, shape));
    }
  }
}

TEST(SplinePath, InterpolatesTheWaypointsAndIsC2) {
  for (PathShape shape : {PathShape::natural_spline, PathShape::clamped_spline}) {
    SCOPED_TRACE(std::string(to_string(shape)));
    const Path2 p = uneven_path(shape);
    double t = 0;
    for (std::size_t i = 0; i < p.vertices().size(); ++i) {
      if (i > 0) {  // the end of segment i - 1 and the start of segment i meet with value, velocity and acceleration
        const PathSample<2> left = p.sample_on(i - 1, t);
        EXPECT_LT((left.p - p.vertices()[i]).norm(), 1e-12);
        if (i < p.segments()) {
          const PathSample<2> right = p.sample_on(i, t);
          EXPECT_LT((right.p - p.vertices()[i]).norm(), 1e-12);
          EXPECT_LT((left.v - right.v).norm(), 1e-11);
          EXPECT_LT((left.a - right.a).norm(), 1e-10);
        }
      }
      EXPECT_LT((p.sample(t).p - p.vertices()[i]).norm(), 1e-12);
      if (i < p.durations().size()) t += p.durations()[i];
    }
    const double h = 1e-6;  // derivatives by central differences, inside segments
    for (double tt : {0.1, 0.5, 1.3, 2.0, 2.9}) {
      const auto s = p.sample(tt), sp = p.sample(tt + h), sm = p.sample(tt - h);
      EXPECT_LT(((sp.p - sm.p) / (2 * h) - s.v).norm(), 1e-7);
      EXPECT_LT(((sp.v - sm.v) / (2 * h) - s.a).norm(), 1e-6);
    }
  }
}

TEST(SplinePath, EndConditions) {
  const Path2 clamped = uneven_path(PathShape::clamped_spline);
  EXPECT_LT(clamped.sample(0.0).v.norm(), 1e-13);
  EXPECT_LT(clamped.sample(clamped.duration()).v.norm(), 1e-12);
  EXPECT_GT(clamped.sample(0.0).a.norm(), 1e-3);  // at rest, not still: it starts accelerating
  const Path2 natural = uneven_path(PathShape::natural_spline);
  EXPECT_LT(natural.sample(0.0).a.norm(), 1e-13);
  EXPECT_LT(natural.sample(natural.duration()).a.norm(), 1e-11);
  EXPECT_GT(natural.sample(0.0).v.norm(), 1e-3);
}

TEST(SplinePath, TwoWaypoints) {
  const Eigen::Vector2d a(0.5, -1.0), b(2.0, 3.0);
  const double T = 1.6;
  const Path2 line({a, b}, {T}, PathShape::natural_spline);
  const Path2 rest({a, b}, {T}, PathShape::clamped_spline);
  for (double t : {0.0, 0.3, 0.8, 1.25, 1.6}) {
    const double s = t / T;
    EXPECT_LT((line.sample(t).p - (a + s * (b - a))).norm(), 1e-14);
    EXPECT_LT((line.sample(t).v - (b - a) / T).norm(), 1e-14);
    EXPECT_LT(line.sample(t).a.norm(), 1e-14);
    // the cubic Hermite blend from rest to rest: 3 s^2 - 2 s^3
    EXPECT_LT((rest.sample(t).p - (a + (3 * s * s - 2 * s * s * s) * (b - a))).norm(), 1e-14);
    EXPECT_LT((rest.sample(t).v - (6 * s - 6 * s * s) / T * (b - a)).norm(), 1e-13);
    EXPECT_LT((rest.sample(t).a - (6 - 12 * s) / (T * T) * (b - a)).norm(), 1e-13);
  }
}

TEST(SplinePath, ShapeSurvivesLiftAndSampling) {
  const Path2 p = uneven_path(PathShape::natural_spline);
  const Path3 q = lift_to_3d(p);
  EXPECT_EQ(q.shape(), PathShape::natural_spline);
  const SampledPath s(p, 1e-3);
  for (std::size_t i = 0; i < s.size(); i += 37) {
    const auto x = p.sample(s.time(i));
    ASSERT_EQ(s.position(i), x.p);
    ASSERT_EQ(s.acceleration(i), x.a);
    ASSERT_EQ(q.sample(s.time(i)).p.head<2>(), x.p);
  }
}

TEST(SplinePath, QuinticIsTheDefaultShape) {
  const Path2 p({{0.0, 0.0}, {1.0, 2.0}}, {1.0});
  EXPECT_EQ(p.shape(), PathShape::quintic);
  EXPECT_NEAR(p.sample(0.5).v.norm(), 1.875 * std::sqrt(5.0), 1e-12);  // 30 s^2 (1 - s)^2 at s = 1/2: 1.875
}
