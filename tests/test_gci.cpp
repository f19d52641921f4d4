// The grid convergence index (verify/gci.hpp) on functions of known order: f(h) = f0 + C h^p
// sampled at h, 2h, 4h. The oracle is the function itself: its exact value f0 and order p.
#include <gtest/gtest.h>

#include <cmath>

#include "verify/gci.hpp"

namespace ks {
namespace {

struct Known {
  double f0, c, p;
  double at(double h) const { return f0 + c * std::pow(h, p); }
};

/// The grid study of `f` at h, 2h, 4h (grid 1 the finest).
GciResult study(const Known& f, double h) { return grid_convergence(f.at(h), f.at(2 * h), f.at(4 * h), 2.0); }

TEST(Gci, RecoversOrderAndValueOfKnownFunctions) {
  for (const Known f : {Known{2.0, 3.0, 2.0}, Known{2.0, 3.0, 1.0}, Known{-1.5, 0.25, 1.5}, Known{34.36, -7.0, 4.0},
                        Known{1.0, -0.5, 0.5}}) {
    for (const double h : {0.02, 0.1, 0.2}) {
      SCOPED_TRACE("f0 " + std::to_string(f.f0) + " p " + std::to_string(f.p) + " h " + std::to_string(h));
      const GciResult g = study(f, h);
      ASSERT_EQ(g.convergence, Convergence::monotone);
      EXPECT_NEAR(g.order, f.p, 1e-9 * f.p + 1e-12 / (std::abs(f.c) * std::pow(h, f.p)));
      EXPECT_NEAR(g.extrapolated, f.f0, 1e-12 * (1 + std::abs(f.f0)));
      EXPECT_NEAR(g.ratio, std::pow(2.0, -f.p), 1e-9);
      // with the exact order, (f1 - f2) / (r^p - 1) is f1's own error: the GCI is Fs times the
      // relative error of the fine grid, and of the coarse grid
      const double f1 = f.at(h), f3 = f.at(4 * h);
      EXPECT_NEAR(g.gci_fine, 1.25 * std::abs((f1 - f.f0) / f1), 1e-8 * g.gci_fine + 1e-14);
      EXPECT_NEAR(g.gci_coarse, 1.25 * std::abs((f3 - f.f0) / f3), 1e-8 * g.gci_coarse + 1e-14);
    }
  }
}

TEST(Gci, SafetyFactorScalesTheBand) {
  const Known f{2.0, 3.0, 2.0};
  GciOptions three;
  three.safety_factor = 3.0;  // Roache's factor for two grids
  const GciResult a = study(f, 0.1), b = grid_convergence(f.at(0.1), f.at(0.2), f.at(0.4), 2.0, three);
  EXPECT_NEAR(b.gci_fine / a.gci_fine, 3.0 / 1.25, 1e-12);
  EXPECT_EQ(a.extrapolated, b.extrapolated);
  GciOptions bad;
  bad.safety_factor = 0.5;
  std::string why;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("safety_factor"), std::string::npos) << why;
  EXPECT_EQ(grid_convergence(1, 2, 3, 2.0, bad).convergence, Convergence::not_enough);
}

TEST(Gci, RefinementRatioOtherThanTwo) {
  const Known f{5.0, 2.0, 2.0};
  const double h = 0.01, r = 3.0;
  const GciResult g = grid_convergence(f.at(h), f.at(r * h), f.at(r * r * h), r);
  ASSERT_EQ(g.convergence, Convergence::monotone);
  EXPECT_NEAR(g.order, 2.0, 1e-9);
  EXPECT_NEAR(g.extrapolated, 5.0, 1e-12);
}

TEST(Gci, DivergenceIsSaidNotNumbered) {
  // a peak that grows as the grid is refined: f(h) = 1/h (changes grow), and changes of equal size
  const Known grows{0.0, 1.0, -1.0};
  for (const GciResult g : {study(grows, 0.1), grid_convergence(3.0, 2.0, 1.0, 2.0), grid_convergence(1.0, 2.0, 2.0, 2.0)}) {
    EXPECT_EQ(g.convergence, Convergence::divergent);
    EXPECT_TRUE(std::isnan(g.order));
    EXPECT_TRUE(std::isnan(g.extrapolated));
    EXPECT_TRUE(std::isnan(g.gci_fine));
    EXPECT_TRUE(std::isnan(g.gci_coarse));
  }
  // the tip torque of a path that passes a singularity between samples: 182, 319, 573 Nm at
  // 80, 160, 320 knots (grid 1 the finest)
  EXPECT_EQ(grid_convergence(573.0, 319.0, 182.0, 2.0).convergence, Convergence::divergent);
}

TEST(Gci, OscillationIsSaidNotNumbered) {
  const GciResult g = grid_convergence(1.0, 1.1, 0.9, 2.0);
  EXPECT_EQ(g.convergence, Convergence::oscillatory);
  EXPECT_LT(g.ratio, 0.0);
  EXPECT_TRUE(std::isnan(g.order));
  EXPECT_TRUE(std::isnan(g.extrapolated));
  EXPECT_TRUE(std::isnan(g.gci_fine));
}

TEST(Gci, UnchangedAndExactFinePair) {
  const GciResult same = grid_convergence(4.0, 4.0, 4.0, 2.0);
  EXPECT_EQ(same.convergence, Convergence::unchanged);
  EXPECT_EQ(same.extrapolated, 4.0);
  EXPECT_EQ(same.gci_fine, 0.0);
  EXPECT_EQ(same.gci_coarse, 0.0);
  const GciResult fine = grid_convergence(4.0, 4.0, 5.0, 2.0);
  EXPECT_EQ(fine.convergence, Convergence::monotone);
  EXPECT_TRUE(std::isinf(fine.order));
  EXPECT_EQ(fine.extrapolated, 4.0);
  EXPECT_EQ(fine.gci_fine, 0.0);
  EXPECT_NEAR(fine.gci_coarse, 1.25 * 0.2, 1e-15);
}

TEST(Gci, MissingValuesAreNotEnough) {
  const double nan = std::nan("");
  for (const GciResult g : {grid_convergence(nan, 1, 2, 2.0), grid_convergence(1, 2, INFINITY, 2.0),
                            grid_convergence(1, 2, 3, 1.0), grid_convergence(1, 2, 3, nan)}) {
    EXPECT_EQ(g.convergence, Convergence::not_enough);
    EXPECT_TRUE(std::isnan(g.order));
    EXPECT_TRUE(std::isnan(g.gci_fine));
  }
}

TEST(Gci, NamesRoundTrip) {
  for (const Convergence c : {Convergence::monotone, Convergence::unchanged, Convergence::oscillatory,
                              Convergence::divergent, Convergence::not_enough}) {
    Convergence back = Convergence::monotone;
    ASSERT_TRUE(parse(to_string(c), back));
    EXPECT_EQ(back, c);
  }
  Convergence x;
  EXPECT_FALSE(parse("converged", x));
}

}  // namespace
}  // namespace ks
