// The lane type (model/lanes.hpp) and the step's algebra written over it, against plain scalar code
// and Eigen: each lane's result is the scalar result bit for bit, NaN, infinities and signed zeros
// included.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "methods/base/resolution.hpp"
#include "model/lanes.hpp"
#include "model/trig.hpp"

using namespace ks;

namespace {
bool same(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
/// The same bits, or both NaN: which NaN an operation on two NaN operands returns depends on the
/// operand order the compiler picks (+ and * commute), and no NaN of the step reaches a result.
bool same_or_nan(double a, double b) { return same(a, b) || (std::isnan(a) && std::isnan(b)); }
const double kNaN = std::numeric_limits<double>::quiet_NaN(), kInf = std::numeric_limits<double>::infinity();

/// Values that exercise the corners: signed zeros, NaN, infinities, ties, ordinary numbers.
std::vector<double> corner_values() {
  return {0.0, -0.0, 1.0, -1.0, 0.5, -2.5, 1e-300, -1e300, kNaN, -kNaN, kInf, -kInf, 3.0, 3.0};
}
}  // namespace

// The two algebra helpers whose sums Eigen orders: the written-out forms equal Eigen's bit for bit.
TEST(LaneAlgebra, ManipulabilityEqualsEigensRowSums) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int n = 0; n < 20000; ++n) {
    Mat23 J;
    for (int k = 0; k < 6; ++k) J.data()[k] = u(rng);
    const double a = J.row(0).squaredNorm(), b = J.row(0).dot(J.row(1)), c = J.row(1).squaredNorm();
    const double d = a * c - b * b, eigen = d > 0.0 ? d : 0.0;
    ASSERT_TRUE(same(manipulability_squared(J), eigen)) << n;
  }
}

// nonredundant_acceleration (Eigen's PartialPivLU written out, pivots per lane) against PartialPivLU
// itself: random Jacobians, and ones built from corner values (ties between pivots, zero columns,
// NaN and infinities).
TEST(LaneAlgebra, NonredundantSolveEqualsEigensPartialPivLu) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-2, 2);
  const std::vector<double> corners = corner_values();
  std::uniform_int_distribution<std::size_t> pick(0, corners.size() - 1);
  for (int n = 0; n < 40000; ++n) {
    Mat23 J;
    for (int k = 0; k < 6; ++k) J.data()[k] = n % 2 ? u(rng) : corners[pick(rng)];
    if (n % 7 == 0) J(1, 0) = -J(0, 0);  // equal magnitudes in the first pivot column
    if (n % 11 == 0) J(0, 0) = 1.0;      // a tie with the row of ones
    const Vec2 b(u(rng), u(rng));
    const double add = u(rng);
    Mat3 J3;
    J3.topRows<2>() = J;
    J3.row(2).setOnes();
    const Eigen::PartialPivLU<Mat3> lu(J3);
    const Vec3 want = lu.solve(Vec3(b.x(), b.y(), add));
    double det = 0;
    const Vec3 got = nonredundant_acceleration<double>(J, b, add, det);
    ASSERT_TRUE(same_or_nan(det, lu.determinant())) << n << ": " << det << " vs " << lu.determinant() << "\n" << J3;
    for (int j = 0; j < 3; ++j) ASSERT_TRUE(same_or_nan(got[j], want[j])) << n << " " << j << "\n" << J3;
  }
}

#if defined(__AVX2__)
TEST(LaneType, OperationsAreTheScalarOnesPerLane) {
  const std::vector<double> v = corner_values();
  for (double a0 : v)
    for (double b0 : v) {
      const double av[4] = {a0, b0, -a0, 1.5}, bv[4] = {b0, a0, 2.0, -b0};
      const F64x4 a = F64x4::load(av), b = F64x4::load(bv);
      for (int l = 0; l < 4; ++l) {
        const double x = av[l], y = bv[l];
        EXPECT_TRUE(same_or_nan(lane(a + b, l), x + y));
        EXPECT_TRUE(same_or_nan(lane(a - b, l), x - y));
        EXPECT_TRUE(same_or_nan(lane(a * b, l), x * y));
        EXPECT_TRUE(same_or_nan(lane(a / b, l), x / y));
        EXPECT_TRUE(same(lane(-a, l), -x));
        EXPECT_TRUE(same(lane(vabs(a), l), std::abs(x)));
        EXPECT_TRUE(same_or_nan(lane(vsqrt(a), l), std::sqrt(x)));
        EXPECT_TRUE(same(lane(vmin(a, b), l), std::min(x, y))) << x << " " << y;
        EXPECT_TRUE(same(lane(vmax(a, b), l), std::max(x, y))) << x << " " << y;
        EXPECT_EQ(bits(a < b) >> l & 1, x < y);
        EXPECT_EQ(bits(a <= b) >> l & 1, x <= y);
        EXPECT_EQ(bits(a > b) >> l & 1, x > y);
        EXPECT_EQ(bits(a >= b) >> l & 1, x >= y);
        EXPECT_EQ(bits(a == b) >> l & 1, x == y);
        EXPECT_EQ(bits(a != b) >> l & 1, x != y);
        EXPECT_TRUE(same(lane(select(a < b, a, b), l), x < y ? x : y));
        EXPECT_EQ(bits(!(a < b)) >> l & 1, !(x < y));
      }
    }
}

// sincos in lanes equals fast_sincos in every lane: quadrant boundaries, signed zeros, the libm range
// (|x| >= 1e5, NaN, infinities) mixed with ordinary lanes.
TEST(LaneType, SincosEqualsFastSincosPerLane) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-40, 40);
  std::vector<double> xs = {0.0, -0.0, 1e5, -1e5, 99999.9, 1e7, kNaN, kInf, -kInf, 1e-310};
  for (int k = -20; k <= 20; ++k) xs.push_back(k * M_PI / 4), xs.push_back(std::nextafter(k * M_PI / 4, 100.0));
  for (int n = 0; n < 4000; ++n) xs.push_back(u(rng));
  for (std::size_t i = 0; i + 4 <= xs.size(); ++i) {
    const F64x4 x = F64x4::load(&xs[i]);
    F64x4 s, c;
    sincos_lanes(x, s, c);
    for (int l = 0; l < 4; ++l) {
      double s1, c1;
      fast_sincos(xs[i + l], s1, c1);
      ASSERT_TRUE(same_or_nan(lane(s, l), s1)) << xs[i + l];
      ASSERT_TRUE(same_or_nan(lane(c, l), c1)) << xs[i + l];
    }
  }
}

// The tracker in lanes: each lane makes its own choice between rotation and direct evaluation, and
// its values are those of the scalar tracker fed that lane's steps.
TEST(LaneType, TrigTrackerLanesFollowScalarTrackers) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> step(-0.012, 0.012);
  double q[4][3] = {{0.3, -1.2, 2.5}, {1.0, 0.2, -0.4}, {-2.0, 1.1, 0.0}, {0.0, 0.0, 0.0}};
  std::vector<TrigTracker> scalar;
  for (auto& r : q) scalar.emplace_back(Vec3(r[0], r[1], r[2]));
  auto lanes_of_q = [&] {
    LaneVec<F64x4, 3> v;
    for (int j = 0; j < 3; ++j) {
      const double c[4] = {q[0][j], q[1][j], q[2][j], q[3][j]};
      v[j] = F64x4::load(c);
    }
    return v;
  };
  TrigTrackerOf<F64x4> tracker(lanes_of_q());
  for (int i = 0; i < 3000; ++i) {
    double dq[4][3];
    for (int l = 0; l < 4; ++l)
      for (int j = 0; j < 3; ++j) {
        dq[l][j] = (i + l) % 101 == 0 ? 0.5 : step(rng);
        q[l][j] += dq[l][j];
      }
    LaneVec<F64x4, 3> d;
    for (int j = 0; j < 3; ++j) {
      const double c[4] = {dq[0][j], dq[1][j], dq[2][j], dq[3][j]};
      d[j] = F64x4::load(c);
    }
    tracker.advance(lanes_of_q(), d);
    for (int l = 0; l < 4; ++l) {
      scalar[l].advance(Vec3(q[l][0], q[l][1], q[l][2]), Vec3(dq[l][0], dq[l][1], dq[l][2]));
      const JointTrig& s = scalar[l].trig();
      const JointTrigOf<F64x4>& t = tracker.trig();
      ASSERT_TRUE(same(lane(t.s1, l), s.s1) && same(lane(t.c1, l), s.c1) && same(lane(t.s23, l), s.s23) &&
                  same(lane(t.c123, l), s.c123) && same(lane(t.s12, l), s.s12))
          << "step " << i << " lane " << l;
    }
  }
}
#endif
