// IK side by side: our solvers against Orocos KDL's ChainIkSolverPos_LMA and
// ChainIkSolverPos_NR (ChainFkSolverPos_recursive + ChainIkSolverVel_pinv) on the SAME planar-3R
// problems. Problem set (seeded): 1000 targets = FK of uniformly random joint states of the seed's
// arm (l = 1 m), position + orientation alpha; starts either "near" (the generating joint state plus
// a uniform perturbation of +-1 rad per joint) or "random" (uniform in [-pi, pi]^3, independent).
// Every solver: at most 500 iterations, stop at a task error of 1e-6 (ours: ||(dx, dy, dalpha)||;
// LMA: the weighted norm with L = (1, 1, 0, 0, 0, 1); NR: every twist component). A solve counts as a
// success when the solver says so AND our independent check finds ||(dx, dy, wrap(dalpha))|| < 1e-5.
// Counters: success_% , iter (mean iterations over all solves), time/solve (CPU); the Time and CPU
// columns are for the whole set of 1000 solves. scara_seed/*: one solve of seed 001's problem.
#include <benchmark/benchmark.h>

#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <kdl/chainiksolverpos_nr.hpp>
#include <kdl/chainiksolvervel_pinv.hpp>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "ik/solve.hpp"
#include "kdl_arm.hpp"

using namespace ks;
using namespace ks::ik;

namespace {
constexpr int kCases = 1000;
constexpr int kMaxIter = 500;
constexpr double kTol = 1e-6;

struct Case {
  Vec<3> q_true, q0;
  PlanarPose pose;
  PlanarPosition position;
};

enum class Starts { near, random };

const PlanarArm3& arm() {
  static const PlanarArm3 a = PlanarArm3::seed();
  return a;
}

const std::vector<Case>& cases(Starts starts) {
  static const auto make = [](Starts s) {
    std::mt19937_64 rng(20261123);
    std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi), perturb(-1.0, 1.0);
    std::vector<Case> v(kCases);
    for (auto& c : v) {
      c.q_true = Vec<3>(angle(rng), angle(rng), angle(rng));
      const Vec<3> d(perturb(rng), perturb(rng), perturb(rng));
      const Vec<3> r(angle(rng), angle(rng), angle(rng));
      c.q0 = s == Starts::near ? Vec<3>(c.q_true + d) : r;
      const ArmPose f = forward_kinematics(arm(), c.q_true);
      c.pose.arm = c.position.arm = arm();
      c.pose.target = c.position.target = f.tip;
      c.pose.alpha = f.alpha;
    }
    return v;
  };
  static const std::vector<Case> near = make(Starts::near), random = make(Starts::random);
  return starts == Starts::near ? near : random;
}

// Independent check of a returned joint vector.
bool reaches(const Case& c, const Vec<3>& q, bool orientation) {
  const ArmPose f = forward_kinematics(arm(), q);
  const double dp = (f.tip - c.pose.target).norm();
  const double da = orientation ? wrap_angle(f.alpha - c.pose.alpha) : 0.0;
  return std::isfinite(dp) && std::hypot(dp, da) < 1e-5;
}

void report(benchmark::State& st, int successes, long iterations) {
  st.counters["success_%"] = 100.0 * successes / kCases;
  st.counters["iter"] = static_cast<double>(iterations) / kCases;
  st.counters["time/solve"] =  // seconds, printed with an SI prefix (u = microseconds)
      benchmark::Counter(static_cast<double>(kCases) * st.iterations(), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// ------------------------------------------------------------------------------------------ ours
template <bool Pose>
void ours(benchmark::State& st, Method method, Starts starts, bool history) {
  const auto& cs = cases(starts);
  Options o;
  o.method = method;
  o.tolerance = kTol;
  o.max_iter = kMaxIter;
  o.keep_history = history;
  Summary<3, Pose ? 3 : 2> s;
  for (auto _ : st)
    for (const auto& c : cs) {
      if constexpr (Pose) solve(c.pose, c.q0, o, s);
      else solve(c.position, c.q0, o, s);
      benchmark::DoNotOptimize(s.q.data());
    }
  int ok = 0;
  long it = 0;
  for (const auto& c : cs) {
    if constexpr (Pose) solve(c.pose, c.q0, o, s);
    else solve(c.position, c.q0, o, s);
    ok += s.converged() && reaches(c, s.q, Pose);
    it += s.iterations;
  }
  report(st, ok, it);
}

// ------------------------------------------------------------------------------------------- KDL
struct KdlSet {
  std::vector<KDL::JntArray> q0;
  std::vector<KDL::Frame> goal;
  explicit KdlSet(const std::vector<Case>& cs) {
    for (const auto& c : cs) {
      KDL::JntArray q(3);
      for (int i = 0; i < 3; ++i) q(i) = c.q0[i];
      q0.push_back(q);
      goal.emplace_back(KDL::Rotation::RotZ(c.pose.alpha), KDL::Vector(c.pose.target.x(), c.pose.target.y(), 0.0));
    }
  }
};

Vec<3> to_vec(const KDL::JntArray& q) { return {q(0), q(1), q(2)}; }

void kdl_lma(benchmark::State& st, Starts starts, bool pose) {
  const auto& cs = cases(starts);
  const KdlSet set(cs);
  const KDL::Chain chain = test::kdl_chain(arm());
  Eigen::Matrix<double, 6, 1> L;
  L << 1, 1, 0, 0, 0, pose ? 1 : 0;
  KDL::ChainIkSolverPos_LMA lma(chain, L, kTol, kMaxIter);
  KDL::JntArray out(3);
  for (auto _ : st)
    for (int i = 0; i < kCases; ++i) benchmark::DoNotOptimize(lma.CartToJnt(set.q0[i], set.goal[i], out));
  int ok = 0;
  long it = 0;
  for (int i = 0; i < kCases; ++i) {
    const int rc = lma.CartToJnt(set.q0[i], set.goal[i], out);
    ok += rc >= 0 && reaches(cs[i], to_vec(out), pose);
    it += lma.lastNrOfIter;
  }
  report(st, ok, it);
}

// ChainIkSolverPos_NR calls the FK solver once per iteration: count the calls.
struct CountingFk : KDL::ChainFkSolverPos_recursive {
  using KDL::ChainFkSolverPos_recursive::ChainFkSolverPos_recursive;
  long calls = 0;
  int JntToCart(const KDL::JntArray& q, KDL::Frame& f, int segment = -1) override {
    ++calls;
    return KDL::ChainFkSolverPos_recursive::JntToCart(q, f, segment);
  }
};

void kdl_nr(benchmark::State& st, Starts starts) {
  const auto& cs = cases(starts);
  const KdlSet set(cs);
  const KDL::Chain chain = test::kdl_chain(arm());
  CountingFk fk(chain);
  KDL::ChainIkSolverVel_pinv vel(chain);
  KDL::ChainIkSolverPos_NR nr(chain, fk, vel, kMaxIter, kTol);
  KDL::JntArray out(3);
  for (auto _ : st)
    for (int i = 0; i < kCases; ++i) benchmark::DoNotOptimize(nr.CartToJnt(set.q0[i], set.goal[i], out));
  int ok = 0;
  fk.calls = 0;
  for (int i = 0; i < kCases; ++i) {
    const int rc = nr.CartToJnt(set.q0[i], set.goal[i], out);
    ok += rc >= 0 && reaches(cs[i], to_vec(out), true);
  }
  report(st, ok, fk.calls);  // one FK per iteration (the converging one included)
}
}  // namespace

// Seed 001's SCARA problem from its start (pi/3, pi/4, 50), thesis z mode, tolerance 1e-6 mm: one
// solve per benchmark iteration (the seed's MATLAB took ~40 ms per solve).
void scara_seed(benchmark::State& st, Method method, double lambda) {
  const ScaraPosition p;
  const Vec<3> q0(std::numbers::pi / 3.0, std::numbers::pi / 4.0, 50.0);
  Options o;
  o.method = method;
  o.lambda = lambda;
  o.keep_history = false;
  Summary<3, 3> s;
  for (auto _ : st) {
    solve(p, q0, o, s);
    benchmark::DoNotOptimize(s.q.data());
  }
  st.counters["iter"] = s.iterations;
  st.counters["converged"] = s.converged();
}

// Registered in this order so that each group reads as one side-by-side table.
int main(int argc, char** argv) {
  using benchmark::RegisterBenchmark;
  const auto ms = benchmark::kMillisecond;
  struct Ours {
    const char* name;
    Method method;
    bool history;
  };
  const Ours pose_methods[] = {{"ours_lm_adaptive", Method::lm_adaptive, false},
                               {"ours_newton", Method::newton, false},
                               {"ours_halley", Method::halley, false},
                               {"ours_lm_adaptive+history", Method::lm_adaptive, true},
                               {"ours_analytic", Method::analytic, false}};
  for (const Starts starts : {Starts::near, Starts::random}) {
    const std::string group = starts == Starts::near ? "pose_near/" : "pose_random/";
    for (const Ours& m : pose_methods) {
      if (starts == Starts::random && (m.history || m.method == Method::analytic)) continue;
      RegisterBenchmark((group + m.name).c_str(), ours<true>, m.method, starts, m.history)->Unit(ms);
    }
    RegisterBenchmark((group + "kdl_lma").c_str(), kdl_lma, starts, true)->Unit(ms);
    RegisterBenchmark((group + "kdl_nr").c_str(), kdl_nr, starts)->Unit(ms);
  }
  // Position only (redundant: minimum-norm / damped steps), random starts; KDL LMA with
  // L = (1, 1, 0, 0, 0, 0). KDL NR always solves the full twist: no position-only mode.
  for (const Ours& m : pose_methods) {
    if (m.history || m.method == Method::analytic) continue;
    RegisterBenchmark((std::string("position_random/") + m.name).c_str(), ours<false>, m.method, Starts::random, false)
        ->Unit(ms);
  }
  RegisterBenchmark("position_random/kdl_lma", kdl_lma, Starts::random, false)->Unit(ms);

  const auto ns = benchmark::kNanosecond;
  RegisterBenchmark("scara_seed/newton", scara_seed, Method::newton, 0.0)->Unit(ns);
  RegisterBenchmark("scara_seed/lm_0.1", scara_seed, Method::lm, 0.1)->Unit(ns);
  RegisterBenchmark("scara_seed/lm_10", scara_seed, Method::lm, 10.0)->Unit(ns);
  RegisterBenchmark("scara_seed/lm_adaptive", scara_seed, Method::lm_adaptive, 0.0)->Unit(ns);
  RegisterBenchmark("scara_seed/halley_thesis", scara_seed, Method::halley_thesis, 0.0)->Unit(ns);
  RegisterBenchmark("scara_seed/halley", scara_seed, Method::halley, 0.0)->Unit(ns);

  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
