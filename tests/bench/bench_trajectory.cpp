// Time of one 2001-step seed run (target for local_weighted: <= 150 us on the 2-core machine),
// with the path sampled once as a sweep does (SampledPath), and, for comparison, sampled per run;
// and per-run time in SIMD lanes (simulate_lanes: 1, 4 and 8 runs at once; items = runs).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <vector>

#include "methods/closed_form/seed_cases.hpp"
#include "methods/closed_form/lanes.hpp"

using namespace ks;

static void run(benchmark::State& st, const char* name, Integrator integ, bool history) {
  const PlanarArm3 arm = PlanarArm3::seed();
  TrajectoryOptions o = find_seed_case(name)->options();
  o.integrator = integ;
  const SampledPath path(seed_square(), o.dt);
  TrajectoryHistory h;
  for (auto _ : st) benchmark::DoNotOptimize(simulate(arm, path, o, history ? &h : nullptr));
  st.counters["steps/s"] = benchmark::Counter(2001.0 * st.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK_CAPTURE(run, local_weighted_1a, "1a", Integrator::semi_implicit_euler, false)->Unit(benchmark::kMicrosecond);
static void run_sampling_path(benchmark::State& st) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const Path2 path = seed_square();
  const TrajectoryOptions o = find_seed_case("1a")->options();
  for (auto _ : st) benchmark::DoNotOptimize(simulate(arm, path, o));
}
BENCHMARK(run_sampling_path)->Name("run/local_weighted_1a_sampling_path_per_run")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(run, local_weighted_1a_history, "1a", Integrator::semi_implicit_euler, true)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(run, local_unweighted_2a, "2a", Integrator::semi_implicit_euler, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(run, vertex_alpha_5a, "5a", Integrator::semi_implicit_euler, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(run, local_weighted_1a_rk4, "1a", Integrator::rk4, false)->Unit(benchmark::kMicrosecond);

// Runs in lanes: batches of `lanes` runs of case `name` with alpha1A spread over +-1 degree (all
// reach the end, as the seed case does); the CPU time per run is the counter per_run (and items/s = runs/s).
// Lane widths the processor does not run are skipped.
static void lanes(benchmark::State& st, const char* name, Integrator integ) {
  const int width = static_cast<int>(st.range(0));
  if (width > supported_lanes()) {
    st.SkipWithError("this processor or build does not run this lane width");
    return;
  }
  const PlanarArm3 arm = PlanarArm3::seed();
  std::vector<TrajectoryOptions> o(width, find_seed_case(name)->options());
  for (int i = 0; i < width; ++i) {
    o[i].integrator = integ;
    o[i].alpha1A += (i - width / 2) * 2e-3;
  }
  const SampledPath path(seed_square(), o[0].dt);
  std::vector<TrajectoryMetrics> out(width);
  for (auto _ : st) {
    simulate_lanes(width, arm, path, o.data(), width, out.data());
    benchmark::DoNotOptimize(out.data());
  }
  st.SetItemsProcessed(st.iterations() * width);
  // runs per CPU second, inverted: CPU time per run
  st.counters["per_run"] = benchmark::Counter(static_cast<double>(st.iterations() * width),
                                              benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
static double minimum(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }
// with --benchmark_repetitions: mean, median, stddev, cv and min of the repetitions
#define KS_LANES(name, ...)                                                                         \
  BENCHMARK_CAPTURE(lanes, name, __VA_ARGS__)->Arg(1)->Arg(4)->Arg(8)->Unit(benchmark::kMicrosecond) \
      ->ComputeStatistics("min", minimum)
KS_LANES(local_weighted_1a, "1a", Integrator::semi_implicit_euler)->Name("BM_LocalWeighted_Lanes");
KS_LANES(local_unweighted_2a, "2a", Integrator::semi_implicit_euler)->Name("BM_LocalUnweighted_Lanes");
KS_LANES(vertex_alpha_5a, "5a", Integrator::semi_implicit_euler)->Name("BM_VertexAlpha_Lanes");
KS_LANES(local_weighted_1a_rk4, "1a", Integrator::rk4)->Name("BM_LocalWeightedRk4_Lanes");
BENCHMARK_MAIN();
