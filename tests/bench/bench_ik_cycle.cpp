// The IK cycle check alone: the iterates of studies/ik_basins.toml's solves (newton, lm 0.1, halley;
// every 4th start of its 201 x 201 grid in each angle: 51 x 51 x 3 solves, about 0.4 M checks, most
// in slowly closing 2-cycles where every lag passes the 0.1 % error filter), fed to the check as the
// solver feeds it. plain: the form before ik/cycle_watch.hpp (tests/ik_cycle_oracle.hpp); watch: the
// engine's. Counter returns: cycles found (the same for both). Time and CPU: the whole replay.
#include <benchmark/benchmark.h>

#include <vector>

#include "common/angles.hpp"
#include "ik/cycle_watch.hpp"
#include "ik/solve.hpp"
#include "ik_cycle_oracle.hpp"
#include "space/space.hpp"

using namespace ks;
using namespace ks::ik;

namespace {
/// One solve's iterates as its cycle check sees them: q [rad, rad, mm], step length, ||F|| [mm].
struct Iterates {
  std::vector<Vec<3>> q;
  std::vector<double> step, error;
};

const std::vector<Iterates>& basins_iterates() {
  static const std::vector<Iterates> all = [] {
    std::vector<Iterates> out;
    ScaraPosition p;
    p.target = Vec<3>(50.0, -80.0, 10.0);
    const std::vector<double> grid = linspace_values(-180.0, 180.0, 201);
    Summary<3, 3> s;
    for (const Method m : {Method::newton, Method::lm, Method::halley}) {
      Options o;
      o.method = m;
      o.lambda = 0.1;
      for (std::size_t a = 0; a < grid.size(); a += 4)
        for (std::size_t b = 0; b < grid.size(); b += 4) {
          solve(p, Vec<3>(grid[a] * kDeg, grid[b] * kDeg, 50.0), o, s);
          Iterates it;
          std::size_t n = s.history.size();  // a converged (or stalled, ...) last iterate is not checked
          if (s.status != Status::cycle && s.status != Status::max_iter && n > 1) --n;
          for (std::size_t k = 0; k < n; ++k) {
            it.q.push_back(s.history.q[k]);
            it.step.push_back(s.history.step[k]);
            it.error.push_back(s.history.error[k]);
          }
          out.push_back(std::move(it));
        }
    }
    return out;
  }();
  return all;
}

template <class Watch>
void replay(benchmark::State& state) {
  const std::vector<Iterates>& all = basins_iterates();
  long returns = 0, checks = 0;
  for (auto _ : state) {
    returns = 0, checks = 0;
    for (const Iterates& it : all) {
      Watch w;
      w.window = 8;
      w.push(it.q[0], 0.0, it.error[0]);
      w.best_error = it.error[0];
      for (std::size_t k = 1; k < it.q.size(); ++k) {
        w.push(it.q[k], it.step[k], it.error[k]);
        returns += w.returned(ScaraPosition::revolute, 1e-8);
      }
      checks += static_cast<long>(it.q.size()) - 1;
    }
    benchmark::DoNotOptimize(returns);
  }
  state.counters["returns"] = static_cast<double>(returns);
  state.counters["checks"] = static_cast<double>(checks);
}
}  // namespace

BENCHMARK(replay<test::PlainCycleWatch<3>>)->Name("cycle_check/plain")->Unit(benchmark::kMillisecond);
BENCHMARK(replay<ik::detail::CycleWatch<3>>)->Name("cycle_check/watch")->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
