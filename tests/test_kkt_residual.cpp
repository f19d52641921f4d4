// kkt_residual (methods/global_solve.hpp) at the edges of the free set: no variable, no row, rows of
// zeros, every variable held by a bound, non-finite entries. Each expected value is the definition's
// min over lambda >= 0 of |grad + jac^T lambda|_inf worked out by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "methods/global_solve.hpp"

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

TEST(KktResidual, JacobianOfTheWrongSizeIsRefused) {
  EXPECT_THROW(kkt_residual({1.0, 2.0}, {1.0}, 1), std::invalid_argument);
  EXPECT_THROW(kkt_residual({1.0}, {}, 2), std::invalid_argument);
}

}  // namespace
}  // namespace ks
