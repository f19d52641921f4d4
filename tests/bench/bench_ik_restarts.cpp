// Pose IK with random restarts on the Panda-like arm (studies/robots/panda_like.urdf, base_link to
// tool): every kinesweep method that applies to a chain pose problem (newton, lm, lm_adaptive,
// halley; halley_thesis needs a square system and analytic a closed form) against Orocos KDL's
// ChainIkSolverPos_LMA given the same restart budget and the same restart draws
// (tests/ik_restart_cases.hpp).
// Problem set (seeded): C targets = KDL's forward kinematics of joint vectors uniform within the
// limits; starts uniform within the limits, from another stream.
// Ours: tolerance 1e-6 on ||F|| (m, rad), the robot's limits enforced as `joint_limits` says
// (default clamp: a study's default for a robot with limits), at most `max_iter` updates per
// attempt, up to R restarts (default 20, max_iter 100), lm with lambda = 1e-3 (--lambda),
// lm_adaptive's lambda_scale and the stall_window as given (defaults: ik::Options'). KDL LMA:
// weights 1, precision 1e-6, the same max_iter per attempt; it restarts when it reports a failure.
// Success: KDL's forward kinematics puts the final q within 1e-6 of the target (sqrt(|dp|^2 +
// angle^2)); "in limits" also asks q within the joint limits (mod 2 pi). Ours enforce the limits,
// so their success counts only solutions within them; KDL's is given both ways.
// Timing: every solver solves the whole set once per round, solvers interleaved, `rounds` rounds;
// us per solve = the round's wall time / C; min and median over the rounds, and KDL's time over
// ours (min over min, median over median) as the speed-up.
// Usage: bench_ik_restarts [--cases C] [--rounds N] [--restarts R] [--max-iter K]
//                          [--limits none|clamp|reject] [--lambda L] [--lambda-scale T]
//                          [--stall-window W] [--urdf FILE]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "ik_restart_cases.hpp"
#include "robot/urdf.hpp"

using namespace ks;
using namespace ks::ik;

namespace {

constexpr double kTol = 1e-6;

struct Solver {
  std::string name;
  std::function<int(const test::RestartCase&, VecN&)> solve;  // returns the restarts made
  std::vector<VecN> out;
  std::vector<int> restarts;
  std::vector<double> us;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  int cases = 1000, rounds = 7, restarts = 20, max_iter = 100;
  double lambda = 1e-3;  // lm's fixed damping: the default 0.1 converges linearly, slowly, at 1e-6
  double lambda_scale = Options{}.lambda_scale;  // lm_adaptive's initial damping (the default)
  int stall_window = 0;                          // ik::Options::stall_window (0: off, the default)
  JointLimits limits = JointLimits::clamp;
  std::string urdf = KS_SOURCE_DIR "/studies/robots/panda_like.urdf";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--cases") cases = std::max(1, std::atoi(v.c_str()));
    else if (a == "--rounds") rounds = std::max(1, std::atoi(v.c_str()));
    else if (a == "--restarts") restarts = std::max(0, std::atoi(v.c_str()));
    else if (a == "--max-iter") max_iter = std::max(1, std::atoi(v.c_str()));
    else if (a == "--lambda") lambda = std::atof(v.c_str());
    else if (a == "--lambda-scale") lambda_scale = std::atof(v.c_str());
    else if (a == "--stall-window") stall_window = std::max(0, std::atoi(v.c_str()));
    else if (a == "--urdf") urdf = v;
    else if (a == "--limits" && parse(v, limits)) continue;
    else return std::fprintf(stderr, "unknown option %s %s\n", a.c_str(), v.c_str()), 2;
  }
  const Chain chain = load_urdf(urdf, "base_link", "tool", {0.0, 0.0, -9.81});
  const std::vector<test::RestartCase> set = test::restart_cases(chain, cases, 20261202, 777);
  std::printf("%s: %d joints, %d pose targets, %d rounds, restarts <= %d, max_iter %d per attempt, "
              "joint_limits %s, lm lambda %g\n",
              chain.name.c_str(), chain.dof(), cases, rounds, restarts, max_iter,
              std::string(to_string(limits)).c_str(), lambda);

  ChainIkWorkspace ws;
  ChainIkResult result;
  std::vector<Solver> solvers;
  for (const Method m : {Method::newton, Method::lm, Method::lm_adaptive, Method::halley}) {
    Options o;
    o.method = m;
    o.tolerance = kTol;
    o.max_iter = max_iter;
    o.lambda = lambda;
    o.lambda_scale = lambda_scale;
    o.stall_window = stall_window;
    o.keep_history = false;
    o.joint_limits = limits;
    o.restarts = restarts;
    solvers.push_back({"ours " + std::string(to_string(m)), [&, o](const test::RestartCase& k, VecN& q) mutable {
                         o.restart_seed = k.seed;
                         solve_chain(chain, k.task, k.q0, o, result, ws);
                         q = result.q;
                         return result.restarts_used;
                       },
                       {}, {}, {}});
  }
  test::KdlLmaRestarts lma(chain, kTol, max_iter);
  solvers.push_back({"KDL LMA", [&](const test::RestartCase& k, VecN& q) { return lma.solve(k, restarts, q); }, {}, {}, {}});

  for (Solver& s : solvers) s.out.resize(set.size()), s.restarts.resize(set.size());
  for (int r = 0; r < rounds; ++r)
    for (Solver& s : solvers) {
      const auto t0 = std::chrono::steady_clock::now();
      for (std::size_t i = 0; i < set.size(); ++i) s.restarts[i] = s.solve(set[i], s.out[i]);
      const auto t1 = std::chrono::steady_clock::now();
      s.us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count() / static_cast<double>(set.size()));
    }

  test::KdlJudge judge(chain);
  const Solver& kdl = solvers.back();
  const double kdl_min = *std::min_element(kdl.us.begin(), kdl.us.end()), kdl_median = median(kdl.us);
  std::printf("%-17s %9s %9s %10s %12s %12s %12s %12s %9s %9s\n", "solver", "success%", "in_lim%", "restarts",
              "restarts_max", "first_try%", "us_min", "us_median", "x_min", "x_median");
  for (const Solver& s : solvers) {
    int ok = 0, ok_in = 0, first = 0, used = 0, used_max = 0;
    for (std::size_t i = 0; i < set.size(); ++i) {
      const bool good = judge.pose_error(s.out[i], set[i].goal) < kTol;
      ok += good;
      ok_in += good && test::within_limits(chain, s.out[i]);
      first += good && s.restarts[i] == 0;
      used += s.restarts[i];
      used_max = std::max(used_max, s.restarts[i]);
    }
    const double tmin = *std::min_element(s.us.begin(), s.us.end()), tmed = median(s.us);
    const double c = static_cast<double>(set.size());
    std::printf("%-17s %9.1f %9.1f %10.3f %12d %12.1f %12.2f %12.2f %9.2f %9.2f\n", s.name.c_str(), 100.0 * ok / c,
                100.0 * ok_in / c, used / c, used_max, 100.0 * first / c, tmin, tmed, kdl_min / tmin,
                kdl_median / tmed);
  }
  std::printf("(success: KDL FK within %g of the target; in_lim: and within the joint limits mod 2 pi; "
              "restarts: mean restarts made; first_try: solved without a restart; x: KDL LMA's time over "
              "the solver's)\n",
              kTol);
  return 0;
}
