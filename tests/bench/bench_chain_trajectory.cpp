// Time of one run of the generic chain trajectory (methods/chain/trajectory.hpp) beside the closed
// form's (methods/base/trajectory.hpp), in one binary: the seed's case 1a (local_weighted, 2001 steps of
// semi-implicit Euler) on the closed-form 3R, on the same arm as a generic planar chain, on a planar
// 5R and on the 7-DOF arm7.urdf following a square in space (position, and position with the
// orientation held). The paths are sampled once, as a sweep does. Target: the generic 3R within twice
// the closed form. Ten repetitions each; read the min and median rows.
#include <benchmark/benchmark.h>

#include <algorithm>

#include "methods/chain/trajectory.hpp"
#include "methods/closed_form/seed_cases.hpp"
#include "robot/urdf.hpp"

using namespace ks;

namespace {

double min_of(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

void configure(benchmark::internal::Benchmark* b) {
  b->Unit(benchmark::kMicrosecond)->Repetitions(10)->ComputeStatistics("min", min_of)->ReportAggregatesOnly(true);
}

TrajectoryOptions options_1a() { return find_seed_case("1a")->options(); }

/// A square of side 0.2 m in the plane x = 0.5 m, from z = 0.5 to 0.7 m, 0.5 s per side.
Path3 arm7_square() {
  using V = Eigen::Vector3d;
  return Path3({V(0.5, -0.1, 0.5), V(0.5, 0.1, 0.5), V(0.5, 0.1, 0.7), V(0.5, -0.1, 0.7), V(0.5, -0.1, 0.5)},
               {0.5, 0.5, 0.5, 0.5});
}
VecN arm7_guess() {
  VecN q(7);
  q << 0.0, 0.6, 0.0, -1.4, 0.0, 0.9, 0.0;
  return q;
}

void closed_form_3r(benchmark::State& st) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const TrajectoryOptions o = options_1a();
  const SampledPath path(seed_square(), o.dt);
  for (auto _ : st) benchmark::DoNotOptimize(simulate(arm, path, o));
}

/// A chain's run to its last sample: the robots' joint limits are marked, not stopped at (a run of the
/// shipped URDFs along these squares crosses some), so every run measures the whole path.
void run_chain(benchmark::State& st, const Chain& chain, const ChainTask& task, const VecN& q0,
               TrajectoryOptions o) {
  o.on_violation = OnViolation::mark;
  const TrajectoryMetrics check = simulate(chain, task, q0, o);
  if (check.samples != task.path.size()) {
    st.SkipWithError(("run status " + std::string(to_string(check.status))).c_str());
    return;
  }
  for (auto _ : st) benchmark::DoNotOptimize(simulate(chain, task, q0, o));
  st.counters["steps/s"] = benchmark::Counter(static_cast<double>(check.samples) * st.iterations(),
                                              benchmark::Counter::kIsRate);
}

void generic_3r(benchmark::State& st) {
  const TrajectoryOptions o = options_1a();
  run_chain(st, planar_chain(planar_bars({1, 1, 1}, {5, 2, 1}, 0.1), 9.81),
            ChainTask(TaskSpace::planar_position, seed_square(), o.dt), planar_start_guess(3), o);
}

void generic_5r(benchmark::State& st) {
  const TrajectoryOptions o = options_1a();
  run_chain(st, load_urdf(KS_SOURCE_DIR "/studies/robots/planar5r.urdf", "base_link", "tool", {0, -9.81, 0}),
            ChainTask(TaskSpace::planar_position, seed_square(), o.dt), planar_start_guess(5), o);
}

void arm7(benchmark::State& st, TaskSpace space) {
  const TrajectoryOptions o = options_1a();
  run_chain(st, load_urdf(KS_SOURCE_DIR "/studies/robots/arm7.urdf", "base_link", "tool", {0, 0, -9.81}),
            ChainTask(space, arm7_square(), o.dt), arm7_guess(), o);
}

}  // namespace

BENCHMARK(closed_form_3r)->Name("run/closed_form_3r_1a")->Apply(configure);
BENCHMARK(generic_3r)->Name("run/generic_3r_1a")->Apply(configure);
BENCHMARK(generic_5r)->Name("run/generic_5r_planar5r_urdf")->Apply(configure);
BENCHMARK_CAPTURE(arm7, spatial_position, TaskSpace::spatial_position)->Name("run/arm7_spatial_position")->Apply(configure);
BENCHMARK_CAPTURE(arm7, spatial_pose, TaskSpace::spatial_pose)->Name("run/arm7_spatial_pose")->Apply(configure);
BENCHMARK_MAIN();
