// The lane type (model/lanes.hpp) against plain scalar code: each lane's result is the scalar result
// bit for bit, NaN, infinities and signed zeros included.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "model/lanes.hpp"
#include "model/sincos.hpp"

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

#endif
