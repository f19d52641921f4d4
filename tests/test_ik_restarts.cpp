// Converged angles wrapped, random restarts, the robot's joint limits as the chain problems'
// default, and success against Orocos KDL's ChainIkSolverPos_LMA on the Panda-like arm with the
// same restart budget. Oracles: forward kinematics (ours and KDL's), the joint limits as written in
// the URDF, KDL's own success rate on the same cases.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "ik/chain_ik.hpp"
#include "ik/solve.hpp"
#include "ik_restart_cases.hpp"
#include "model/kinematics.hpp"
#include "robot/urdf.hpp"
#include "schema/params.hpp"
#include "study/study.hpp"

using namespace ks;
using namespace ks::ik;

namespace {
constexpr double kPi = std::numbers::pi;

Chain load(const char* file) {
  return load_urdf(std::string(KS_SOURCE_DIR) + "/studies/robots/" + file, "base_link", "tool", {0.0, 0.0, -9.81});
}

bool in_pi_interval(double x) { return x > -kPi && x <= kPi; }

// --- wrapping of converged angles ----------------------------------------------------------------

// The planar 3R pose problem from starts many turns away: the converged angles are in (-pi, pi] and
// still put the tip on the target (forward kinematics of the stored q).
TEST(IkWrap, PlanarPoseFromFarStartsConvergesToWrappedAngles) {
  PlanarPose p;
  p.target = {1.5, 1.5};
  p.alpha = 0.3;
  for (const Method m : {Method::newton, Method::lm_adaptive, Method::halley, Method::halley_thesis})
    for (const double turns : {-40.0, -3.0, 5.0, 1000.0}) {
      Options o;
      o.method = m;
      o.tolerance = 1e-10;
      const Vec3 q0(2 * kPi * turns + 0.1, 1.4, -1.2 + 2 * kPi * turns);
      const auto s = solve(p, q0, o);
      ASSERT_TRUE(s.converged()) << s.brief();
      for (int j = 0; j < 3; ++j) EXPECT_TRUE(in_pi_interval(s.q[j])) << s.brief();
      const Vec2 tip = end_effector(p.arm, joint_trig(s.q));
      EXPECT_LT((tip - p.target).norm(), 1e-9) << s.brief();
      EXPECT_LT(std::abs(wrap_angle(s.q.sum() - p.alpha)), 1e-9) << s.brief();
    }
}

// The SCARA's prismatic joint is not an angle: it is never wrapped.
TEST(IkWrap, ScaraWrapsTheAnglesOnly) {
  ScaraPosition p;
  p.target = {50.0, -80.0, 500.0};
  Options o;
  const auto s = solve(p, Vec3(60.0 + 0.5, 45.0 - 0.7, 50.0), o);  // 60 rad and 45 rad: ~10 and 7 turns
  ASSERT_TRUE(s.converged()) << s.brief();
  EXPECT_TRUE(in_pi_interval(s.q[0]) && in_pi_interval(s.q[1])) << s.brief();
  EXPECT_NEAR(s.q[2], 500.0, 1e-6);
  EXPECT_LT((p.forward(s.q) - p.target).norm(), 1e-6);
}

// A chain with limited joints: joint_limits = none wraps every revolute joint; clamp keeps each
// joint within its limits as iterated (never wrapped out of them); the tip reaches the target.
TEST(IkWrap, ChainJointsAreWrappedUnlessTheirLimitsAreEnforced) {
  const Chain c = load("arm7.urdf");
  const std::vector<test::RestartCase> set = test::restart_cases(c, 40, 11, 12);
  test::KdlJudge judge(c);
  ChainIkWorkspace ws;
  ChainIkResult r;
  int converged_none = 0, converged_clamp = 0;
  for (const test::RestartCase& k : set) {
    for (const JointLimits l : {JointLimits::none, JointLimits::clamp}) {
      Options o;
      o.method = Method::newton;
      o.joint_limits = l;
      o.tolerance = 1e-9;
      o.max_iter = 200;
      VecN q0 = k.q0;
      q0[0] += 6 * kPi, q0[3] -= 4 * kPi;  // far from the limits' range: none must bring them back
      solve_chain(c, k.task, l == JointLimits::none ? q0 : k.q0, o, r, ws);
      if (!r.converged()) continue;
      (l == JointLimits::none ? converged_none : converged_clamp)++;
      EXPECT_LT(judge.pose_error(r.q, k.goal), 1e-8);
      for (int j = 0; j < c.dof(); ++j) {
        if (l == JointLimits::none) EXPECT_TRUE(in_pi_interval(r.q[j])) << j << " " << r.q.transpose();
        else EXPECT_TRUE(r.q[j] >= c.joints[j].lower && r.q[j] <= c.joints[j].upper) << j << " " << r.q.transpose();
      }
    }
  }
  EXPECT_GT(converged_none, 20);
  EXPECT_GT(converged_clamp, 20);
}

// --- restarts ------------------------------------------------------------------------------------

// restarts = 0 is a single attempt; with restarts the outcome is a pure function of the seed, the
// history holds every attempt (rows = iterations + 1 + restarts_used), every restart's start (a
// later row with step 0) lies within the joint limits, and a run that needed restarts converged on
// its last attempt only.
TEST(IkRestarts, AttemptsAreDeterministicAndStartWithinTheLimits) {
  const Chain c = load("panda_like.urdf");
  const std::vector<test::RestartCase> set = test::restart_cases(c, 60, 5, 6);
  ChainIkWorkspace ws;
  ChainIkResult a, b, single;
  int restarted = 0;
  for (const test::RestartCase& k : set) {
    Options o;
    o.method = Method::newton;
    o.max_iter = 30;
    o.joint_limits = JointLimits::reject;
    solve_chain(c, k.task, k.q0, o, single, ws);
    o.restarts = 8;
    o.restart_seed = k.seed;
    solve_chain(c, k.task, k.q0, o, a, ws);
    solve_chain(c, k.task, k.q0, o, b, ws);
    EXPECT_EQ(a.status, b.status);
    EXPECT_EQ(a.restarts_used, b.restarts_used);
    EXPECT_EQ(a.iterations, b.iterations);
    EXPECT_TRUE(a.q == b.q);
    EXPECT_EQ(single.restarts_used, 0);
    if (single.converged()) {  // nothing to restart: the same as one attempt
      EXPECT_EQ(a.restarts_used, 0);
      EXPECT_TRUE(a.q == single.q);
      continue;
    }
    EXPECT_GE(a.restarts_used, 1);
    EXPECT_LE(a.restarts_used, 8);
    if (a.restarts_used < 8) {
      EXPECT_TRUE(a.converged());
    }
    restarted += 1;
    ASSERT_EQ(a.history.size(), static_cast<std::size_t>(a.iterations + 1 + a.restarts_used));
    int starts = 0;
    for (std::size_t row = 1; row < a.history.size(); ++row) {
      if (a.history.step[row] != 0.0) continue;
      ++starts;
      for (int j = 0; j < c.dof(); ++j) {
        EXPECT_GE(a.history.q[row][j], c.joints[j].lower);
        EXPECT_LE(a.history.q[row][j], c.joints[j].upper);
      }
    }
    EXPECT_EQ(starts, a.restarts_used);
  }
  EXPECT_GT(restarted, 0);
}

// Restarts only add attempts: every case solved without them is solved with them, and some more.
TEST(IkRestarts, RestartsDoNotLoseSolutions) {
  const Chain c = load("panda_like.urdf");
  const std::vector<test::RestartCase> set = test::restart_cases(c, 100, 7, 8);
  ChainIkWorkspace ws;
  ChainIkResult r0, r;
  int ok0 = 0, ok = 0;
  for (const test::RestartCase& k : set) {
    Options o;
    o.method = Method::lm_adaptive;
    o.max_iter = 100;
    o.joint_limits = JointLimits::clamp;
    solve_chain(c, k.task, k.q0, o, r0, ws);
    o.restarts = 10;
    o.restart_seed = k.seed;
    solve_chain(c, k.task, k.q0, o, r, ws);
    if (r0.converged()) {
      EXPECT_TRUE(r.converged());
    }
    ok0 += r0.converged(), ok += r.converged();
  }
  EXPECT_GT(ok, ok0);
}

// --- against KDL ---------------------------------------------------------------------------------

// 200 reachable pose targets of the Panda-like arm (tip poses of joint vectors within its limits)
// from random starts within its limits, 20 restarts and stall_window 20 for every method that
// applies to a chain pose problem, against KDL's LMA with the same restarts and the same draws.
// Without limits (KDL's LMA does not know them): every method solves at least as many targets as
// KDL, every solution it reports converged is one by KDL's forward kinematics, and its angles are
// wrapped to (-pi, pi]. With the robot's limits enforced (reject, clamp): every solution reported
// converged lies within the limits, and each method finds at least as many solutions within them as
// KDL's LMA does (KDL's counted within the limits mod 2 pi).
struct PandaSet {
  static constexpr double kTol = 1e-6;
  static constexpr int kRestarts = 20, kMaxIter = 100, kStallWindow = 20;
  Chain c = load("panda_like.urdf");
  std::vector<test::RestartCase> set = test::restart_cases(c, 200, 20261202, 777);
  test::KdlJudge judge{c};
  int kdl_ok = 0, kdl_in_limits = 0;
  PandaSet() {
    test::KdlLmaRestarts lma(c, kTol, kMaxIter);
    VecN q;
    for (const test::RestartCase& k : set) {
      lma.solve(k, kRestarts, q);
      const bool ok = judge.pose_error(q, k.goal) < kTol;
      kdl_ok += ok;
      kdl_in_limits += ok && test::within_limits(c, q);
    }
  }
  Options options(Method m, JointLimits l) const {
    Options o;
    o.method = m;
    o.tolerance = kTol;
    o.max_iter = kMaxIter;
    o.keep_history = false;
    o.joint_limits = l;
    o.restarts = kRestarts;
    o.stall_window = kStallWindow;
    if (m == Method::lm) o.lambda = 1e-5;
    return o;
  }
};

TEST(IkRestarts, EveryMethodSolvesAtLeastAsManyPandaTargetsAsKdlLma) {
  PandaSet p;
  EXPECT_GT(p.kdl_ok, 190);  // the comparison means something
  ChainIkWorkspace ws;
  ChainIkResult r;
  for (const Method m : {Method::newton, Method::lm, Method::lm_adaptive, Method::halley}) {
    int ok = 0;
    for (const test::RestartCase& k : p.set) {
      Options o = p.options(m, JointLimits::none);
      o.restart_seed = k.seed;
      solve_chain(p.c, k.task, k.q0, o, r, ws);
      if (!r.converged()) continue;
      const double e = p.judge.pose_error(r.q, k.goal);
      EXPECT_LT(e, PandaSet::kTol) << to_string(m);
      for (int j = 0; j < p.c.dof(); ++j) EXPECT_TRUE(in_pi_interval(r.q[j])) << to_string(m) << " " << r.q.transpose();
      ok += e < PandaSet::kTol;
    }
    EXPECT_GE(ok, p.kdl_ok) << to_string(m) << ": " << ok << " of 200 against KDL LMA's " << p.kdl_ok;
  }
}

TEST(IkRestarts, WithTheLimitsEnforcedEveryMethodFindsMoreSolutionsWithinThemThanKdlLma) {
  PandaSet p;
  EXPECT_GT(p.kdl_in_limits, 50);
  ChainIkWorkspace ws;
  ChainIkResult r;
  for (const JointLimits l : {JointLimits::reject, JointLimits::clamp})
    for (const Method m : {Method::newton, Method::lm, Method::lm_adaptive, Method::halley}) {
      int ok = 0;
      for (const test::RestartCase& k : p.set) {
        Options o = p.options(m, l);
        o.restart_seed = k.seed;
        solve_chain(p.c, k.task, k.q0, o, r, ws);
        if (!r.converged()) continue;
        const double e = p.judge.pose_error(r.q, k.goal);
        EXPECT_LT(e, PandaSet::kTol) << to_string(m) << " " << to_string(l);
        EXPECT_TRUE(test::within_limits(p.c, r.q)) << to_string(m) << " " << to_string(l) << " " << r.q.transpose();
        ok += e < PandaSet::kTol && test::within_limits(p.c, r.q);
      }
      EXPECT_GE(ok, p.kdl_in_limits) << to_string(m) << " " << to_string(l) << ": " << ok << " of 200 against KDL LMA's "
                                     << p.kdl_in_limits;
    }
}

// stall_window ends an attempt whose residual has not halved over that many updates (status
// stalled, iterations a multiple of the window), and never one that converges within the window.
TEST(IkRestarts, StallWindowEndsAttemptsThatStopImproving) {
  PandaSet p;
  ChainIkWorkspace ws;
  ChainIkResult free_run, watched;
  int stalled = 0;
  for (const test::RestartCase& k : p.set) {
    Options o = p.options(Method::lm_adaptive, JointLimits::none);
    o.restarts = 0;
    o.stall_window = 0;
    solve_chain(p.c, k.task, k.q0, o, free_run, ws);
    o.stall_window = 20;
    solve_chain(p.c, k.task, k.q0, o, watched, ws);
    if (free_run.converged() && free_run.iterations < 20) {
      EXPECT_TRUE(watched.converged());
      EXPECT_EQ(watched.iterations, free_run.iterations);
      EXPECT_EQ(watched.q, free_run.q);
    }
    if (watched.status == Status::stalled && free_run.status != Status::stalled) {
      ++stalled;
      EXPECT_EQ(watched.iterations % 20, 0);
      EXPECT_LT(watched.iterations, free_run.iterations);
    }
  }
  EXPECT_GT(stalled, 5);  // attempts at a non-root minimum (about 1 in 10 here) end early
}

// --- the robot's limits as the default --------------------------------------------------------

RunSpec first_run(const std::string& robot, const std::string& block_extra) {
  const Study s = parse_study(robot + "[[block]]\nname = \"b\"\nkind = \"ik\"\nproblem = \"pose\"\n" + block_extra,
                              std::string(KS_SOURCE_DIR) + "/studies/s.toml");
  return s.blocks.front().run(0);
}

TEST(IkLimitsDefault, ChainProblemsEnforceTheRobotsLimitsUnlessTheStudySaysOtherwise) {
  const std::string panda = "[robot]\nurdf = \"robots/panda_like.urdf\"\nbase = \"base_link\"\ntip = \"tool\"\n";
  EXPECT_EQ(std::get<IkRun>(first_run(panda, "")).options.joint_limits, JointLimits::clamp);
  EXPECT_EQ(std::get<IkRun>(first_run(panda, "joint_limits = \"none\"\n")).options.joint_limits, JointLimits::none);
  EXPECT_EQ(std::get<IkRun>(first_run(panda, "joint_limits = \"reject\"\n")).options.joint_limits,
            JointLimits::reject);
  const std::string nlink = "[robot]\nl = [1, 1, 0.5, 0.5]\nm = [4, 4, 2, 2]\n";
  EXPECT_EQ(std::get<IkRun>(first_run(nlink, "")).options.joint_limits, JointLimits::none);
  EXPECT_EQ(std::get<IkRun>(first_run(nlink + "limits = [[-170, 170], [-170, 170], [-170, 170], [-170, 170]]\n", ""))
                .options.joint_limits,
            JointLimits::clamp);
  EXPECT_EQ(std::get<IkRun>(first_run(panda, "")).options.restarts, 0);
}

}  // namespace
