// One motion run: a MotionRun (schema/run_spec.hpp) as a motion::MotionProblem on the study's chain
// and [world], solved by motion::solve_motion (or its initial cubic evaluated), into a MotionResult
// with its status and, when asked, the history of its samples (t, q, qd, tau).
#include "runner/execute_motion.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <optional>

#include "model/chain_kinematics.hpp"
#include "motion/solve_motion.hpp"
#include "schema/history_arrays.hpp"

namespace ks {

namespace {

using motion::Criterion;

/// The status of a motion that ended at criteria `c` with largest constraint `worst`, its solve's
/// termination `term` (nullopt: no solve, the cubic evaluated). `tolerance`: a constraint value up
/// to this counts as kept.
MotionStatus status_of(const motion::Criteria& c, double worst, double tolerance,
                       std::optional<motion::MotionTermination> term) {
  using T = motion::MotionTermination;
  for (int k = 0; k < motion::kCriteria; ++k)
    if (std::isnan(c[k]) || (k != int(Criterion::min_clearance) && !std::isfinite(c[k]))) return MotionStatus::failure;
  if (!std::isfinite(worst)) return MotionStatus::failure;
  if (term && *term == T::failure) return MotionStatus::failure;
  if (motion::at(c, Criterion::min_clearance) < 0.0) return MotionStatus::collision;
  if (worst > tolerance || (term && *term == T::infeasible)) return MotionStatus::infeasible;
  if (term && *term == T::max_evaluations) return MotionStatus::max_evaluations;
  return MotionStatus::ok;
}

/// The history arrays of `robot`'s motion at x: every stride-th sample of `problem` and the last
/// (t [s], q [rad or m], qd [rad/s or m/s], tau [Nm or N], points: the joint origins and the tip [m]).
/// Evaluates the problem at x (no gradients).
std::vector<HistoryArray> motion_arrays(const motion::MotionProblem& problem, const std::vector<double>& x,
                                        const RobotShape& robot, int stride) {
  motion::MotionEvaluation ev;
  problem.evaluate(x, false, ev);
  const motion::JointSpline spline = problem.spline_at(x);
  const std::vector<VecN>& tau = problem.last_torques();
  const int N = problem.samples(), n = problem.joints();
  std::vector<int> rows;
  for (int s = 0; s < N; s += stride) rows.push_back(s);
  if (rows.back() != N - 1) rows.push_back(N - 1);
  const auto defs = motion_history_arrays(robot);
  std::vector<HistoryArray> a;
  for (const HistoryArrayDef& d : defs) a.push_back({d.name, d.unit, rows.size(), d.columns, {}});
  for (auto& h : a) h.data.reserve(rows.size() * h.cols);
  VecN q(n), qd(n), qdd(n), jerk(n);
  const Chain& chain = problem.spec().chain;
  ChainData data;
  for (int s : rows) {
    const double t = problem.sample_time(s, spline.duration());
    spline.evaluate(t, q, qd, qdd, jerk);
    a[0].data.push_back(t);
    for (int j = 0; j < n; ++j) a[1].data.push_back(q[j]);
    for (int j = 0; j < n; ++j) a[2].data.push_back(qd[j]);
    for (int j = 0; j < n; ++j) a[3].data.push_back(tau[static_cast<std::size_t>(s)][j]);
    forward_kinematics(chain, data, q);
    for (int k = 0; k <= n; ++k) {
      const Vec3& p = k < n ? data.joint[static_cast<std::size_t>(k)].p : data.tip.p;
      for (int c = 0; c < 3; ++c) a[4].data.push_back(p[c]);
    }
  }
  return a;
}


/// Re-evaluates the end x of `problem` at factor times as many samples (the same spline, windows,
/// limits and obstacles) into res's check_* fields; `c` the criteria at the problem's own samples.
/// False when a dense value is NaN (the run is then a failure).
bool dense_check(const motion::MotionProblem& problem, const std::vector<double>& x, int factor,
                 const motion::Criteria& c, MotionResult& res) {
  motion::MotionSpec spec = problem.spec();
  spec.samples = factor * (problem.samples() - 1) + 1;
  spec.normalise = false;  // the objective is not used; its reference may be 0
  spec.evaluate_reference = false;
  const motion::MotionProblem dense(std::move(spec));
  motion::MotionEvaluation ev;
  dense.evaluate(x, false, ev);
  res.check_samples = dense.samples();
  const double clear = motion::at(ev.criteria, Criterion::min_clearance);
  res.check_min_clearance = std::isinf(clear) ? MotionResult::kNaN : clear;  // +inf: no obstacles
  bool nan = std::isnan(clear), limited = false;
  double worst = -std::numeric_limits<double>::infinity();  // the largest ratio - 1
  for (std::size_t i = 0; i < ev.constraints.size(); ++i) {
    if (dense.constraint_list()[i].kind == motion::MotionConstraint::Kind::clearance) continue;
    nan = nan || std::isnan(ev.constraints[i]);
    limited = true;
    worst = std::max(worst, ev.constraints[i] + dense.spec().limit_margin);
  }
  res.check_max_limit = limited && !nan ? worst : MotionResult::kNaN;
  const auto change = [&](Criterion k) {
    return (motion::at(ev.criteria, k) - motion::at(c, k)) / std::abs(motion::at(c, k));
  };
  res.check_torque_sq_change = change(Criterion::torque_sq);
  res.check_power_sq_change = change(Criterion::power_sq);
  return !nan && !std::isnan(motion::at(ev.criteria, Criterion::torque_sq)) &&
         !std::isnan(motion::at(ev.criteria, Criterion::power_sq));
}

}  // namespace

RunOutcome run_motion(const Scenario& sc, const MotionRun& run, int stride) {
  RunOutcome out;
  MotionResult res;
  out.result = res;
  const Chain* chain = sc.base_chain ? sc.base_chain : sc.chain;
  if (!chain) return out;  // failure: no chain (the parser refuses such blocks)
  motion::MotionSpec spec;
  spec.chain = *chain;
  spec.q_start = run.start;
  spec.q_goal = run.goal;
  spec.controls = run.controls;
  spec.duration = run.duration;
  // Without a solve, T is a variable that is never moved when there are no controls to vary.
  spec.vary_duration = run.solve ? run.vary_duration : run.controls == 0;
  spec.min_duration = run.min_duration;
  spec.max_duration = run.max_duration;
  spec.samples = run.samples;
  motion::at(spec.weights, Criterion::torque_sq) = run.w_torque;
  motion::at(spec.weights, Criterion::power_sq) = run.w_power;
  motion::at(spec.weights, Criterion::duration) = run.w_time;
  motion::at(spec.weights, Criterion::peak_torque) = run.w_peak;
  motion::at(spec.weights, Criterion::jerk_sq) = run.w_jerk;
  motion::at(spec.weights, Criterion::min_manipulability) = run.w_manipulability;
  motion::at(spec.weights, Criterion::min_clearance) = run.w_clearance;
  spec.normalise = run.normalise;
  if (sc.world && sc.world->has_obstacles()) {
    spec.obstacles = sc.world->obstacles;
    spec.obstacle_velocities = sc.world->velocities;
    spec.radii = sc.world->link_radius;
    spec.clearance_margin = run.clearance_margin;
  }
  spec.limit_margin = run.limit_margin;
  motion::MotionSolveOptions options;
  options.max_evaluations = run.max_evaluations;
  options.starts = run.starts;
  try {
    const motion::MotionProblem problem(std::move(spec));
    std::vector<double> x = problem.initial_point();
    motion::Criteria c{};
    double objective = 0.0, worst = 0.0;
    std::optional<motion::MotionTermination> term;
    if (run.solve) {
      const motion::MotionSummary s = motion::solve_motion(problem, options);
      x = s.x;
      c = s.final;
      objective = s.final_objective;
      worst = s.max_constraint;
      term = s.termination;
      res.evaluations = s.evaluations;
    } else {
      motion::MotionEvaluation ev;
      problem.evaluate(x, false, ev);
      c = ev.criteria;
      objective = ev.objective;
      if (!ev.constraints.empty()) worst = *std::max_element(ev.constraints.begin(), ev.constraints.end());
      if (std::any_of(ev.constraints.begin(), ev.constraints.end(), [](double g) { return std::isnan(g); }))
        worst = std::numeric_limits<double>::quiet_NaN();
    }
    res.status = status_of(c, worst, options.constraint_tolerance, term);
    // ok and max_evaluations hold only if the dense check agrees: no collision, no limit exceeded
    // between the samples either.
    const bool dense_ok = dense_check(problem, x, run.check_factor, c, res);
    if (res.status == MotionStatus::ok || res.status == MotionStatus::max_evaluations) {
      if (!dense_ok) res.status = MotionStatus::failure;
      else if (res.check_min_clearance < 0.0) res.status = MotionStatus::collision;
      else if (res.check_max_limit > options.constraint_tolerance) res.status = MotionStatus::infeasible;
    }
    if (!std::isfinite(objective) && res.status != MotionStatus::failure) res.status = MotionStatus::failure;
    res.duration = motion::at(c, Criterion::duration);
    res.torque_sq = motion::at(c, Criterion::torque_sq);
    res.power_sq = motion::at(c, Criterion::power_sq);
    res.peak_torque = motion::at(c, Criterion::peak_torque);
    res.jerk_sq = motion::at(c, Criterion::jerk_sq);
    res.min_manipulability = motion::at(c, Criterion::min_manipulability);
    const double clear = motion::at(c, Criterion::min_clearance);
    res.min_clearance = std::isfinite(clear) ? clear : MotionResult::kNaN;  // +inf: no obstacles
    res.torque_sq_0 = motion::at(problem.reference(), Criterion::torque_sq);
    res.power_sq_0 = motion::at(problem.reference(), Criterion::power_sq);
    res.objective = objective;
    res.max_constraint = worst;
    out.result = res;
    if (stride > 0 && !x.empty()) out.history.arrays = motion_arrays(problem, x, RobotShape::of(*chain), stride);
  } catch (const std::exception&) {  // a problem that cannot be set up (e.g. a zero reference to normalise by)
    res = MotionResult{};
    res.status = MotionStatus::failure;
    out.result = res;
    out.history.arrays.clear();
  }
  return out;
}

}  // namespace ks
