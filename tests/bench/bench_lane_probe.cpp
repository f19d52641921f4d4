// The trajectory kernel in lanes (simulate_lanes) against the lane probe (lane_probe.hpp), the
// minimal arithmetic of the same runs, in one process: case 1a, batches of `width` runs with alpha1A
// spread over +-1 degree as bench_trajectory's lanes benchmark does. Probe computes E only (the
// per-step arithmetic); ProbeMetrics computes every metric the kernel stores for these runs. The
// counter per_run is the CPU time per run. tests/bench/lane_probe_ratios.py runs this binary and
// prints the ratios.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <vector>

#include "lane_probe.hpp"
#include "methods/closed_form/lanes.hpp"
#include "methods/closed_form/seed_cases.hpp"

using namespace ks;

namespace {

std::vector<TrajectoryOptions> batch(int width) {
  std::vector<TrajectoryOptions> o(width, find_seed_case("1a")->options());
  for (int i = 0; i < width; ++i) o[i].alpha1A += (i - width / 2) * 2e-3;
  return o;
}

void per_run(benchmark::State& st, int width) {
  st.SetItemsProcessed(st.iterations() * width);
  st.counters["per_run"] = benchmark::Counter(static_cast<double>(st.iterations() * width),
                                              benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void kernel(benchmark::State& st) {
  const int width = static_cast<int>(st.range(0));
  if (width > supported_lanes()) {
    st.SkipWithError("this processor or build does not run this lane width");
    return;
  }
  const PlanarArm3 arm = PlanarArm3::seed();
  const std::vector<TrajectoryOptions> o = batch(width);
  const SampledPath path(seed_square(), o[0].dt);
  std::vector<TrajectoryMetrics> out(width);
  for (auto _ : st) {
    simulate_lanes(width, arm, path, o.data(), width, out.data());
    benchmark::DoNotOptimize(out.data());
  }
  per_run(st, width);
}

void probe(benchmark::State& st, ks_probe::Metrics metrics) {
  const int width = static_cast<int>(st.range(0));
  if ((width == 4 && !ks_probe::runs_x4()) || (width == 8 && !ks_probe::runs_x8())) {
    st.SkipWithError("this processor or build does not run this lane width");
    return;
  }
  const std::vector<TrajectoryOptions> o = batch(width);
  std::vector<double> alpha(width), k(width);
  std::vector<ks_probe::ProbeResult> out(width);
  for (int i = 0; i < width; ++i) alpha[i] = o[i].alpha1A, k[i] = o[i].k;
  const ks_probe::ProbePath path = ks_probe::seed_square_path(o[0].dt);
  const auto run = width == 8 ? ks_probe::run_x8 : width == 4 ? ks_probe::run_x4 : ks_probe::run_x1;
  for (auto _ : st) {
    run(metrics, path, alpha.data(), k.data(), out.data());
    benchmark::DoNotOptimize(out.data());
  }
  per_run(st, width);
}

double minimum(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

}  // namespace

BENCHMARK(kernel)->Name("Kernel")->Arg(1)->Arg(4)->Arg(8)->Unit(benchmark::kMicrosecond)->ComputeStatistics("min", minimum);
BENCHMARK_CAPTURE(probe, e, ks_probe::Metrics::E)->Name("Probe")->Arg(1)->Arg(4)->Arg(8)->Unit(benchmark::kMicrosecond)->ComputeStatistics("min", minimum);
BENCHMARK_CAPTURE(probe, all, ks_probe::Metrics::all)->Name("ProbeMetrics")->Arg(1)->Arg(4)->Arg(8)->Unit(benchmark::kMicrosecond)->ComputeStatistics("min", minimum);
BENCHMARK_MAIN();
