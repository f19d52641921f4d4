// Sobol' indices from a Saltelli design (space/saltelli.cpp, sensitivity/sobol_indices.cpp): the
// design's AB matrices against A and B (a property), the Ishigami function's analytic indices inside
// the estimator's bootstrap intervals at N = 2^14, and failed runs counted, not silently dropped.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <span>
#include <vector>

#include "sensitivity/sobol_indices.hpp"
#include "space/space.hpp"

namespace {
using namespace ks;

TEST(SaltelliDesign, ABTakesOneColumnFromBAndTheRestFromA) {
  const std::vector<std::pair<double, double>> ranges{{0, 1}, {-2, 2}, {10, 20}};
  const std::uint64_t n = 64;
  const auto x = saltelli_draws(5, n, ranges);
  ASSERT_EQ(x.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    ASSERT_EQ(x[i].size(), n * 5);
    for (double v : x[i]) {
      EXPECT_GE(v, ranges[i].first);
      EXPECT_LT(v, ranges[i].second);
    }
    for (std::uint64_t m = 0; m < 3; ++m)
      for (std::uint64_t j = 0; j < n; ++j)
        EXPECT_EQ(x[i][(2 + m) * n + j], m == i ? x[i][n + j] : x[i][j]) << "factor " << i << " AB_" << m;
  }
  // A and B differ (different Sobol' coordinates), and the seed changes the points
  EXPECT_NE(x[0][0], x[0][n]);
  EXPECT_NE(saltelli_draws(6, n, ranges)[0][0], x[0][0]);
  EXPECT_EQ(saltelli_draws(5, n, ranges), x);
}

double ishigami(double x1, double x2, double x3) {
  return std::sin(x1) + 7.0 * std::sin(x2) * std::sin(x2) + 0.1 * std::pow(x3, 4) * std::sin(x1);
}

struct Outputs {
  std::vector<double> a, b;
  std::vector<std::vector<double>> ab;
  std::vector<std::span<const double>> spans() const {
    std::vector<std::span<const double>> s;
    for (const auto& v : ab) s.emplace_back(v);
    return s;
  }
};

Outputs ishigami_outputs(std::uint64_t n, std::uint64_t seed) {
  const double pi = std::numbers::pi;
  const std::vector<std::pair<double, double>> ranges(3, {-pi, pi});
  const auto x = saltelli_draws(seed, n, ranges);
  auto f = [&](std::uint64_t r) { return ishigami(x[0][r], x[1][r], x[2][r]); };
  Outputs o;
  o.ab.resize(3);
  for (std::uint64_t j = 0; j < n; ++j) {
    o.a.push_back(f(j));
    o.b.push_back(f(n + j));
    for (std::uint64_t m = 0; m < 3; ++m) o.ab[m].push_back(f((2 + m) * n + j));
  }
  return o;
}

TEST(SobolIndices, IshigamiAnalyticIndicesLieInTheBootstrapIntervals) {
  // a = 7, b = 0.1 (Ishigami and Homma 1990; Saltelli et al. 2010)
  const double first[3] = {0.3139, 0.4424, 0.0}, total[3] = {0.5576, 0.4424, 0.2437};
  const Outputs o = ishigami_outputs(1 << 14, 2);
  const SobolIndices s = sobol_indices(o.a, o.b, o.spans());
  EXPECT_EQ(s.samples, 1u << 14);
  EXPECT_EQ(s.dropped, 0u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(s.first_lo[i], first[i]) << "S" << i + 1 << " = " << s.first[i];
    EXPECT_GE(s.first_hi[i], first[i]) << "S" << i + 1 << " = " << s.first[i];
    EXPECT_LE(s.total_lo[i], total[i]) << "ST" << i + 1 << " = " << s.total[i];
    EXPECT_GE(s.total_hi[i], total[i]) << "ST" << i + 1 << " = " << s.total[i];
    EXPECT_LT(s.first_hi[i] - s.first_lo[i], 0.1);  // informative intervals, not [-inf, inf]
    EXPECT_LT(s.total_hi[i] - s.total_lo[i], 0.1);
  }
  // the output variance: a^2/8 + b pi^4/5 + b^2 pi^8/18 + 1/2
  const double pi = std::numbers::pi;
  EXPECT_NEAR(s.variance, 49.0 / 8 + 0.1 * std::pow(pi, 4) / 5 + 0.01 * std::pow(pi, 8) / 18 + 0.5, 0.2);
}

TEST(SobolIndices, RowsWithAFailedRunAreCountedAndLeftOut) {
  Outputs o = ishigami_outputs(256, 3);
  const SobolIndices all = sobol_indices(o.a, o.b, o.spans(), {0, 0.95, 1});
  o.ab[1][10] = std::nan("");
  o.a[20] = std::nan("");
  o.b[20] = std::nan("");  // the same row twice: one row dropped
  const SobolIndices some = sobol_indices(o.a, o.b, o.spans(), {0, 0.95, 1});
  EXPECT_EQ(some.samples, 254u);
  EXPECT_EQ(some.dropped, 2u);
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(std::isfinite(some.first[i]) && std::isfinite(some.total[i]));
  EXPECT_NE(some.first[0], all.first[0]);
  EXPECT_THROW(sobol_indices(o.a, std::span<const double>(o.b).first(3), o.spans()), std::invalid_argument);
  EXPECT_THROW(sobol_indices(o.a, o.b, o.spans(), {-1, 0.95, 1}), std::invalid_argument);
}

}  // namespace
