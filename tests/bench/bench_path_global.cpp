// One evaluation of the seed 3R path-global objective (20-knot cubic spline, 2001 samples, objective E):
// the value alone and the value with its gradient, in each extension; and one whole run (the local
// start, the SLSQP solve, the measure and the verification between samples). Per sample: the counter
// the counter per_sample (seconds).
#include <benchmark/benchmark.h>

#include <vector>

#include "methods/path_global/alpha_basis.hpp"
#include "methods/path_global/closed_form.hpp"
#include "methods/path_global/solve_closed_form.hpp"
#include "task/quintic_path.hpp"

using namespace ks;

namespace {
constexpr double kDegree = 3.14159265358979323846 / 180.0;

// the thesis' case 4 alpha(t) in the extension's coordinate, fitted by the 20-knot spline
std::vector<double> case4(const PathGlobalProblem& problem, const SampledPath& path, const AlphaBasis& b) {
  const std::vector<double> thesis4{-18.3 * kDegree, 18.3 * kDegree, 18.9 * kDegree, -10.3 * kDegree, -8.6 * kDegree};
  const AlphaBasis v = vertex_quintic_basis(path);
  std::vector<double> x(path.size());
  for (std::size_t i = 0; i < path.size(); ++i) {
    double a, ad, add;
    v.at(i, thesis4.data(), a, ad, add);
    x[i] = problem.coordinate(i, a, Elbow::positive);
  }
  return fit_basis(b, x.data(), x.size());
}
}  // namespace

static void evaluation(benchmark::State& st, Extension ext, bool gradient) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const SampledPath path(seed_square(), 1e-3);
  const PathGlobalProblem problem(arm, path, Elbow::positive, 1e-9, ext);
  const AlphaBasis b = cubic_spline_basis(path, 20);
  const std::vector<double> c = case4(problem, path, b);
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
