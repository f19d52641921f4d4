// Parameter space: product and zip decoding, LHS strata, deterministic draws, ranges, global ids.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <set>

#include "space/space.hpp"
#include "study/study.hpp"

using namespace ks;

namespace {
const std::string kTraj = "[[block]]\nname = \"b\"\nkind = \"trajectory\"\n";

Axis num_axis(std::string name, std::vector<double> v) {
  Axis a;
  a.name = std::move(name);
  for (double x : v) a.values.emplace_back(x);
  return a;
}
Axis str_axis(std::string name, std::vector<std::string> v) {
  Axis a;
  a.name = std::move(name);
  for (auto& x : v) a.values.emplace_back(x);
  return a;
}
double num(const Cell& c) { return std::get<double>(c); }
}  // namespace

TEST(Space, ColumnsCoverEveryParameterOfTheKind) {
  Block t({"t", BlockKind::trajectory, {}, {}, {}}, KindContext{});
  std::vector<std::string> names;
  for (const auto& c : t.columns()) names.push_back(c.name);
  EXPECT_EQ(names, (std::vector<std::string>{"preset", "method", "k", "alpha1A", "K_N", "K_L", "vertex_alpha_2",
                                             "vertex_alpha_3", "vertex_alpha_4", "vertex_alpha_5", "integrator",
                                             "dt", "torque_bound", "K_P", "K_D", "tracking_bound", "orientation_bound",
                                             "on_violation", "inertia", "start_branch", "end", "end_window",
                                             "end_gain"}));
  EXPECT_EQ(t.columns()[t.column_index("alpha1A")].unit, "rad");
  EXPECT_EQ(t.columns()[t.column_index("vertex_alpha_5")].unit, "rad");
  EXPECT_EQ(t.columns()[t.column_index("method")].type, CellType::str);
  EXPECT_EQ(t.params(0).size(), t.columns().size());

  Block ik({"i", BlockKind::ik, {}, {}, {}}, KindContext{});
  names.clear();
  for (const auto& c : ik.columns()) names.push_back(c.name);
  EXPECT_EQ(names, (std::vector<std::string>{"problem", "method", "lambda", "q0_1", "q0_2", "q0_3", "target_x",
                                             "target_y", "target_z", "target_alpha", "tol", "max_iter", "joint_limits",
                                             "restarts", "stall_window", "restart_seed", "z_mode"}));
  EXPECT_EQ(ik.columns()[ik.column_index("q0_3")].unit, "mm");
  EXPECT_EQ(ik.columns()[ik.column_index("max_iter")].type, CellType::i64);
  // Seed 001 defaults.
  const auto p = ik.params(0);
  EXPECT_EQ(std::get<std::string>(p[0]), "scara");
  EXPECT_NEAR(num(p[3]), std::numbers::pi / 3, 1e-15);
  EXPECT_EQ(num(p[6]), 50.0);
  EXPECT_EQ(num(p[7]), -80.0);
  EXPECT_EQ(num(p[8]), 10.0);
  EXPECT_TRUE(std::isnan(num(p[9])));

  Block planar({"p", BlockKind::ik, {{"problem", std::string("planar3r_pose")}}, {}, {}}, KindContext{});
  EXPECT_EQ(planar.columns()[planar.column_index("q0_3")].unit, "rad");
  EXPECT_EQ(planar.columns()[planar.column_index("target_x")].unit, "m");
}

TEST(Space, ProductVisitsEveryCombinationOnce) {
  BlockSpec spec{"b", BlockKind::trajectory, {}, {}, {}};
  spec.axes = {str_axis("method", {"local_weighted", "local_unweighted", "vertex_alpha"}),
               num_axis("alpha1A", {0.1, 0.2, 0.3, 0.4}), num_axis("k", {0, 0.25, 0.5, 0.75, 1.0})};
  Block b(spec, KindContext{});
  EXPECT_EQ(b.run_count(), 60u);
  EXPECT_EQ(b.shape(), (std::vector<std::uint64_t>{3, 4, 5}));
  std::set<std::tuple<std::string, double, double>> seen;
  const auto mi = b.column_index("method"), ai = b.column_index("alpha1A"), ki = b.column_index("k");
  for (std::uint64_t i = 0; i < b.run_count(); ++i) {
    const auto p = b.params(i);
    seen.emplace(std::get<std::string>(p[mi]), num(p[ai]), num(p[ki]));
    const auto g = b.grid_index(i);
    EXPECT_EQ(b.local_index(g), i);
    // index -> value: the cells are the axes' values at the grid index.
    EXPECT_EQ(p[mi], b.axes()[0].values[g[0]]);
    EXPECT_EQ(p[ai], b.axes()[1].values[g[1]]);
    EXPECT_EQ(p[ki], b.axes()[2].values[g[2]]);
    EXPECT_EQ(b.value(i, "k"), p[ki]);
    EXPECT_EQ(b.value(i, ai), p[ai]);
  }
  EXPECT_EQ(seen.size(), 60u);
  // Last dim fastest.
  EXPECT_EQ(b.grid_index(1), (std::vector<std::uint64_t>{0, 0, 1}));
  EXPECT_EQ(b.grid_index(5), (std::vector<std::uint64_t>{0, 1, 0}));
  EXPECT_THROW(b.params(60), std::out_of_range);
}

TEST(Space, ZipAdvancesAxesTogether) {
  const Study s = parse_study(kTraj +
                              "zip = [[\"alpha1A\", \"k\"]]\n[block.axes]\nmethod = [\"local_weighted\", "
                              "\"local_unweighted\"]\nalpha1A = [1, 2, 3]\nK_N = [0, 5]\nk = [0.1, 0.2, 0.3]\n");
  const Block& b = s.blocks[0];
  ASSERT_EQ(b.dims().size(), 3u);  // method, (alpha1A, k), K_N
  EXPECT_EQ(b.shape(), (std::vector<std::uint64_t>{2, 3, 2}));
  EXPECT_EQ(b.dims()[1].axes, (std::vector<std::size_t>{1, 3}));
  EXPECT_EQ(b.run_count(), 12u);
  std::set<std::tuple<std::string, double, double>> seen;
  for (std::uint64_t i = 0; i < b.run_count(); ++i) {
    const double a = num(b.value(i, "alpha1A")) / kDeg, k = num(b.value(i, "k"));
    EXPECT_NEAR(k, 0.1 * std::round(a), 1e-12);  // paired, never crossed
    seen.emplace(std::get<std::string>(b.value(i, "method")), a, num(b.value(i, "K_N")));
    EXPECT_EQ(b.local_index(b.grid_index(i)), i);
  }
  EXPECT_EQ(seen.size(), 12u);
}

TEST(Space, DecodingIsDirectForHugeBlocks) {
  // 10^12 runs: nothing per run is stored, decoding any index is immediate.
  BlockSpec spec{"big", BlockKind::trajectory, {}, {}, {}};
  std::vector<double> v(1000);
  for (int i = 0; i < 1000; ++i) v[i] = i;
  spec.axes = {num_axis("alpha1A", v), num_axis("k", v), num_axis("K_N", v), num_axis("dt", v)};
  for (auto& x : spec.axes[3].values) std::get<double>(x) += 1;  // dt > 0
  Block b(spec, KindContext{});
  EXPECT_EQ(b.run_count(), 1'000'000'000'000u);
  const std::uint64_t last = b.run_count() - 1;
  EXPECT_EQ(num(b.value(last, "alpha1A")), 999.0);
  EXPECT_EQ(num(b.value(last, "dt")), 1000.0);
  const std::uint64_t g[] = {123, 456, 789, 12};
  const std::uint64_t i = b.local_index(g);
  EXPECT_EQ(i, ((123ull * 1000 + 456) * 1000 + 789) * 1000 + 12);
  EXPECT_EQ(num(b.value(i, "K_N")), 789.0);
}

TEST(Space, LatinHypercubeHitsEachStratumOnce) {
  const std::uint64_t n = 50;
  const std::vector<std::pair<double, double>> ranges{{-25, 35}, {0, 1}, {10, 10.5}};
  const auto d = lhs_draws(42, n, ranges);
  ASSERT_EQ(d.size(), 3u);
  for (std::size_t j = 0; j < 3; ++j) {
    std::vector<int> hits(n, 0);
    for (double x : d[j]) {
      const double u = (x - ranges[j].first) / (ranges[j].second - ranges[j].first);
      ASSERT_GE(u, 0.0);
      ASSERT_LT(u, 1.0);
      ++hits[std::size_t(u * double(n))];
    }
    EXPECT_TRUE(std::all_of(hits.begin(), hits.end(), [](int h) { return h == 1; })) << "axis " << j;
  }
  EXPECT_EQ(lhs_draws(42, n, ranges), d);
  EXPECT_NE(lhs_draws(43, n, ranges), d);
}

TEST(Space, LatinHypercubeInAStudyIsOneDimension) {
  const Study s = parse_study(kTraj + "lhs = { count = 40, seed = 7 }\n[block.axes]\nmethod = [\"local_weighted\", "
                                      "\"local_unweighted\"]\nalpha1A = { lhs = { from = -25, to = 35 } }\n"
                                      "k = { lhs = { from = 0, to = 1 } }\n");
  const Block& b = s.blocks[0];
  EXPECT_EQ(b.shape(), (std::vector<std::uint64_t>{2, 40}));
  EXPECT_EQ(b.axes()[1].form, "lhs");
  std::vector<int> ha(40, 0), hk(40, 0);
  for (std::uint64_t i = 0; i < 40; ++i) {
    const double a = num(b.value(i, "alpha1A")) / kDeg, k = num(b.value(i, "k"));
    ++ha[std::size_t((a + 25.0) / 60.0 * 40.0 + 1e-9)];
    ++hk[std::size_t(k * 40.0)];
  }
  EXPECT_EQ(std::count(ha.begin(), ha.end(), 1), 40);
  EXPECT_EQ(std::count(hk.begin(), hk.end(), 1), 40);
}

TEST(Space, RandomDrawsAreDeterministic) {
  // mt19937_64 is fully specified by the standard (its 10000th output from the default seed).
  std::mt19937_64 rng;
  rng.discard(9999);
  EXPECT_EQ(rng(), 9981545732273789042ull);
  // Our mapping of raw draws to (0, 1) is fixed too.
  EXPECT_EQ(unit_open01(0), 0x1.0p-54);
  EXPECT_EQ(unit_open01(~0ull), 1.0 - 0x1.0p-54);
  const auto a = uniform_draws(5, 1000, -1.0, 2.0);
  EXPECT_EQ(uniform_draws(5, 1000, -1.0, 2.0), a);
  EXPECT_NE(uniform_draws(6, 1000, -1.0, 2.0), a);
  for (double x : a) {
    EXPECT_GE(x, -1.0);
    EXPECT_LT(x, 2.0);
  }
  std::mt19937_64 ref(5);
  EXPECT_EQ(a[0], -1.0 + 3.0 * unit_open01(ref()));
  // Through a study file: the same seed gives the same axis.
  const std::string t = kTraj + "[block.axes]\nk = { random = { from = 0, to = 1, count = 100, seed = 3 } }\n";
  const Study s1 = parse_study(t), s2 = parse_study(t);
  EXPECT_EQ(s1.blocks[0].axes()[0].values, s2.blocks[0].axes()[0].values);
  EXPECT_EQ(s1.blocks[0].axes()[0].form, "random");
  const Study s3 = parse_study(kTraj + "[block.axes]\nk = { random = { from = 0, to = 1, count = 100, seed = 4 } }\n");
  EXPECT_NE(s1.blocks[0].axes()[0].values, s3.blocks[0].axes()[0].values);
}

TEST(Space, RangesIncludeTheirEnd) {
  EXPECT_EQ(range_count(-25, 35, 0.25), 241u);
  EXPECT_EQ(range_count(0, 1, 0.05), 21u);
  EXPECT_EQ(range_count(-180, 180, 1.8), 201u);
  EXPECT_EQ(range_count(0.1, 0.3, 0.1), 3u);
  EXPECT_EQ(range_count(0, 1, 0.3), 4u);
  EXPECT_EQ(range_count(1, 0, -0.5), 3u);
  EXPECT_EQ(range_count(1, 0, 0.5), 0u);
  EXPECT_EQ(range_count(0, 1, 0), 0u);
  EXPECT_EQ(range_count(2, 2, 1), 1u);
  const auto v = range_values(0, 1, 0.05);
  EXPECT_EQ(v.back(), 1.0);
  EXPECT_EQ(v[3], 3 * 0.05);
  const auto l = linspace_values(0, 1, 21);
  EXPECT_EQ(l.size(), 21u);
  EXPECT_EQ(l.front(), 0.0);
  EXPECT_EQ(l.back(), 1.0);
  EXPECT_EQ(linspace_values(3, 4, 1), std::vector<double>{3});
  // Study forms: list, values, range, linspace; degrees become radians.
  const Study s = parse_study(kTraj + "[block.axes]\nalpha1A = { from = 0, to = 30, count = 3 }\n"
                                      "K_N = { values = [1, 2] }\ntorque_bound = [10, 20]\n");
  const Block& b = s.blocks[0];
  EXPECT_EQ(b.axes()[0].form, "linspace");
  EXPECT_EQ(b.axes()[1].form, "values");
  EXPECT_EQ(num(b.axes()[0].values[1]), 15 * kDeg);
  EXPECT_EQ(b.run_count(), 12u);
}

TEST(Space, GlobalRunIds) {
  const Study s = parse_study(kTraj + "[block.axes]\nk = [0, 1, 2]\n[[block]]\nname = \"c\"\nkind = \"ik\"\n"
                                      "[block.axes]\nmethod = [\"newton\", \"lm\"]\n[[block]]\nname = \"d\"\n"
                                      "kind = \"trajectory\"\n[block.axes]\nalpha1A = [1, 2, 3, 4]\n");
  EXPECT_EQ(s.run_count(), 9u);
  EXPECT_EQ(s.first_run(0), 0u);
  EXPECT_EQ(s.first_run(1), 3u);
  EXPECT_EQ(s.first_run(2), 5u);
  std::uint64_t g = 0;
  for (std::size_t bi = 0; bi < s.blocks.size(); ++bi)
    for (std::uint64_t li = 0; li < s.blocks[bi].run_count(); ++li, ++g) {
      const RunRef r = s.locate(g);
      EXPECT_EQ(r.block, bi);
      EXPECT_EQ(r.local, li);
      EXPECT_EQ(s.first_run(bi) + li, g);
    }
  EXPECT_THROW(s.locate(9), std::out_of_range);
  EXPECT_EQ(s.block_index("d"), 2u);
  EXPECT_EQ(s.block_index("zz"), Block::npos);
}

TEST(Space, InconsistentSpecsAreRejected) {
  BlockSpec bad{"b", BlockKind::trajectory, {{"k", 0.5}}, {num_axis("k", {0, 1})}, {}};
  EXPECT_THROW(Block(bad, KindContext{}), std::invalid_argument);
  BlockSpec zip{"b", BlockKind::trajectory, {}, {num_axis("k", {0, 1}), num_axis("alpha1A", {0})}, {{"k", "alpha1A"}}};
  EXPECT_THROW(Block(zip, KindContext{}), std::invalid_argument);
  BlockSpec type{"b", BlockKind::trajectory, {{"method", 1.0}}, {}, {}};
  EXPECT_THROW(Block(type, KindContext{}), std::invalid_argument);
  BlockSpec unknown{"b", BlockKind::ik, {{"alpha1A", 1.0}}, {}, {}};
  EXPECT_THROW(Block(unknown, KindContext{}), std::invalid_argument);
}
