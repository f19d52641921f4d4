// fast_sincos against libm: within 2 ulp-scale error over the angles a simulation meets, and exact
// fallbacks for large and non-finite arguments.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "model/sincos.hpp"

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
