// Motion runs (kind = "motion") through the study parser and the executor against the motion library
// called directly: a study's run (degrees in the file, [world] obstacles, weights) gives the metrics
// of the MotionProblem built by hand from the same numbers (radians), bit for bit, with and without
// the solve; the kind's tables (parameters per joint in deg, statuses, defaults).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "motion/motion_problem.hpp"
#include "motion/solve_motion.hpp"
#include "runner/execute.hpp"
#include "schema/params.hpp"
#include "study/study.hpp"

using namespace ks;
using namespace ks::motion;

namespace {

const std::string kRobots = KS_SOURCE_DIR "/studies/robots/";
constexpr double kPi = std::numbers::pi;

/// A study of the Puma arm (wrist locked) with a sphere off its path and one motion block of seed
/// 002 section 7.2's motion (0 -> (90, 45, -30) deg in 9 s, K = 1, p = 0.4 f5/f5^0 + 0.6 f6/f6^0)
/// with `extra` appended to the block.
std::string puma_study(const std::string& extra) {
  return "[robot]\ndh = \"" + kRobots + "puma560_arm.toml\"\n"
         "[world]\nlink_radius = [0.05, 0.05, 0.05]\n"
         "obstacles = [{ type = \"sphere\", centre = [0.6, -0.4, 0.3], radius = 0.1 }]\n"
         "[[block]]\nname = \"m\"\nkind = \"motion\"\ngoal_1 = 90\ngoal_2 = 45\ngoal_3 = -30\nduration = 9\n"
         "controls = 1\nw_torque = 0.4\nw_power = 0.6\nmax_evaluations = 60\n" + extra;
}

/// The same motion problem built by hand on the study's chain.
MotionSpec puma_spec(const Study& s) {
  MotionSpec spec;
  spec.chain = *s.base_chain;
  spec.q_start = VecN::Zero(3);
  spec.q_goal = (VecN(3) << kPi / 2, kPi / 4, -kPi / 6).finished();
  spec.controls = 1;
  spec.duration = 9.0;
  spec.samples = 201;
  at(spec.weights, Criterion::torque_sq) = 0.4;
  at(spec.weights, Criterion::power_sq) = 0.6;
  spec.normalise = true;
  spec.obstacles.emplace_back(geometry::Sphere{Vec3(0.6, -0.4, 0.3), 0.1});
  spec.radii.assign(3, 0.05);
  spec.clearance_margin = 1e-3;
  return spec;
}

const MotionResult& result_of(const RunOutcome& o) { return std::get<MotionResult>(o.result); }

}  // namespace

TEST(MotionKind, CubicRunEqualsTheMotionProblemEvaluation) {
  const Study s = parse_study(puma_study("solve = false\n"), "motion.toml");
  ASSERT_EQ(s.blocks.size(), 1u);
  RunWorkspace ws;
  const RunOutcome out = execute(Scenario::of(s), s.blocks[0].run(0), 1, ws);
  const MotionResult& r = result_of(out);
  const MotionProblem P(puma_spec(s));
  MotionEvaluation ev;
  P.evaluate(P.initial_point(), false, ev);
  EXPECT_EQ(out.status(), "ok");
  EXPECT_EQ(r.torque_sq, at(ev.criteria, Criterion::torque_sq));
  EXPECT_EQ(r.power_sq, at(ev.criteria, Criterion::power_sq));
  EXPECT_EQ(r.peak_torque, at(ev.criteria, Criterion::peak_torque));
  EXPECT_EQ(r.jerk_sq, at(ev.criteria, Criterion::jerk_sq));
  EXPECT_EQ(r.min_manipulability, at(ev.criteria, Criterion::min_manipulability));
  EXPECT_EQ(r.min_clearance, at(ev.criteria, Criterion::min_clearance));
  EXPECT_GT(r.min_clearance, 0.0);
  EXPECT_EQ(r.torque_sq_0, r.torque_sq);
  EXPECT_EQ(r.power_sq_0, r.power_sq);
  EXPECT_DOUBLE_EQ(r.objective, 1.0);  // 0.4 + 0.6 at the reference
  EXPECT_EQ(r.duration, 9.0);
  EXPECT_EQ(r.evaluations, 0);
  EXPECT_LE(r.max_constraint, 0.0);
  // the history: t, q, qd, tau, points at every sample
  ASSERT_EQ(out.history.arrays.size(), 5u);
  EXPECT_EQ(out.history.arrays[0].name, "t");
  EXPECT_EQ(out.history.arrays[3].name, "tau");
  EXPECT_EQ(out.history.arrays[3].rows, static_cast<std::size_t>(P.samples()));
}

TEST(MotionKind, SolvedRunEqualsSolveMotion) {
  const Study s = parse_study(puma_study(""), "motion.toml");
  RunWorkspace ws;
  const RunOutcome out = execute(Scenario::of(s), s.blocks[0].run(0), 0, ws);
  const MotionResult& r = result_of(out);
  const MotionProblem P(puma_spec(s));
  MotionSolveOptions o;
  o.max_evaluations = 60;
  const MotionSummary S = solve_motion(P, o);
  EXPECT_EQ(out.status(), "ok");
  EXPECT_EQ(r.torque_sq, at(S.final, Criterion::torque_sq));
  EXPECT_EQ(r.power_sq, at(S.final, Criterion::power_sq));
  EXPECT_EQ(r.objective, S.final_objective);
  EXPECT_EQ(r.evaluations, S.evaluations);
  EXPECT_LT(r.torque_sq, r.torque_sq_0);
  EXPECT_LT(r.power_sq, r.power_sq_0);
  EXPECT_TRUE(out.history.arrays.empty());
}

// The dense check (check_factor times the samples) is the motion problem at those samples evaluated
// at the run's end: a problem that skips its reference's evaluation gives the same criteria bit for
// bit as one that evaluates it, and says its reference is not there.
TEST(MotionKind, DenseCheckIsTheProblemAtDenseSamples) {
  const Study s = parse_study(puma_study("solve = false\ncheck_factor = 4\n"), "motion.toml");
  RunWorkspace ws;
  const RunOutcome out = execute(Scenario::of(s), s.blocks[0].run(0), 0, ws);
  const MotionResult& r = result_of(out);
  MotionSpec spec = puma_spec(s);
  const MotionProblem P(spec);
  spec.samples = 4 * (P.samples() - 1) + 1;
  spec.normalise = false;
  const MotionProblem with_reference(spec);
  spec.evaluate_reference = false;
  const MotionProblem without(spec);
  EXPECT_TRUE(std::isnan(at(without.reference(), Criterion::torque_sq)));
  EXPECT_FALSE(std::isnan(at(with_reference.reference(), Criterion::torque_sq)));
  MotionEvaluation a, b;
  with_reference.evaluate(P.initial_point(), false, a);
  without.evaluate(P.initial_point(), false, b);
  for (int c = 0; c < kCriteria; ++c) EXPECT_EQ(a.criteria[c], b.criteria[c]) << c;
  EXPECT_EQ(a.constraints, b.constraints);
  EXPECT_EQ(r.check_samples, without.samples());
  EXPECT_EQ(r.check_min_clearance, at(b.criteria, Criterion::min_clearance));
  EXPECT_EQ(r.check_torque_sq_change, (at(b.criteria, Criterion::torque_sq) - r.torque_sq) / std::abs(r.torque_sq));
  // a problem without its reference cannot normalise
  spec.normalise = true;
  std::string why;
  EXPECT_FALSE(spec.IsValid(&why));
  EXPECT_NE(why.find("evaluate_reference"), std::string::npos) << why;
}

TEST(MotionKind, Tables) {
  KindContext ctx;
  ctx.robot.chain = true;
  ctx.robot.planar = false;
  ctx.robot.joints = 2;
  ctx.robot.prismatic = {false, true};
  const auto t = params(BlockKind::motion, ctx);
  const ParamDef* g1 = find_param(t, "goal_1");
  const ParamDef* g2 = find_param(t, "goal_2");
  ASSERT_TRUE(g1 && g2);
  EXPECT_EQ(g1->file_unit_name(), "deg");
  EXPECT_EQ(g2->file_unit_name(), "m");
  EXPECT_EQ(find_param(t, "goal_3"), nullptr);
  const RunSpec d = default_run(BlockKind::motion, ctx);
  EXPECT_DOUBLE_EQ(std::get<double>(g1->get(d)), 30.0 * kPi / 180.0);
  EXPECT_EQ(std::get<double>(g2->get(d)), 0.0);
  const auto st = statuses(BlockKind::motion);
  ASSERT_EQ(st.size(), 5u);
  EXPECT_EQ(st.front(), "ok");
  EXPECT_EQ(ranking(BlockKind::motion).objective, "objective");
}

TEST(MotionKind, FailureIsAStatus) {
  // duration outside [min_duration, max_duration] with vary_duration: the problem refuses, the run fails
  const Study s = parse_study(puma_study("vary_duration = true\nmax_duration = 5\n"), "motion.toml");
  RunWorkspace ws;
  const RunOutcome out = execute(Scenario::of(s), s.blocks[0].run(0), 1, ws);
  EXPECT_EQ(out.status(), "failure");
  EXPECT_TRUE(std::isnan(result_of(out).torque_sq));
  EXPECT_TRUE(out.history.arrays.empty());
}
