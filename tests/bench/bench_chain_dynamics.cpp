// Time of one evaluate_dynamics call (M, c, g, tip J, J̇ q̇, tip frame) for the planar 3R (the
// seed's arm as a chain: the planar specialisation), a planar 5R, the 7-DOF arm of
// studies/robots/arm7.urdf and the same planar 3R forced onto the spatial algorithms; and, for
// comparison, the closed-form 3R's M, c, g, J and J̇ q̇ (model/dynamics.hpp, model/kinematics.hpp).
// Each iteration takes the next of 64 random states, so nothing is constant-folded.
#include <benchmark/benchmark.h>

#include <random>

#include "model/chain_dynamics.hpp"
#include "model/dynamics.hpp"
#include "robot/urdf.hpp"

using namespace ks;

namespace {

struct States {
  std::vector<VecN> q, qd;
  explicit States(int n) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> d(-3.0, 3.0);
    for (int k = 0; k < 64; ++k) {
      VecN a(n), b(n);
      for (int i = 0; i < n; ++i) a[i] = d(rng), b[i] = d(rng);
      q.push_back(a);
      qd.push_back(b);
    }
  }
};

void run_chain(benchmark::State& st, const Chain& chain) {
  const States s(chain.dof());
  ChainData data;
  ChainState out;
  std::size_t k = 0;
  for (auto _ : st) {
    evaluate_dynamics(chain, data, s.q[k & 63], s.qd[k & 63], out);
    benchmark::DoNotOptimize(out);
    ++k;
  }
}

Chain seed3r() { return planar_chain(planar_bars({1, 1, 1}, {5, 2, 1}, 0.1), 9.81, "seed3r"); }

}  // namespace

static void closed_form_3r(benchmark::State& st) {
  const DynamicsCoefficients dc(PlanarArm3::seed());
  const PlanarArm3 arm = PlanarArm3::seed();
  const States s(3);
  std::size_t k = 0;
  for (auto _ : st) {
    const Vec3 q = s.q[k & 63], qd = s.qd[k & 63];
    const JointTrig t = joint_trig(q);
    Sym3 M = mass_matrix_sym(dc, t);
    Vec3 c = coriolis(dc, t, qd), g = gravity(dc, t);
    Mat23 J = jacobian(arm, t);
    Vec2 b = jacobian_dot_times_qd(arm, t, qd);
    benchmark::DoNotOptimize(M);
    benchmark::DoNotOptimize(c);
    benchmark::DoNotOptimize(g);
    benchmark::DoNotOptimize(J);
    benchmark::DoNotOptimize(b);
    ++k;
  }
}
BENCHMARK(closed_form_3r)->Name("closed_form/3r");

static void chain_planar_3r(benchmark::State& st) { run_chain(st, seed3r()); }
BENCHMARK(chain_planar_3r)->Name("evaluate_dynamics/planar_3r");

static void chain_planar_5r(benchmark::State& st) {
  run_chain(st, planar_chain(planar_bars({0.7, 0.6, 0.6, 0.5, 0.4}, {2.8, 2.4, 2.4, 2.0, 1.6}, 0.05), 9.81, "planar5r"));
}
BENCHMARK(chain_planar_5r)->Name("evaluate_dynamics/planar_5r");

static void chain_arm7(benchmark::State& st) {
  run_chain(st, load_urdf(KS_SOURCE_DIR "/studies/robots/arm7.urdf", "base_link", "tool", Eigen::Vector3d(0, 0, -9.81)));
}
BENCHMARK(chain_arm7)->Name("evaluate_dynamics/arm7");

static void chain_spatial_3r(benchmark::State& st) {
  Chain c = seed3r();
  c.planar_fast_path = false;
  run_chain(st, c);
}
BENCHMARK(chain_spatial_3r)->Name("evaluate_dynamics/planar_3r_spatial_algorithms");

BENCHMARK_MAIN();
