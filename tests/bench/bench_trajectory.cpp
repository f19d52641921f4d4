// Time of one 2001-step seed run (target for local_weighted: <= 150 us on the 2-core machine),
// with the path sampled once as a sweep does (SampledPath), and, for comparison, sampled per run.
#include <benchmark/benchmark.h>

#include "methods/seed_cases.hpp"

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
BENCHMARK_MAIN();
