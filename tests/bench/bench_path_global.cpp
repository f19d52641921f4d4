// One evaluation of the seed 3R path-global objective (20-knot cubic spline, 2001 samples, objective E):
// the value alone and the value with its gradient, in each extension; and one whole run (the local
// start, the SLSQP solve, the measure and the verification between samples). Per sample: the counter
// the counter per_sample (seconds).
#include <benchmark/benchmark.h>

#include <vector>

#include "methods/path_global/alpha_basis.hpp"
#include "methods/path_global/closed_form.hpp"
#include "methods/path_global/solve_closed_form.hpp"
#include "path_global_fixtures.hpp"
#include "task/task_path.hpp"

using namespace ks;


static void evaluation(benchmark::State& st, Extension ext, bool gradient) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const SampledPath path(seed_square(), 1e-3);
  const PathGlobalProblem problem(arm, path, Elbow::positive, 1e-9, ext);
  const AlphaBasis b = cubic_spline_basis(path, 20);
  const std::vector<double> c = case4_fit(problem, path, b);
  std::vector<double> g(b.coefficients);
  for (auto _ : st) benchmark::DoNotOptimize(problem.objective(b, c.data(), GlobalObjective::E, gradient ? g.data() : nullptr));
  st.counters["per_sample"] = benchmark::Counter(static_cast<double>(path.size()) * st.iterations(),
                                                 benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK_CAPTURE(evaluation, self_motion_value, Extension::self_motion, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(evaluation, self_motion_gradient, Extension::self_motion, true)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(evaluation, alpha_value, Extension::alpha, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(evaluation, alpha_gradient, Extension::alpha, true)->Unit(benchmark::kMicrosecond);

static void run(benchmark::State& st, Extension ext) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const SampledPath path(seed_square(), 1e-3);
  TrajectoryOptions o;
  o.method = TrajectoryMethod::global_spline;
  o.global.knots = 20;
  o.global.extension = ext;
  double evaluations = 0;
  for (auto _ : st) evaluations = solve_global_spline(arm, path, o).opt_evaluations;
  st.counters["evaluations"] = evaluations;
}
BENCHMARK_CAPTURE(run, self_motion, Extension::self_motion)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(run, alpha, Extension::alpha)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
