// The seed's pipeline for case 1h -- a GA-like global search (GN_ESCH, population 50, 5000 evaluations)
// then SQP (LD_SLSQP, finite differences) -- on 2 threads (the seed under Octave: ~40 min).
// Also sweep then polish (1h: a 0.1 deg x 0.01 landscape's 8 best cells, BOBYQA from each, in parallel).
#include <benchmark/benchmark.h>

#include "runner/optimize_blocks.hpp"
#include "study/study.hpp"

namespace {
const char* kSeedPipeline = R"(
[robot]
inertia = "thesis_m11"
[[optimize]]
preset = "1h"
[optimize.global]
algorithm = "GN_ESCH"
population = 50
max_evals = 5000
ftol_abs = 1e-6
[optimize.local]
algorithm = "LD_SLSQP"
max_evals = 400
)";

void BM_Case1h_GaLikeThenSqp(benchmark::State& state) {
  const ks::Study s = ks::parse_study(kSeedPipeline, "bench.toml");
  ks::OptimizeRunOptions o;
  o.threads = static_cast<int>(state.range(0));
  double best = 0, evals = 0;
  for (auto _ : state) {
    const ks::OptimizeResult r = ks::run_optimization(s, 0, o);
    best = r.record.best_objective;
    evals = static_cast<double>(r.record.size());
  }
  state.counters["E_best"] = best;
  state.counters["evaluations"] = evals;
}
BENCHMARK(BM_Case1h_GaLikeThenSqp)->Arg(2)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

// The same 5000 global evaluations as two concurrent ESCH islands of 2500 (seeds 42, 43), then SQP
// from each island's best point: both threads busy during the global stage.
void BM_Case1h_TwoIslandsThenSqp(benchmark::State& state) {
  const ks::Study s = ks::parse_study(R"(
[robot]
inertia = "thesis_m11"
[[optimize]]
preset = "1h"
[optimize.global]
algorithm = "GN_ESCH"
population = 50
max_evals = 2500
islands = 2
ftol_abs = 1e-6
[optimize.local]
algorithm = "LD_SLSQP"
max_evals = 400
starts = 2
)", "bench.toml");
  ks::OptimizeRunOptions o;
  o.threads = static_cast<int>(state.range(0));
  double best = 0, evals = 0;
  for (auto _ : state) {
    const ks::OptimizeResult r = ks::run_optimization(s, 0, o);
    best = r.record.best_objective;
    evals = static_cast<double>(r.record.size());
  }
  state.counters["E_best"] = best;
  state.counters["evaluations"] = evals;
}
BENCHMARK(BM_Case1h_TwoIslandsThenSqp)->Arg(2)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

void BM_Case1h_SweepThenPolish(benchmark::State& state) {
  const ks::Study s = ks::parse_study(R"(
[robot]
inertia = "thesis_m11"
[[block]]
name = "landscape"
kind = "trajectory"
method = "local_weighted"
[block.axes]
alpha1A = { from = -30, to = -15, step = 0.1 }
k = { from = 0, to = 1, step = 0.01 }
[[optimize]]
preset = "1h"
variables = { alpha1A = [-40, 40], k = [0, 1] }
polish_from = { block = "landscape", best = 8 }
[optimize.local]
algorithm = "LN_BOBYQA"
max_evals = 1000
)", "bench.toml");
  ks::OptimizeRunOptions o;
  o.threads = static_cast<int>(state.range(0));
  double best = 0;
  for (auto _ : state) best = ks::run_optimization(s, 0, o).record.best_objective;
  state.counters["E_best"] = best;
}
BENCHMARK(BM_Case1h_SweepThenPolish)->Arg(2)->Unit(benchmark::kMillisecond)->Iterations(2)->UseRealTime();
}  // namespace

BENCHMARK_MAIN();
