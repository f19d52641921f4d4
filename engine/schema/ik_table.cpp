// The IK kind's parameters and metrics (see schema/params.hpp).
#include "schema/kind_tables.hpp"
#include "schema/table_builders.hpp"

namespace ks {

using namespace schema_detail;
using Run = IkRun;

IkRun IkRun::planar_defaults() {
  IkRun r;
  r.problem = IkProblem::planar3r_pose;
  r.q0 = joint_vector({0.0, 90.0 * kDeg, -90.0 * kDeg});
  r.target = {1.5, 1.5, std::numeric_limits<double>::quiet_NaN()};
  r.target_alpha = 0.0;
  r.z_mode = ZMode::unset;
  return r;
}

IkRun IkRun::chain_defaults(const std::vector<bool>& prismatic, int joints, const Eigen::Vector3d& target,
                            bool limited) {
  IkRun r;
  r.options.joint_limits = limited ? ik::JointLimits::clamp : ik::JointLimits::none;
  r.problem = IkProblem::position;
  r.q0 = VecN::Zero(joints);
  for (int j = 0; j < joints; ++j) r.q0[j] = j < int(prismatic.size()) && prismatic[j] ? 0.0 : 30.0 * kDeg;
  r.target = target;
  r.target_alpha = 0.0;
  r.z_mode = ZMode::unset;
  return r;
}

std::vector<ParamDef> ik_params(const KindContext& ctx) {
  using ik::Method;
  const RobotShape& robot = ctx.robot;
  const std::string len = ctx.scara ? "mm" : "m";
  std::vector<std::string> iterative;  // every method but analytic: the start matters
  for (Method m : {Method::newton, Method::lm, Method::lm_adaptive, Method::halley_thesis, Method::halley})
    iterative.emplace_back(ik::to_string(m));
  const EffectRule from_start{"method", iterative};
  std::vector<ParamDef> t;
  const std::vector<std::string> problems =
      robot.chain ? names_of<IkProblem>(IkProblem::scara, IkProblem::position, IkProblem::pose)
                  : names_of<IkProblem>(IkProblem::scara, IkProblem::planar3r_pose, IkProblem::planar3r_position,
                                        IkProblem::position, IkProblem::pose);
  t.push_back(named<Run>("problem", problems, "IK problem", [](auto& r) -> auto& { return r.problem; }));
  t.push_back(named<Run>("method",
                         names_of<Method>(Method::newton, Method::lm, Method::lm_adaptive, Method::halley_thesis,
                                          Method::halley, Method::analytic),
                         "IK method", [](auto& r) -> auto& { return r.options.method; }));
  t.push_back(real<Run>("lambda", FileUnit::none, "", ik::Options::lambda_rule,
                        "Levenberg-Marquardt damping (lm, lm_adaptive)", [](auto& r) -> auto& { return r.options.lambda; },
                        EffectRule{"method", {"lm", "lm_adaptive"}}));
  const int n = ctx.scara ? 3 : robot.joints;
  for (int j = 0; j < n; ++j) {
    const std::string i = std::to_string(j + 1);
    const bool mm = ctx.scara && j == 2, metres = !ctx.scara && robot.is_prismatic(j);
    std::string what = "initial guess, joint " + i;
    if (j == 2 && !robot.chain) what += " (SCARA: prismatic d)";
    t.push_back(real<Run>("q0_" + i, mm || metres ? FileUnit::none : FileUnit::deg, mm ? "mm" : metres ? "m" : "rad",
                          Domain::any(), what, [j](auto& r) -> auto& { return r.q0[j]; }, from_start));
  }
  std::vector<std::string> with_z{"scara"}, with_alpha{"planar3r_pose"};
  if (robot.planar) with_alpha.push_back("pose");
  else with_z.insert(with_z.end(), {"position", "pose"});
  t.push_back(real<Run>("target_x", FileUnit::none, len, Domain::any(), "target x",
                        [](auto& r) -> auto& { return r.target[0]; }));
  t.push_back(real<Run>("target_y", FileUnit::none, len, Domain::any(), "target y",
                        [](auto& r) -> auto& { return r.target[1]; }));
  t.push_back(real<Run>("target_z", FileUnit::none, len, Domain::any(),
                        robot.planar ? "target z (SCARA)" : "target z (SCARA, spatial chains)",
                        [](auto& r) -> auto& { return r.target[2]; }, EffectRule{"problem", with_z}));
  t.push_back(real<Run>("target_alpha", FileUnit::deg, "rad", Domain::any(),
                        robot.planar ? "target orientation (planar3r_pose, pose)" : "target orientation (planar3r_pose)",
                        [](auto& r) -> auto& { return r.target_alpha; }, EffectRule{"problem", with_alpha}));
  if (!robot.planar) {
    const char* axis[3] = {"roll (about x)", "pitch (about y)", "yaw (about z)"};
    const char* name[3] = {"target_roll", "target_pitch", "target_yaw"};
    for (int a = 0; a < 3; ++a)
      t.push_back(real<Run>(name[a], FileUnit::deg, "rad", Domain::any(),
                            std::string("target orientation, ") + axis[a] + "; R = Rz(yaw) Ry(pitch) Rx(roll) (pose)",
                            [a](auto& r) -> auto& { return r.target_rpy[a]; }, EffectRule{"problem", {"pose"}}));
  }
  t.push_back(real<Run>("tol", FileUnit::none, ctx.scara ? "mm" : "", ik::Options::tolerance_rule,
                        "stop when the residual norm falls below this",
                        [](auto& r) -> auto& { return r.options.tolerance; }));
  t.push_back(integer<Run>("max_iter", "", ik::Options::max_iter_rule, "iteration cap",
                           [](auto& r) -> auto& { return r.options.max_iter; }));
  t.push_back(named<Run>("joint_limits",
                         names_of<ik::JointLimits>(ik::JointLimits::none, ik::JointLimits::clamp, ik::JointLimits::reject),
                         "the robot's joint limits: ignored, iterates clamped into them, or a solution outside "
                         "them ends out_of_limits (position, pose; default clamp when the robot has limits)",
                         [](auto& r) -> auto& { return r.options.joint_limits; }, EffectRule{"problem", {"position", "pose"}}));
  t.push_back(integer<Run>("restarts", "", ik::Options::restarts_rule,
                           "random restarts after a failed attempt, from starts drawn within the joint limits "
                           "((-180, 180) deg for unlimited revolute joints); iterations are summed over attempts",
                           [](auto& r) -> auto& { return r.options.restarts; }, from_start));
  t.push_back(integer<Run>("stall_window", "", ik::Options::stall_window_rule,
                           "an attempt whose residual norm has not halved over this many updates ends stalled "
                           "(and gives way to a restart); 0: no check",
                           [](auto& r) -> auto& { return r.options.stall_window; }, from_start));
  t.push_back(integer<Run>("restart_seed", "", IkRun::restart_seed_rule,
                           "seed of the restarts' draws (mixed with the run's start and target)",
                           [](auto& r) -> auto& { return r.restart_seed; }, from_start));
  t.push_back(named<Run>("z_mode", names_of<ZMode>(ZMode::thesis, ZMode::physical),
                         "SCARA z residual: thesis (+q3) or physical", [](auto& r) -> auto& { return r.z_mode; },
                         EffectRule{"problem", {"scara"}}));
  return t;
}

std::vector<MetricDef> ik_metrics(const KindContext& ctx) {
  using R = IkResult;
  MetricDef iterations = metric<R>("iterations", CellType::i64, "",
                                   "updates made (the seed's count; summed over restarts)", true,
                                   [](const R& r) { return std::int64_t(r.iterations); })
                             .labelled("iterations");
  iterations.if_failed = [](const RunSpec& r) { return double(std::get<IkRun>(r).options.max_iter); };
  std::vector<MetricDef> m{
      iterations,
      metric<R>("error", CellType::f64, ctx.scara ? "mm" : "problem units",
                "||F|| at the final iterate (mm for scara; for the other problems the residual's own units: m, or "
                "m and rad mixed)",
                true, [](const R& r) { return r.error; })
          .labelled("final ‖F‖"),
      metric<R>("solution", CellType::i64, "", "index of the known exact solution reached (mod 2 pi), -1 if none",
                true, [](const R& r) { return std::int64_t(r.solution); })
          .labelled("solution reached"),
      metric<R>("rejected", CellType::i64, "", "lm_adaptive: rejected trial steps", false,
                [](const R& r) { return std::int64_t(r.rejected); }),
      metric<R>("min_rcond", CellType::f64, "", "smallest reciprocal condition number met", false,
                [](const R& r) { return r.min_rcond; }),
      metric<R>("restarts_used", CellType::i64, "", "random restarts made (0: the first attempt's outcome)", true,
                [](const R& r) { return std::int64_t(r.restarts_used); }),
  };
  const int n = ctx.scara ? 3 : ctx.robot.joints;
  for (int j = 0; j < n; ++j) {
    const std::string i = std::to_string(j + 1);
    std::string unit = ctx.robot.is_prismatic(j) ? "m" : "rad", what = "final iterate, joint " + i;
    if (j == 2 && !ctx.robot.chain) unit = ctx.scara ? "mm" : "rad", what += ctx.scara ? " (d)" : "";
    if (unit == "rad") what += " (converged, limits not enforced: wrapped to (-pi, pi])";
    m.push_back(metric<R>("q_final_" + i, CellType::f64, unit, what, false, [j](const R& r) {
      return j < r.q.size() ? r.q[j] : std::numeric_limits<double>::quiet_NaN();
    }));
  }
  return m;
}

}  // namespace ks
