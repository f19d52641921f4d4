// A path-global run on a chain under the robot's limits is `ok` only where another optimiser cannot
// improve it: NLopt's MMA (method of moving asymptotes: conservative convex approximations, no
// quasi-Newton model), started from the run's coefficients on the same objective with the limits as
// constraints (one per window of samples and limited quantity), lowers E by no more than 1e-4
// relative within them, or the run is not reported ok. A 4R whose unconstrained optimum crosses a
// joint limit, and the 7-DOF arm's square of studies/path_global_arm7.toml at 10 knots (its global
// block), where SLSQP with those constraints stalled 11 % above the optimum.
#include <gtest/gtest.h>

#include <nlopt.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "methods/chain/trajectory.hpp"
#include "methods/path_global/alpha_basis.hpp"
#include "methods/path_global/chain.hpp"
#include "methods/path_global/joint_chart.hpp"
#include "robot/urdf.hpp"
#include "widest_raise.hpp"
#include "task/task_path.hpp"

using namespace ks;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

struct Mma {
  const ChainGlobalProblem* problem;
  const AlphaBasis* basis;
  const LimitConstraints* limits;
  std::vector<double> full;  // every coefficient; the free ones from x
  std::vector<int> free;
  std::vector<double> grad, con, jac;

  void at(const double* x) {
    for (std::size_t m = 0; m < free.size(); ++m) full[free[m]] = x[m];
  }
  double eval(const double* x) {
    at(x);
    return problem->objective(*basis, full.data(), GlobalObjective::E, grad.data(), limits, con.data(), jac.data());
  }
};


struct FromEnd {
  TrajectoryMetrics run;
  double f_run = 0, f_mma = 0, worst = 0;  // E at the run's end, MMA's E from there, its largest constraint
};

/// The global run of o from guess q0 (its start: the local run of o.global.start_method), then MMA
/// from its end on the same problem (the solved joints the run states, its basis and limits).
FromEnd mma_from_end(const Chain& chain, const ChainTask& task, const VecN& q0, const TrajectoryOptions& o) {
  FromEnd out;
  TrajectoryOptions lo = o;
  lo.method = o.global.start_method == StartMethod::local_weighted ? TrajectoryMethod::local_weighted
                                                                   : TrajectoryMethod::local_unweighted;
  lo.on_violation = OnViolation::ignore;
  ChainHistory h;
  h.stride = 1;
  simulate(chain, task, q0, lo, &h);
  EXPECT_GT(h.size, 0);
  const VecN q_start = h.q.col(0);
  std::vector<double> c;
  out.run = solve_global_spline_chain(chain, task, q0, o, nullptr, &c);
  std::vector<int> solved;
  for (long code = std::lround(out.run.opt_solved_joints); code > 0; code /= 10)
    solved.insert(solved.begin(), static_cast<int>(code % 10) - 1);
  const JointExtensionProblem problem(chain, task, solved, q_start);
  const AlphaBasis basis = cubic_spline_basis(task.path.size(), task.path.dt(), task.path.path().duration(),
                                              static_cast<int>(o.global.knots), o.global.end == EndState::rest);
  const LimitConstraints limits = LimitConstraints::of(chain, problem.samples(), static_cast<int>(o.global.knots));
  const int K = basis.coefficients, r = problem.coordinates();
  EXPECT_EQ(c.size(), static_cast<std::size_t>(K * r));
  Mma s{&problem, &basis, &limits, c, {}, std::vector<double>(c.size()), std::vector<double>(limits.count()),
        std::vector<double>(static_cast<std::size_t>(limits.count()) * c.size())};
  for (int k = 0; k < r; ++k)
    for (int j = 1; j < K; ++j) s.free.push_back(k * K + j);  // the start posture is fixed
  std::vector<double> x(s.free.size());
  for (std::size_t i = 0; i < s.free.size(); ++i) x[i] = c[s.free[i]];
  out.f_run = s.eval(x.data());
  nlopt::opt mma(nlopt::LD_MMA, static_cast<unsigned>(x.size()));
  mma.set_min_objective(
      [](const std::vector<double>& xs, std::vector<double>& g, void* d) {
        Mma& st = *static_cast<Mma*>(d);
        const double f = st.eval(xs.data());
        if (!g.empty())
          for (std::size_t i = 0; i < st.free.size(); ++i) g[i] = st.grad[st.free[i]];
        return f;
      },
      &s);
  mma.add_inequality_mconstraint(
      [](unsigned rows, double* con, unsigned n, const double* xs, double* g, void* d) {
        Mma& st = *static_cast<Mma*>(d);
        st.eval(xs);
        for (unsigned a = 0; a < rows; ++a) {
          con[a] = st.con[a];
          if (g)
            for (unsigned b = 0; b < n; ++b) g[a * n + b] = st.jac[a * st.full.size() + st.free[b]];
        }
      },
      &s, std::vector<double>(limits.count(), 0.0));
  mma.set_maxeval(300);
  mma.set_ftol_rel(1e-12);
  out.f_mma = out.f_run;
  try {
    mma.optimize(x, out.f_mma);
  } catch (const nlopt::roundoff_limited&) {
  }
  out.f_mma = s.eval(x.data());
  out.worst = *std::ranges::max_element(s.con);
  return out;
}

/// The claim: ok only when MMA cannot lower E by more than 1e-4 relative within the limits (its
/// largest constraint at most 1e-6: within the margin the run keeps).
void expect_status_holds(const FromEnd& e, const char* what) {
  std::printf("%s: %s, E %.8f (%g evaluations, %g limits active); MMA from its end %.8f (largest constraint %.2e)\n",
              what, std::string(to_string(e.run.status)).c_str(), e.f_run, e.run.opt_evaluations,
              e.run.opt_active_limits, e.f_mma, e.worst);
  if (e.worst <= 1e-6 && e.f_mma < e.f_run * (1.0 - 1e-4)) {
    EXPECT_NE(e.run.status, RunStatus::ok) << what << ": reported ok, but MMA lowers E from " << e.f_run << " to "
                                           << e.f_mma;
  }
}

}  // namespace

TEST(PathGlobalLimitsOptimum, FourLinkArmWithALimitTheUnconstrainedOptimumCrosses) {
  Chain chain = planar_chain(planar_bars({1, 1, 0.5, 0.5}, {5, 2, 0.5, 0.5}, 0.1));
  const ChainTask task(TaskSpace::planar_position, seed_square(), 2e-3);
  TrajectoryOptions o;
  o.dt = 2e-3;
  o.alpha1A = 4 * kDeg;
  o.method = TrajectoryMethod::global_spline;
  o.global.extension = Extension::joints;
  o.global.start_method = StartMethod::local_unweighted;
  o.global.knots = 8;
  // as PathGlobalJoints.ALimitTheUnconstrainedOptimumCrossesIsKept: the joint whose largest |q| the
  // unconstrained optimum raises most above the local run's, limited half-way between the two
  ChainHistory local_h, free_h;
  TrajectoryOptions lo = o;
  lo.method = TrajectoryMethod::local_unweighted;
  ASSERT_EQ(simulate(chain, task, planar_start_guess(4), lo, &local_h).status, RunStatus::ok);
  ASSERT_EQ(simulate(chain, task, planar_start_guess(4), o, &free_h).status, RunStatus::ok);
  const auto [j, local_max, free_max] = widest_raise(local_h, free_h, 4);
  const double limit = 0.5 * (local_max + free_max);
  chain.joints[j].lower = -limit, chain.joints[j].upper = limit;
  const FromEnd e = mma_from_end(chain, task, planar_start_guess(4), o);
  EXPECT_GE(e.run.opt_active_limits, 1.0);
  expect_status_holds(e, "4R, a joint limited between its local and unconstrained ranges");
}

TEST(PathGlobalLimitsOptimum, SevenDofArmSquareTenKnots) {
  const Chain chain =
      load_urdf(std::string(KS_SOURCE_DIR) + "/studies/robots/arm7.urdf", "base_link", "tool", {0.0, 0.0, -9.81});
  const std::vector<Eigen::Vector3d> v{{0.5, -0.1, 0.4}, {0.5, 0.1, 0.4}, {0.5, 0.1, 0.6}, {0.5, -0.1, 0.6}, {0.5, -0.1, 0.4}};
  TrajectoryOptions o;
  o.dt = 4e-3;
  o.integrator = Integrator::rk4;
  o.null_damping = 20;
  o.limit_centring = 8;
  const ChainTask task(TaskSpace::spatial_position, Path3(v, {2.0, 2.0, 2.0, 2.0}), o.dt);
  VecN q0 = VecN::Constant(7, 0.3);
  q0[2] = 60 * kDeg, q0[3] = -90 * kDeg;
  o.method = TrajectoryMethod::global_spline;
  o.global.extension = Extension::joints;
  o.global.start_method = StartMethod::local_weighted;
  o.global.knots = 10;
  const FromEnd e = mma_from_end(chain, task, q0, o);
  EXPECT_EQ(e.run.status, RunStatus::ok) << to_string(e.run.status);
  EXPECT_GE(e.run.opt_active_limits, 1.0);
  EXPECT_LE(std::max({e.run.max_q_limit_ratio, e.run.max_qd_limit_ratio, e.run.max_tau_limit_ratio}), 1.0);
  expect_status_holds(e, "arm7, the square, 10 knots");
}
