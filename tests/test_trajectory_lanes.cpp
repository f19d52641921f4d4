// Runs in SIMD lanes (methods/closed_form/lanes.hpp) against the single-run path: every metric and
// every history array bit for bit, for random batches mixing starts, gains, elbows, bounds and
// tolerances (so runs stop at different samples, or never start), every method and integrator, full
// and part-filled batches, and the seed's Table 4 cases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <random>
#include <set>
#include <vector>

#include "methods/closed_form/seed_cases.hpp"
#include "methods/closed_form/lanes.hpp"
#include "methods/metrics/sample_metrics.hpp"

using namespace ks;

namespace {

bool same(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// Every field of two metrics, bit for bit; the differences as text.
std::string differences(const TrajectoryMetrics& a, const TrajectoryMetrics& b) {
  std::string d;
  if (a.status != b.status) d += " status " + std::string(to_string(a.status)) + " vs " + std::string(to_string(b.status));
  if (a.samples != b.samples) d += " samples " + std::to_string(a.samples) + " vs " + std::to_string(b.samples);
  const std::pair<const char*, std::pair<double, double>> fields[] = {
      {"E", {a.E, b.E}},
      {"E_M", {a.E_M, b.E_M}},
      {"min_manipulability", {a.min_manipulability, b.min_manipulability}},
      {"torque_sq_integral", {a.torque_sq_integral, b.torque_sq_integral}},
      {"power_sq_integral", {a.power_sq_integral, b.power_sq_integral}},
      {"max_tracking_error", {a.max_tracking_error, b.max_tracking_error}},
      {"final_alpha", {a.final_alpha, b.final_alpha}},
      {"stop_time", {a.stop_time, b.stop_time}}};
  for (const auto& [name, v] : fields)
    if (!same(v.first, v.second)) d += std::string(" ") + name;
  if (a.tau_inf.size() != b.tau_inf.size() ||
      std::memcmp(a.tau_inf.data(), b.tau_inf.data(), sizeof(double) * a.tau_inf.size()) != 0)
    d += " tau_inf";
  // the per-sample table's entries (sample_metrics.hpp), among them those of the last sample a run adds
  for (int k = 0; k < kSampleMetricCount; ++k)
    if (!same(a.sampled[k], b.sampled[k])) d += " sampled[" + std::to_string(k) + "]";
  return d;
}

/// The first n samples of a history array (a column per sample; vectors: an entry per sample).
template <class M>
bool same_columns(const M& a, const M& b, Eigen::Index n) {
  const Eigen::Index height = M::ColsAtCompileTime == 1 ? 1 : a.rows();
  return std::memcmp(a.data(), b.data(), sizeof(double) * height * n) == 0;
}
std::string differences(const TrajectoryHistory& a, const TrajectoryHistory& b) {
  if (a.size != b.size) return " history size " + std::to_string(a.size) + " vs " + std::to_string(b.size);
  const Eigen::Index n = a.size;
  std::string d;
  if (!same_columns(a.t, b.t, n)) d += " t";
  if (!same_columns(a.q, b.q, n)) d += " q";
  if (!same_columns(a.qd, b.qd, n)) d += " qd";
  if (!same_columns(a.qdd, b.qdd, n)) d += " qdd";
  if (!same_columns(a.tau, b.tau, n)) d += " tau";
  if (!same_columns(a.x, b.x, n)) d += " x";
  if (!same_columns(a.alpha, b.alpha, n)) d += " alpha";
  return d;
}

/// Random runs of one method and integrator: alpha1A over the whole circle on some (the start often out
/// of reach), within the reachable range on the others,
/// both elbows, k in [0, 1], null-space damping on some, and on some a torque bound or a singularity
/// tolerance tight enough to stop the run part-way, at a sample that differs from run to run.
std::vector<TrajectoryOptions> random_runs(std::mt19937_64& rng, TrajectoryMethod m, Integrator integ, int count) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<TrajectoryOptions> runs;
  for (int i = 0; i < count; ++i) {
    TrajectoryOptions o;
    o.method = m;
    o.integrator = integ;
    const double deg = std::numbers::pi / 180;  // the first vertex is within reach for alpha1A in about [-24, 114] deg
    o.alpha1A = u(rng) < 0.3 ? (2 * u(rng) - 1) * 180 * deg : (-20 + 130 * u(rng)) * deg;
    o.elbow = u(rng) < 0.5 ? Elbow::positive : Elbow::negative;
    o.k = u(rng) < 0.3 ? 0.0 : u(rng);
    o.null_damping = u(rng) < 0.5 ? 0.0 : 5 * u(rng);
    if (u(rng) < 0.3) o.torque_bound = 20 + 300 * u(rng);
    if (u(rng) < 0.4) o.singular_tolerance = m == TrajectoryMethod::vertex_alpha ? 0.2 * u(rng) : 0.3 + 1.5 * u(rng);
    if (m == TrajectoryMethod::vertex_alpha)
      for (int v = 0; v < 4; ++v) o.vertex_alpha.push_back((2 * u(rng) - 1) * std::numbers::pi / 3);
    runs.push_back(o);
  }
  return runs;
}

struct Counts {
  int runs = 0, by_status[5] = {};
  std::set<std::size_t> stops;  ///< the sample counts of the runs that stopped early
};

/// Runs `runs` through simulate_lanes in batches of `lanes` (the last one part-filled when the count
/// does not divide), with histories at `stride` (0: none), and expects each run's metrics and history
/// to equal simulate() on that run alone.
void expect_lanes_equal_single_runs(int lanes, const PlanarArm3& arm, const SampledPath& path,
                                    const std::vector<TrajectoryOptions>& runs, int stride, Counts* counts = nullptr) {
  const int n = static_cast<int>(runs.size());
  std::vector<TrajectoryHistory> single(n), laned(n);
  std::vector<TrajectoryMetrics> expected(n), got(n);
  for (int i = 0; i < n; ++i) {
    single[i].stride = laned[i].stride = stride > 0 ? stride : 1;
    expected[i] = simulate(arm, path, runs[i], stride > 0 ? &single[i] : nullptr);
    if (counts) {
      ++counts->runs, ++counts->by_status[static_cast<int>(expected[i].status)];
      if (expected[i].status == RunStatus::singular || expected[i].status == RunStatus::diverged)
        counts->stops.insert(expected[i].samples);
    }
  }
  for (int first = 0; first < n; first += lanes) {
    const int count = std::min(lanes, n - first);
    std::vector<TrajectoryHistory*> h(count);
    for (int i = 0; i < count; ++i) h[i] = stride > 0 ? &laned[first + i] : nullptr;
    simulate_lanes(lanes, arm, path, &runs[first], count, &got[first], h.data());
  }
  for (int i = 0; i < n; ++i) {
    EXPECT_EQ(differences(got[i], expected[i]), "") << lanes << " lanes, run " << i << " (" << to_string(runs[i].method)
                                                    << ", " << to_string(runs[i].integrator) << ", alpha1A "
                                                    << runs[i].alpha1A << ", stride " << stride << ")";
    if (stride > 0) {
      EXPECT_EQ(differences(laned[i], single[i]), "") << lanes << " lanes, run " << i;
    }
  }
}

std::vector<int> lane_widths() {
  std::vector<int> w{1};
  if (supported_lanes() >= 4) w.push_back(4);
  if (supported_lanes() >= 8) w.push_back(8);
  return w;
}

const SampledPath& seed_path() {
  static const SampledPath p(seed_square(), 1e-3);
  return p;
}

}  // namespace

class LanesRandomBatches : public ::testing::TestWithParam<std::tuple<int, TrajectoryMethod, Integrator>> {};

// Random batches of every method and integrator, with and without histories, in 4 and 8 lanes: each
// run gets the bits of its single run; across the batches every status occurs.
TEST_P(LanesRandomBatches, EqualSingleRunsBitForBit) {
  const auto [lanes, method, integ] = GetParam();
  if (supported_lanes() < lanes) GTEST_SKIP() << "this processor or build runs " << supported_lanes() << " lanes";
  std::mt19937_64 rng(1234 + 10 * static_cast<int>(method) + static_cast<int>(integ));
  const bool rk4 = integ == Integrator::rk4;
  Counts counts;
  for (const PlanarArm3& arm : {PlanarArm3::seed(), [] {
                                  PlanarArm3 a = PlanarArm3::seed();
                                  a.inertia_form = InertiaForm::thesis_m11;
                                  return a;
                                }()}) {
    const std::vector<TrajectoryOptions> runs = random_runs(rng, method, integ, rk4 ? 24 : 40);
    expect_lanes_equal_single_runs(lanes, arm, seed_path(), runs, 0, &counts);
    expect_lanes_equal_single_runs(lanes, arm, seed_path(), runs, lanes == 4 ? 1 : 7);
  }
  for (RunStatus s : {RunStatus::ok, RunStatus::unreachable_start, RunStatus::singular, RunStatus::diverged})
    EXPECT_GT(counts.by_status[static_cast<int>(s)], 0) << "no run ended " << to_string(s);
  EXPECT_GE(counts.stops.size(), 4u) << "runs that stop early should stop at different samples";
  std::printf("%d runs: ok %d, unreachable_start %d, singular %d, diverged %d; stopped after", counts.runs,
              counts.by_status[0], counts.by_status[1], counts.by_status[2], counts.by_status[3]);
  for (std::size_t n : counts.stops) std::printf(" %zu", n);
  std::printf(" samples\n");
}

INSTANTIATE_TEST_SUITE_P(
    AllMethods, LanesRandomBatches,
    ::testing::Combine(::testing::Values(4, 8),
                       ::testing::Values(TrajectoryMethod::local_weighted, TrajectoryMethod::local_unweighted,
                                         TrajectoryMethod::vertex_alpha),
                       ::testing::Values(Integrator::semi_implicit_euler, Integrator::rk4)),
    [](const auto& info) {
      return "lanes" + std::to_string(std::get<0>(info.param)) + "_" + std::string(to_string(std::get<1>(info.param))) +
             "_" + std::string(to_string(std::get<2>(info.param)));
    });

// Batches of fewer runs than lanes (the rest masked), and batches whose only reachable run is not in
// lane 0, or that have none.
TEST(Lanes, PartFilledBatchesEqualSingleRuns) {
  if (supported_lanes() < 4) GTEST_SKIP() << "no AVX2";
  std::mt19937_64 rng(99);
  const PlanarArm3 arm = PlanarArm3::seed();
  for (int lanes : lane_widths())
    for (int count : {1, 2, 3, 5, 7}) {
      if (count > lanes) continue;
      std::vector<TrajectoryOptions> runs = random_runs(rng, TrajectoryMethod::local_weighted, Integrator::semi_implicit_euler, count);
      expect_lanes_equal_single_runs(lanes, arm, seed_path(), runs, 3);
      for (auto& o : runs) o.alpha1A = 2.5;  // out of reach at the first vertex
      runs.back().alpha1A = 0.0;
      expect_lanes_equal_single_runs(lanes, arm, seed_path(), runs, 3);
      runs.back().alpha1A = 2.5;
      expect_lanes_equal_single_runs(lanes, arm, seed_path(), runs, 0);
    }
}

// The seed's 21 Table 4 cases, with the thesis' and the physical inertia, through every lane width.
TEST(Lanes, SeedCasesEqualSingleRuns) {
  std::vector<TrajectoryOptions> by_method[3];
  for (const SeedCase& c : seed_cases()) by_method[static_cast<int>(c.method)].push_back(c.options());
  for (InertiaForm form : {InertiaForm::thesis_m11, InertiaForm::physical}) {
    PlanarArm3 arm = PlanarArm3::seed();
    arm.inertia_form = form;
    for (int lanes : lane_widths())
      for (const auto& runs : by_method) {
        expect_lanes_equal_single_runs(lanes, arm, seed_path(), runs, 0);
        std::vector<TrajectoryOptions> rk4 = runs;
        for (auto& o : rk4) o.integrator = Integrator::rk4;
        expect_lanes_equal_single_runs(lanes, arm, seed_path(), rk4, 5);
      }
  }
}

// A spline task (timed waypoints, natural and clamped): the lanes evaluate the same path, so every run
// of every method and integrator gets the bits of its single run.
TEST(Lanes, SplinePathsEqualSingleRuns) {
  std::mt19937_64 rng(2007);
  const PlanarArm3 arm = PlanarArm3::seed();
  for (PathShape shape : {PathShape::natural_spline, PathShape::clamped_spline}) {
    const SampledPath path(Path2({{1.5, 1.5}, {1.5, 2.0}, {2.0, 2.0}, {2.0, 1.5}, {1.6, 1.45}}, {0.25, 0.75, 0.5, 0.5}, shape),
                           1e-3);
    for (int lanes : lane_widths())
      for (TrajectoryMethod m :
           {TrajectoryMethod::local_weighted, TrajectoryMethod::local_unweighted, TrajectoryMethod::vertex_alpha})
        for (Integrator integ : {Integrator::semi_implicit_euler, Integrator::rk4}) {
          SCOPED_TRACE(std::string(to_string(shape)) + ", " + std::string(to_string(m)) + ", " +
                       std::string(to_string(integ)) + ", " + std::to_string(lanes) + " lanes");
          const std::vector<TrajectoryOptions> runs = random_runs(rng, m, integ, 2 * lanes);
          expect_lanes_equal_single_runs(lanes, arm, path, runs, 3);
        }
  }
}

// The same run gives the same bits whatever its neighbours and its lane.
TEST(Lanes, ARunsBitsDoNotDependOnItsNeighbours) {
  if (supported_lanes() < 4) GTEST_SKIP() << "no AVX2";
  std::mt19937_64 rng(5);
  const PlanarArm3 arm = PlanarArm3::seed();
  TrajectoryOptions probe = seed_cases()[6].options();  // 1g
  const TrajectoryMetrics alone = simulate(arm, seed_path(), probe);
  for (int lanes : lane_widths())
    for (int slot = 0; slot < lanes; ++slot) {
      std::vector<TrajectoryOptions> runs = random_runs(rng, probe.method, probe.integrator, lanes);
      runs[slot] = probe;
      std::vector<TrajectoryMetrics> got(lanes);
      simulate_lanes(lanes, arm, seed_path(), runs.data(), lanes, got.data());
      EXPECT_EQ(differences(got[slot], alone), "") << lanes << " lanes, slot " << slot;
    }
}

TEST(Lanes, WidthsAndLimits) {
  const int s = supported_lanes();
  EXPECT_TRUE(s == 1 || s == 4 || s == 8);
  EXPECT_EQ(max_lanes(), s);
  limit_lanes(1);
  EXPECT_EQ(max_lanes(), 1);
  limit_lanes(4);
  EXPECT_EQ(max_lanes(), std::min(s, 4));
  limit_lanes(0);
  EXPECT_EQ(max_lanes(), s);
  EXPECT_THROW(limit_lanes(3), std::invalid_argument);
}

TEST(Lanes, IncompatibleRunsAndBadCountsThrow) {
  const PlanarArm3 arm = PlanarArm3::seed();
  TrajectoryOptions a, b;
  EXPECT_TRUE(lane_compatible(a, b));
  b.k = 0.5, b.alpha1A = 0.3, b.elbow = Elbow::negative, b.torque_bound = 10, b.null_damping = 2;
  EXPECT_TRUE(lane_compatible(a, b));
  for (auto change : {+[](TrajectoryOptions& o) { o.integrator = Integrator::rk4; },
                      +[](TrajectoryOptions& o) { o.method = TrajectoryMethod::local_unweighted; },
                      +[](TrajectoryOptions& o) { o.dt = 2e-3; }}) {
    TrajectoryOptions c = a;
    change(c);
    EXPECT_FALSE(lane_compatible(a, c));
    const TrajectoryOptions runs[2] = {a, c};
    TrajectoryMetrics out[2];
    if (supported_lanes() >= 4) {
      EXPECT_THROW(simulate_lanes(4, arm, seed_path(), runs, 2, out), std::invalid_argument);
    }
  }
  TrajectoryMetrics out[9];
  const TrajectoryOptions runs[9] = {};
  EXPECT_THROW(simulate_lanes(max_lanes(), arm, seed_path(), runs, max_lanes() + 1, out), std::invalid_argument);
  EXPECT_THROW(simulate_lanes(3, arm, seed_path(), runs, 1, out), std::invalid_argument);
  if (supported_lanes() < 8) {
    EXPECT_THROW(simulate_lanes(8, arm, seed_path(), runs, 1, out), std::invalid_argument);
  }
  TrajectoryOptions v;
  v.method = TrajectoryMethod::vertex_alpha;  // no vertex orientations
  EXPECT_THROW(simulate_lanes(1, arm, seed_path(), &v, 1, out), std::invalid_argument);
}
