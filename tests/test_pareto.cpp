// Pareto fronts and hypervolume (engine/pareto): the sort-based front against the O(n^2) definition on
// random points with ties, duplicates, NaN and ineligible (bad-status) runs, for 2 and 3 objectives
// of mixed senses; the hypervolume against hand-computed fronts and a grid count on random fronts.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "pareto/pareto.hpp"

namespace {

using ks::pareto::Sense;

/// The definition: eligible NaN-free points that no other such point dominates.
std::vector<std::size_t> brute_front(const std::vector<double>& v, std::size_t d, const std::vector<Sense>& senses,
                                     const std::vector<std::uint8_t>& eligible) {
  const std::size_t n = v.size() / d;
  auto ok = [&](std::size_t i) {
    if (!eligible.empty() && !eligible[i]) return false;
    for (std::size_t k = 0; k < d; ++k)
      if (std::isnan(v[i * d + k])) return false;
    return true;
  };
  auto better_or_equal = [&](std::size_t a, std::size_t b, std::size_t k) {
    return senses[k] == Sense::min ? v[a * d + k] <= v[b * d + k] : v[a * d + k] >= v[b * d + k];
  };
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < n; ++i) {
    if (!ok(i)) continue;
    bool dominated = false;
    for (std::size_t j = 0; j < n && !dominated; ++j) {
      if (j == i || !ok(j)) continue;
      bool all = true, strict = false;
      for (std::size_t k = 0; k < d; ++k) {
        all = all && better_or_equal(j, i, k);
        strict = strict || (v[j * d + k] != v[i * d + k]);
      }
      dominated = all && strict;
    }
    if (!dominated) out.push_back(i);
  }
  return out;
}

/// Random points on a coarse integer grid (many ties and duplicates), some NaN coordinates and some
/// points ineligible.
void random_points(std::mt19937_64& rng, std::size_t n, std::size_t d, int levels, std::vector<double>& v,
                   std::vector<std::uint8_t>& eligible) {
  std::uniform_int_distribution<int> value(0, levels - 1);
  std::uniform_real_distribution<double> u(0, 1);
  v.clear();
  eligible.clear();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < d; ++k) v.push_back(u(rng) < 0.05 ? std::nan("") : value(rng) * 0.5 - 3.0);
    eligible.push_back(u(rng) < 0.8);
  }
  if (n > 4)  // exact duplicates of earlier points
    for (std::size_t k = 0; k < d; ++k) v[(n - 1) * d + k] = v[k], v[(n - 2) * d + k] = v[d + k];
}

TEST(ParetoFront, MatchesBruteForce2d) {
  std::mt19937_64 rng(12345);
  const std::vector<std::vector<Sense>> senses = {
      {Sense::min, Sense::min}, {Sense::min, Sense::max}, {Sense::max, Sense::min}, {Sense::max, Sense::max}};
  std::vector<double> v;
  std::vector<std::uint8_t> eligible;
  int fronts_with_ties = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const std::size_t n = 1 + static_cast<std::size_t>(trial % 60);
    random_points(rng, n, 2, 3 + trial % 12, v, eligible);
    for (const auto& s : senses) {
      const auto expected = brute_front(v, 2, s, eligible);
      ASSERT_EQ(ks::pareto::front(v, 2, s, eligible), expected) << "trial " << trial;
      ASSERT_EQ(ks::pareto::front(v, 2, s), brute_front(v, 2, s, {})) << "trial " << trial;
      fronts_with_ties += expected.size() > 1;
    }
  }
  EXPECT_GT(fronts_with_ties, 100);
}

TEST(ParetoFront, MatchesBruteForce3d) {
  std::mt19937_64 rng(777);
  const std::vector<std::vector<Sense>> senses = {{Sense::min, Sense::min, Sense::min},
                                                  {Sense::min, Sense::max, Sense::min},
                                                  {Sense::max, Sense::min, Sense::max},
                                                  {Sense::max, Sense::max, Sense::max}};
  std::vector<double> v;
  std::vector<std::uint8_t> eligible;
  for (int trial = 0; trial < 300; ++trial) {
    const std::size_t n = 1 + static_cast<std::size_t>(trial % 80);
    random_points(rng, n, 3, 3 + trial % 10, v, eligible);
    for (const auto& s : senses) {
      ASSERT_EQ(ks::pareto::front(v, 3, s, eligible), brute_front(v, 3, s, eligible)) << "trial " << trial;
      ASSERT_EQ(ks::pareto::front(v, 3, s), brute_front(v, 3, s, {})) << "trial " << trial;
    }
  }
}

TEST(ParetoFront, DuplicatesNanAndIneligible) {
  const std::vector<Sense> s = {Sense::min, Sense::max};
  // (1,5) twice: both on the front; (1,4) dominated by them; NaN rows never; (0,9) ineligible would
  // dominate everything but is left out.
  const std::vector<double> v = {1, 5, 1, 5, 1, 4, std::nan(""), 9, 2, 6, 0, 9, 3, 6};
  const std::vector<std::uint8_t> eligible = {1, 1, 1, 1, 1, 0, 1};
  EXPECT_EQ(ks::pareto::front(v, 2, s, eligible), (std::vector<std::size_t>{0, 1, 4}));
  EXPECT_EQ(ks::pareto::front(v, 2, s), (std::vector<std::size_t>{5}));
  EXPECT_TRUE(ks::pareto::front(std::vector<double>{}, 2, s).empty());
  EXPECT_THROW(ks::pareto::front(v, 4, s), std::invalid_argument);
  EXPECT_THROW(ks::pareto::front(v, 2, s, std::vector<std::uint8_t>{1}), std::invalid_argument);
}

TEST(Hypervolume, HandComputed2d) {
  const std::vector<Sense> mm = {Sense::min, Sense::min};
  // Front (1,3), (2,2), (3,1) against (4,4), as rectangles: [1,4]x[3,4] = 3, [2,4]x[2,3] = 2,
  // [3,4]x[1,2] = 1 -> 6.
  const std::vector<double> f = {1, 3, 2, 2, 3, 1};
  EXPECT_DOUBLE_EQ(ks::pareto::hypervolume(f, 2, mm, std::vector<double>{4, 4}), 6.0);
  // A dominated point, a duplicate, a NaN and a point beyond the reference add nothing.
  const std::vector<double> g = {1, 3, 2, 2, 3, 1, 3, 3, 2, 2, std::nan(""), 0, 5, 0};
  EXPECT_DOUBLE_EQ(ks::pareto::hypervolume(g, 2, mm, std::vector<double>{4, 4}), 6.0);
  // The second objective maximised: (1,1), (2,2), (3,3) against (4,0): [1,4]x[0,1] + [2,4]x[1,2] +
  // [3,4]x[2,3] = 3 + 2 + 1.
  const std::vector<Sense> mx = {Sense::min, Sense::max};
  EXPECT_DOUBLE_EQ(ks::pareto::hypervolume(std::vector<double>{1, 1, 2, 2, 3, 3}, 2, mx, std::vector<double>{4, 0}), 6.0);
  EXPECT_DOUBLE_EQ(ks::pareto::hypervolume(std::vector<double>{}, 2, mm, std::vector<double>{4, 4}), 0.0);
  EXPECT_THROW(ks::pareto::hypervolume(f, 2, mm, std::vector<double>{4}), std::invalid_argument);
}

TEST(Hypervolume, HandComputed3d) {
  const std::vector<Sense> s3 = {Sense::min, Sense::min, Sense::min};
  // One point: a box. (1,1,1) against (3,4,5): 2*3*4 = 24.
  EXPECT_DOUBLE_EQ(ks::pareto::hypervolume(std::vector<double>{1, 1, 1}, 3, s3, std::vector<double>{3, 4, 5}), 24.0);
  // (0,0,1) and (1,1,0) against (2,2,2): A = 2*2*1 = 4, B = 1*1*2 = 2, A∩B = [1,2]x[1,2]x[1,2] = 1 -> 5.
  EXPECT_DOUBLE_EQ(ks::pareto::hypervolume(std::vector<double>{0, 0, 1, 1, 1, 0}, 3, s3, std::vector<double>{2, 2, 2}),
                   5.0);
  // Boxes from (1,0,0), (0,1,0), (0,0,1) against (2,2,2): each 1*2*2 = 4, together 12; each pair
  // meets in 1*1*2 = 2 (6 in all), all three in 1: 12 - 6 + 1 = 7.
  EXPECT_DOUBLE_EQ(
      ks::pareto::hypervolume(std::vector<double>{1, 0, 0, 0, 1, 0, 0, 0, 1}, 3, s3, std::vector<double>{2, 2, 2}), 7.0);
  // The same with the second objective maximised (y -> -y, ref y -> -ref y).
  const std::vector<Sense> mxm = {Sense::min, Sense::max, Sense::min};
  EXPECT_DOUBLE_EQ(ks::pareto::hypervolume(std::vector<double>{1, 0, 0, 0, -1, 0, 0, 0, 1}, 3, mxm,
                                           std::vector<double>{2, -2, 2}),
                   7.0);
}

/// The hypervolume counted on a grid of cell centres: a centre counts when some point dominates it.
double grid_volume(const std::vector<double>& v, std::size_t d, const std::vector<double>& lo,
                   const std::vector<double>& ref, int cells) {
  double count = 0;
  std::vector<double> c(d);
  const int total = d == 2 ? cells * cells : cells * cells * cells;
  for (int idx = 0; idx < total; ++idx) {
    int rest = idx;
    for (std::size_t k = 0; k < d; ++k) {
      c[k] = lo[k] + (rest % cells + 0.5) * (ref[k] - lo[k]) / cells;
      rest /= cells;
    }
    for (std::size_t i = 0; i < v.size() / d; ++i) {
      bool dom = true;
      for (std::size_t k = 0; k < d; ++k) dom = dom && v[i * d + k] <= c[k];
      if (dom) {
        ++count;
        break;
      }
    }
  }
  double box = 1;
  for (std::size_t k = 0; k < d; ++k) box *= ref[k] - lo[k];
  return count / total * box;
}

TEST(Hypervolume, MatchesGridCountOnRandomFronts) {
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> u(0, 1);
  for (std::size_t d : {std::size_t{2}, std::size_t{3}}) {
    const std::vector<Sense> s(d, Sense::min);
    const std::vector<double> lo(d, 0.0), ref(d, 1.0);
    const int cells = d == 2 ? 1000 : 100;
    for (int trial = 0; trial < 8; ++trial) {
      std::vector<double> v;
      for (int i = 0; i < 6 + 4 * trial; ++i)
        for (std::size_t k = 0; k < d; ++k) v.push_back(u(rng));
      const double exact = ks::pareto::hypervolume(v, d, s, ref), grid = grid_volume(v, d, lo, ref, cells);
      // a cell centre misclassified only within half a cell of a box face: d faces per point
      EXPECT_NEAR(exact, grid, d == 2 ? 0.005 : 0.03) << "d " << d << " trial " << trial;
      EXPECT_GT(exact, 0.0);
      // The front alone gives the same volume; maximising every objective of the negated points too.
      std::vector<double> fv;
      for (std::size_t i : ks::pareto::front(v, d, s))
        for (std::size_t k = 0; k < d; ++k) fv.push_back(v[i * d + k]);
      EXPECT_DOUBLE_EQ(ks::pareto::hypervolume(fv, d, s, ref), exact);
      std::vector<double> neg(v.size());
      for (std::size_t i = 0; i < v.size(); ++i) neg[i] = -v[i];
      const std::vector<double> neg_ref(d, -1.0);
      EXPECT_NEAR(ks::pareto::hypervolume(neg, d, std::vector<Sense>(d, Sense::max), neg_ref), exact, 1e-12);
    }
  }
}

}  // namespace
