// kkt_residual (methods/path_global/slsqp.hpp) at the edges of the free set: no variable, no row, rows of
// zeros, every variable held by a bound, non-finite entries. Each expected value is the definition's
// min over lambda >= 0 of |grad + jac^T lambda|_inf worked out by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "methods/path_global/slsqp.hpp"

namespace ks {
namespace {

TEST(KktResidual, NoVariableNoRowIsStationary) { EXPECT_EQ(kkt_residual({}, {}, 0), 0.0); }

TEST(KktResidual, NoVariableWithActiveRowsIsStationary) {
  // every free coefficient held by its box bound leaves an empty gradient while limit rows stay active
  EXPECT_EQ(kkt_residual({}, {}, 3), 0.0);
}

TEST(KktResidual, NoRowIsTheGradientsNorm) {
  EXPECT_EQ(kkt_residual({0.5, -2.0, 1.0}, {}, 0), 2.0);
  EXPECT_EQ(kkt_residual({-7.0}, {}, 0), 7.0);
}

TEST(KktResidual, RowsOfZerosChangeNothing) {
  // jac^T lambda = 0 for every lambda: the residual is the gradient's norm
  EXPECT_EQ(kkt_residual({1.0, -3.0}, {0.0, 0.0, 0.0, 0.0}, 2), 3.0);
  EXPECT_EQ(kkt_residual({0.0, 0.0}, {0.0, 0.0}, 1), 0.0);
}

TEST(KktResidual, ZeroRowBesideAnActiveOne) {
  // grad = (1, 0); rows (0, 0) and (-1, 0): lambda_2 = 1 cancels the gradient
  EXPECT_NEAR(kkt_residual({1.0, 0.0}, {0.0, 0.0, -1.0, 0.0}, 2), 0.0, 1e-12);
}

TEST(KktResidual, MultiplierCannotBeNegative) {
  // grad = (1, 2); row (1, 0): lambda >= 0 only adds to grad_1, so lambda = 0 and the residual is 2
  EXPECT_NEAR(kkt_residual({1.0, 2.0}, {1.0, 0.0}, 1), 2.0, 1e-12);
  // row (-1, -1): lambda = 1.5 gives (-0.5, 0.5)
  EXPECT_NEAR(kkt_residual({1.0, 2.0}, {-1.0, -1.0}, 1), 0.5, 1e-12);
}

TEST(KktResidual, MoreRowsThanVariables) {
  // one variable, three rows (0, -2, 4): lambda_2 = 0.5 cancels grad = 1
  EXPECT_NEAR(kkt_residual({1.0}, {0.0, -2.0, 4.0}, 3), 0.0, 1e-12);
}

TEST(KktResidual, NonFiniteIsNaN) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(std::isnan(kkt_residual({nan, 1.0}, {}, 0)));
  EXPECT_TRUE(std::isnan(kkt_residual({1.0, 1.0}, {inf, 0.0}, 1)));
}

TEST(KktResidual, RandomRowsOfEveryScaleStayFiniteAndNoWorseThanNoMultiplier) {
  // property: lambda = 0 is feasible, so the least-squares residual |grad + jac^T lambda|_2 is at most
  // |grad|_2 (and the inf-norm returned at most that); rows duplicated, opposed, zero or scaled by
  // 1e-9 .. 1e9 (as the windowed limit and conditioning rows of a chain's optimum are) drive the
  // active set through every multiplier dropping back to zero
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0), e(-9.0, 9.0);
  std::uniform_int_distribution<int> size(1, 6), kind(0, 5);
  for (int trial = 0; trial < 20000; ++trial) {
    const int n = size(rng), m = size(rng) + 2;
    std::vector<double> g(n), jac(static_cast<std::size_t>(n * m));
    double g2 = 0.0;
    for (double& v : g) v = u(rng) * std::pow(10.0, e(rng)), g2 += v * v;
    for (int row = 0; row < m; ++row) {
      const int k = kind(rng);
      const double scale = std::pow(10.0, e(rng));
      for (int c = 0; c < n; ++c) {
        double& v = jac[static_cast<std::size_t>(row * n + c)];
        if (k == 0) v = 0.0;
        else if (k == 1 && row > 0) v = 2.0 * jac[static_cast<std::size_t>((row - 1) * n + c)];
        else if (k == 2 && row > 0) v = -jac[static_cast<std::size_t>((row - 1) * n + c)];
        else if (k == 3) v = -g[c] * scale;
        else v = u(rng) * scale;
      }
    }
    const double r = kkt_residual(g, jac, static_cast<std::size_t>(m));
    ASSERT_TRUE(std::isfinite(r)) << "trial " << trial;
    ASSERT_LE(r, std::sqrt(g2) * (1.0 + 1e-9) + 1e-300) << "trial " << trial;
  }
}

TEST(KktResidual, JacobianOfTheWrongSizeIsRefused) {
  EXPECT_THROW(kkt_residual({1.0, 2.0}, {1.0}, 1), std::invalid_argument);
  EXPECT_THROW(kkt_residual({1.0}, {}, 2), std::invalid_argument);
}

}  // namespace
}  // namespace ks
