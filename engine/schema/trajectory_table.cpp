// The trajectory kind's parameters and metrics (see schema/params.hpp).
#include <algorithm>
#include <limits>

#include "methods/metrics/sample_metrics.hpp"
#include "methods/closed_form/seed_cases.hpp"
#include "schema/kind_tables.hpp"
#include "schema/table_builders.hpp"

namespace ks {

using namespace schema_detail;
using Run = TrajectoryRun;

namespace {
// global_spline starts from a local run (k, K_N) or a vertex_alpha one (vertex_alpha_i)
const EffectRule kLocalOnly{"method", {"local_weighted", "local_unweighted", "global_spline"}};
const EffectRule kLocalSpring{"method", {"local_weighted", "local_unweighted", "global_spline"}};
const EffectRule kVertexOnly{"method", {"vertex_alpha"}};
const EffectRule kVertexAngles{"method", {"vertex_alpha", "global_spline"}};
const EffectRule kGlobalOnly{"method", {"global_spline"}};

/// global_spline's own parameters (methods/base/path_global_options.hpp).
void global_params(std::vector<ParamDef>& t, const RobotShape& robot) {
  t.push_back(named<Run>("spline", names_of<AlphaSpline>(AlphaSpline::cubic, AlphaSpline::vertex_quintic),
                         "global_spline: alpha(t) as a clamped cubic B-spline (knots) or a quintic per path "
                         "segment through vertex values (seed cases 3-5's family)",
                         [](auto& r) -> auto& { return r.options.global.spline; }, kGlobalOnly));
  t.push_back(integer<Run>("knots", "", PathGlobalOptions::knots_rule,
                           "global_spline, cubic: breakpoints evenly spaced in time (= coefficients)",
                           [](auto& r) -> auto& { return r.options.global.knots; }, kGlobalOnly));
  // the planar chart (self_motion, alpha) is defined for the seed's arm and planar revolute chains;
  // joint coordinates for every chain
  const bool chart = robot.planar && !robot.pose_task;
  std::vector<std::string> extensions =
      !robot.chain ? names_of<Extension>(Extension::self_motion, Extension::alpha)
      : chart      ? names_of<Extension>(Extension::self_motion, Extension::alpha, Extension::joints)
                   : names_of<Extension>(Extension::joints);
  t.push_back(named<Run>("extension", std::move(extensions),
                         "global_spline, cubic: the coordinates the splines describe: the angle along the arm's "
                         "self-motion circle (crosses elbow branches), the tip angle alpha (one elbow branch), or "
                         "joint angles, the other joints solved on the task (joints; any chain)",
                         [](auto& r) -> auto& { return r.options.global.extension; }, kGlobalOnly));
  t.push_back(named<Run>("global_objective",
                         names_of<GlobalObjective>(GlobalObjective::E, GlobalObjective::E_M,
                                                   GlobalObjective::torque_sq_integral, GlobalObjective::kinetic_energy),
                         "global_spline: what alpha(t) minimises (E, E_M, torque_sq_integral, or the integral "
                         "of the kinetic energy)",
                         [](auto& r) -> auto& { return r.options.global.objective; }, kGlobalOnly));
  t.push_back(named<Run>("global_start", names_of<GlobalStart>(GlobalStart::local, GlobalStart::vertex, GlobalStart::random),
                         "global_spline: the optimiser's start: the local run (start_method, alpha1A, k, K_N), "
                         "vertex_alpha's alpha(t) (alpha1A, vertex_alpha_i), or random (start_seed)",
                         [](auto& r) -> auto& { return r.options.global.start; }, kGlobalOnly));
  t.push_back(named<Run>("start_method", names_of<StartMethod>(StartMethod::local_unweighted, StartMethod::local_weighted),
                         "global_spline, global_start = local: the local method of the start",
                         [](auto& r) -> auto& { return r.options.global.start_method; }, kGlobalOnly));
  t.push_back(named<Run>("start_posture", names_of<StartPosture>(StartPosture::fixed, StartPosture::free),
                         "global_spline: alpha at the start fixed at alpha1A, or free",
                         [](auto& r) -> auto& { return r.options.global.posture; }, kGlobalOnly));
  t.push_back(named<Run>("end_state", names_of<EndState>(EndState::rest, EndState::free),
                         "global_spline, cubic: the arm at rest at the end (as at the start), or free to move in "
                         "its self-motion there (as a local method's run may)",
                         [](auto& r) -> auto& { return r.options.global.end; }, kGlobalOnly));
  t.push_back(integer<Run>("start_seed", "", Domain::nonnegative(), "global_spline, global_start = random: the draw's seed",
                           [](auto& r) -> auto& { return r.options.global.start_seed; }, kGlobalOnly));
  t.push_back(real<Run>("opt_tolerance", FileUnit::none, "1", PathGlobalOptions::tolerance_rule,
                        "global_spline: relative change of the objective that stops the optimiser",
                        [](auto& r) -> auto& { return r.options.global.tolerance; }, kGlobalOnly));
  t.push_back(integer<Run>("max_evaluations", "", PathGlobalOptions::max_evaluations_rule,
                           "global_spline: objective evaluations allowed (each with its gradient)",
                           [](auto& r) -> auto& { return r.options.global.max_evaluations; }, kGlobalOnly));
  t.push_back(integer<Run>("verify_factor", "", PathGlobalOptions::verify_factor_rule,
                           "global_spline: the optimum is evaluated again between its samples, at dt / verify_factor "
                           "and dt / verify_factor^2 (1: not verified)",
                           [](auto& r) -> auto& { return r.options.global.verify_factor; }, kGlobalOnly));
  t.push_back(real<Run>("verify_tolerance", FileUnit::none, "1", PathGlobalOptions::verify_tolerance_rule,
                        "global_spline: the relative departure of the dense figures (E, peak torque, minimum "
                        "manipulability, tracking, limit ratios) from the sampled ones above which the run is "
                        "solved again on a finer grid, or ends undersampled",
                        [](auto& r) -> auto& { return r.options.global.verify_tolerance; }, kGlobalOnly));
  t.push_back(integer<Run>("refinements", "", PathGlobalOptions::refinements_rule,
                           "global_spline: how many times a run that departs between its samples is solved again "
                           "from its start on a grid verify_factor times finer (the metrics stay at dt)",
                           [](auto& r) -> auto& { return r.options.global.refinements; }, kGlobalOnly));
}

/// The task's placement and time scale (methods/base/task_placement.hpp): blocks that name one of them.
void placement_params(std::vector<ParamDef>& t, const RobotShape& robot) {
  const std::string about = robot.planar ? "the normal of the robot's plane (the base z for the xy plane)" : "the base z axis";
  t.push_back(real<Run>("task_rotation", FileUnit::none, "rad", TaskPlacement::rotation_rule,
                        "the whole task (path and orientations) rotated by this angle about " + about +
                            " before the translation (seed 002 Eq. 2.21's beta; a multiple of pi/2 is exact)",
                        [](auto& r) -> auto& { return r.placement.rotation; }));
  const std::string along = robot.planar ? " of the robot's plane" : " of the base";
  t.push_back(real<Run>("task_dx", FileUnit::none, "m", TaskPlacement::translation_rule,
                        "the whole task translated along the x axis" + along + " (seed 002's delta_x)",
                        [](auto& r) -> auto& { return r.placement.dx; }));
  t.push_back(real<Run>("task_dy", FileUnit::none, "m", TaskPlacement::translation_rule,
                        "the whole task translated along the y axis" + along + " (seed 002's delta_y)",
                        [](auto& r) -> auto& { return r.placement.dy; }));
  if (!robot.planar)  // a planar robot's task cannot leave its plane
    t.push_back(real<Run>("task_dz", FileUnit::none, "m", TaskPlacement::translation_rule,
                          "the whole task translated along the base z axis (seed 002's delta_z; spatial robots)",
                          [](auto& r) -> auto& { return r.placement.dz; }));
  t.push_back(real<Run>("task_time_scale", FileUnit::none, "", TaskPlacement::time_scale_rule,
                        "every segment duration of the task multiplied by this (2: the same path in twice the "
                        "time; dt is kept)",
                        [](auto& r) -> auto& { return r.placement.time_scale; }));
}

/// The preset: sets the row's method, k, alpha1A and vertex orientations (explicit keys override).
ParamDef preset_param() {
  ParamDef p;
  p.name = "preset";
  p.type = CellType::str;
  for (const SeedCase& c : seed_cases()) p.choices.emplace_back(c.name);
  p.description = "seed 000 Table 4 case (\"\" when none); sets method, k, alpha1A and the vertex orientations";
  p.leading = true;
  p.get = [](const RunSpec& r) { return Cell(std::get<Run>(r).preset); };
  p.set = [](RunSpec& r, const Cell& c) {
    Run& run = std::get<Run>(r);
    run.preset = std::get<std::string>(c);
    if (const SeedCase* sc = find_seed_case(run.preset)) {
      run.options.method = sc->method;
      run.options.k = sc->k;
      run.options.alpha1A = sc->alpha1A_deg * kDeg;
      for (std::size_t v = 0; v < run.options.vertex_alpha.size(); ++v)
        run.options.vertex_alpha[v] = v < sc->vertex_alpha_deg.size() ? sc->vertex_alpha_deg[v] * kDeg : 0.0;
    }
  };
  return p;
}
}  // namespace

std::vector<ParamDef> trajectory_params(const KindContext& ctx) {
  std::vector<ParamDef> t;
  t.push_back(preset_param());
  // (global_spline: revolute chains on a position path; other robots are refused at the key)
  t.push_back(named<Run>("method",
                         names_of<TrajectoryMethod>(TrajectoryMethod::local_weighted, TrajectoryMethod::local_unweighted,
                                                    TrajectoryMethod::vertex_alpha, TrajectoryMethod::global_spline),
                         "redundancy resolution method",
                         [](auto& r) -> auto& { return r.options.method; }));
  t.push_back(real<Run>("k", FileUnit::none, "", Domain::any(), "gravity weight in the resolution",
                        [](auto& r) -> auto& { return r.options.k; }, kLocalOnly));
  const RobotShape& robot = ctx.robot;
  if (robot.planar && !robot.pose_task)
    t.push_back(real<Run>("alpha1A", FileUnit::deg, "rad", Domain::any(), "end-effector orientation at the start",
                          [](auto& r) -> auto& { return r.options.alpha1A; }));
  t.push_back(real<Run>("K_N", FileUnit::none, "1/s", TrajectoryOptions::null_damping_rule, "null-space damping",
                        [](auto& r) -> auto& { return r.options.null_damping; }, kLocalOnly));
  t.push_back(real<Run>("K_L", FileUnit::none, "1/s^2", TrajectoryOptions::limit_centring_rule,
                        "null-space spring towards the middle of each joint's position limits (joints with "
                        "both limits; 0 = none)",
                        [](auto& r) -> auto& { return r.options.limit_centring; }, kLocalSpring));
  for (std::size_t v = 2; robot.vertex_alpha() && v <= ctx.path_vertices; ++v) {
    const std::size_t i = v - 2;
    t.push_back(real<Run>("vertex_alpha_" + std::to_string(v), FileUnit::deg, "rad", Domain::any(),
                          "orientation at vertex " + std::to_string(v) + " (vertex_alpha; global_spline: its vertex start)",
                          [i](auto& r) -> auto& { return r.options.vertex_alpha[i]; }, kVertexAngles));
  }
  if (ctx.path_global && robot.path_global()) global_params(t, robot);
  t.push_back(named<Run>("integrator", names_of<Integrator>(Integrator::semi_implicit_euler, Integrator::rk4),
                         "time integrator", [](auto& r) -> auto& { return r.options.integrator; }));
  t.push_back(real<Run>("dt", FileUnit::none, "s", TrajectoryOptions::dt_rule, "sample / integration step",
                        [](auto& r) -> auto& { return r.options.dt; }));
  t.push_back(real<Run>("torque_bound", FileUnit::none, "Nm", TrajectoryOptions::torque_bound_rule,
                        "|tau_i| above this stops the run (diverged)",
                        [](auto& r) -> auto& { return r.options.torque_bound; }));
  t.push_back(real<Run>("K_P", FileUnit::none, "1/s^2", TrajectoryOptions::clik_gain_rule,
                        "closed-loop task feedback: + K_P (path - tip) in the commanded task acceleration (0 = open loop)",
                        [](auto& r) -> auto& { return r.options.clik_kp; }));
  t.push_back(real<Run>("K_D", FileUnit::none, "1/s", TrajectoryOptions::clik_gain_rule,
                        "closed-loop task feedback: + K_D (path velocity - tip velocity) (0 = open loop)",
                        [](auto& r) -> auto& { return r.options.clik_kd; }));
  t.push_back(real<Run>("tracking_bound", FileUnit::none, "m", TrajectoryOptions::bound_rule,
                        "|tip - path| above this at any sample makes the run off_path (see on_violation)",
                        [](auto& r) -> auto& { return r.options.tracking_bound; }));
  if (robot.pose_task || robot.vertex_alpha())
    t.push_back(real<Run>("orientation_bound", FileUnit::deg, "rad", TrajectoryOptions::bound_rule,
                          "an orientation error above this at any sample makes the run off_path (pose tasks, vertex_alpha)",
                          [](auto& r) -> auto& { return r.options.orientation_bound; },
                          robot.pose_task ? EffectRule{} : kVertexOnly));
  t.push_back(named<Run>("on_violation", names_of<OnViolation>(OnViolation::mark, OnViolation::stop, OnViolation::ignore),
                         "a sample beyond the tracking bound or the joint limits: mark (status off_path / "
                         "out_of_limits, run to the end), stop (end there, metrics NaN) or ignore",
                         [](auto& r) -> auto& { return r.options.on_violation; }));
  if (!robot.chain)
    t.push_back(named<Run>("inertia", names_of<InertiaForm>(InertiaForm::physical, InertiaForm::thesis_m11),
                           "closed form of M(q)", [](auto& r) -> auto& { return r.inertia; }));
  if (!robot.chain) {
    t.push_back(named<Run>("start_branch", names_of<Elbow>(Elbow::positive, Elbow::negative),
                           "elbow branch of the start posture's analytic IK at alpha1A: elbow_down (sin theta2 >= 0, "
                           "the seed's) or elbow_up",
                           [](auto& r) -> auto& { return r.options.elbow; }));
    const EffectRule local{"method", {"local_weighted", "local_unweighted"}};
    t.push_back(named<Run>("end", names_of<EndState>(EndState::free, EndState::rest),
                           "local methods: free (the method's own motion to the end) or rest (over the last "
                           "end_window the null-space term blends into -(I - J+ J) end_gain qd and the tip error "
                           "is fed back: the arm ends at rest on the path's end)",
                           [](auto& r) -> auto& { return r.options.end; }, local));
    t.push_back(real<Run>("end_window", FileUnit::none, "s", TrajectoryOptions::end_window_rule,
                          "end = rest: time before the path's end from which the terminal feedback acts",
                          [](auto& r) -> auto& { return r.options.end_window; }, local));
    t.push_back(real<Run>("end_gain", FileUnit::none, "1/s", TrajectoryOptions::end_gain_rule,
                          "end = rest: the terminal feedback's gain K_S on the self-motion rate",
                          [](auto& r) -> auto& { return r.options.end_gain; }, local));
  }
  for (int j = 0; robot.chain && j < robot.joints; ++j) {
    const bool prismatic = robot.is_prismatic(j);
    t.push_back(real<Run>("q0_" + std::to_string(j + 1), prismatic ? FileUnit::none : FileUnit::deg,
                          prismatic ? "m" : "rad", Domain::any(),
                          "initial guess of the start configuration, joint " + std::to_string(j + 1) +
                              " (placed on the first vertex by an IK solve)",
                          [j](auto& r) -> auto& { return r.q0[j]; }));
  }
  if (ctx.placement) placement_params(t, robot);
  return t;
}

std::vector<MetricDef> trajectory_metrics(const KindContext& ctx) {
  using M = TrajectoryMetrics;
  std::vector<MetricDef> m{
      metric<M>("E", CellType::f64, "Nm", "mean over samples of sqrt(tau^T tau) (seed Eq. 60)", true,
                [](const M& r) { return r.E; })
          .labelled("E (mean ‖τ‖)"),
      metric<M>("E_M", CellType::f64, "Nm/sqrt(kg m^2)", "mean over samples of sqrt(tau^T M^-1 tau)", true,
                [](const M& r) { return r.E_M; })
          .labelled("E_M (mean ‖τ‖ in M⁻¹ norm)"),
      metric<M>("tau_inf", CellType::f64, "Nm", "max over samples and revolute joints of |tau_i|", true,
                [robot = ctx.robot](const M& r) {
                  double a = -std::numeric_limits<double>::infinity();
                  bool any = false;
                  for (int j = 0; j < r.tau_inf.size(); ++j)
                    if (!robot.is_prismatic(j)) a = any ? std::max(a, r.tau_inf[j]) : r.tau_inf[j], any = true;
                  return any ? a : std::numeric_limits<double>::quiet_NaN();
                })
          .labelled("‖τ‖∞"),
      metric<M>("min_manipulability", CellType::f64, "m^2", "min over samples of sqrt(det(J J^T))", true,
                [](const M& r) { return r.min_manipulability; })
          .labelled("min manipulability"),
      metric<M>("torque_sq_integral", CellType::f64, "N^2 m^2 s",
                "trapezoidal integral of sum tau_i^2 (seed 002 f5)", false,
                [](const M& r) { return r.torque_sq_integral; }),
      metric<M>("power_sq_integral", CellType::f64, "W^2 s", "trapezoidal integral of sum (tau_i qd_i)^2 (seed 002 f6)",
                false, [](const M& r) { return r.power_sq_integral; }),
      metric<M>("max_tracking_error", CellType::f64, "m", "max over samples of |tip - path| (open-loop drift)", true,
                [](const M& r) { return r.max_tracking_error; })
          .labelled("max tracking error"),
      metric<M>("mean_tracking_error", CellType::f64, "m", "mean over samples of |tip - path|", true,
                [](const M& r) { return r.mean_tracking_error; })
          .labelled("mean tracking error"),
      metric<M>("final_alpha", CellType::f64, "rad", "end-effector orientation at the last sample", false,
                [](const M& r) { return r.final_alpha; }),
      metric<M>("samples", CellType::i64, "", "samples computed (2001 for the seed's square)", false,
                [](const M& r) { return std::int64_t(r.samples); }),
      metric<M>("stop_time", CellType::f64, "s", "time of the last sample computed", false,
                [](const M& r) { return r.samples == 0 ? std::numeric_limits<double>::quiet_NaN() : r.stop_time; }),
  };
  // per joint, after tau_inf: tau1_inf .. tau<n>_inf (N for a prismatic joint)
  std::vector<MetricDef> joints;
  for (int j = 0; j < ctx.robot.joints; ++j) {
    const std::string i = std::to_string(j + 1);
    joints.push_back(metric<M>("tau" + i + "_inf", CellType::f64, ctx.robot.is_prismatic(j) ? "N" : "Nm",
                               "max over samples of |tau_" + i + "|", true, [j](const M& r) {
                                 return j < r.tau_inf.size() ? r.tau_inf[j] : std::numeric_limits<double>::quiet_NaN();
                               }).labelled("‖τ" + i + "‖∞"));
  }
  m.insert(m.begin() + 3, joints.begin(), joints.end());
  const RobotShape& robot = ctx.robot;
  if (robot.pose_task || robot.vertex_alpha())
    m.push_back(metric<M>("max_orientation_error", CellType::f64, "rad",
                          "max over samples of the tip's orientation error (pose tasks, vertex_alpha; NaN otherwise)",
                          true, [](const M& r) { return r.max_orientation_error; }));
  bool prismatic = false;
  for (int j = 0; j < robot.joints; ++j) prismatic = prismatic || robot.is_prismatic(j);
  if (prismatic) {
    m.push_back(metric<M>("E_force", CellType::f64, "N",
                          "mean over samples of sqrt(f^T f) over the prismatic joints (E covers the revolute ones)",
                          true, [](const M& r) { return r.E_force; }));
    m.push_back(metric<M>("force_inf", CellType::f64, "N", "max over samples and prismatic joints of |f_i|", true,
                          [robot](const M& r) {
                            double a = 0;
                            for (int j = 0; j < r.tau_inf.size(); ++j)
                              if (robot.is_prismatic(j)) a = std::max(a, r.tau_inf[j]);
                            return r.tau_inf.hasNaN() ? std::numeric_limits<double>::quiet_NaN() : a;
                          }));
  }
  for_each_sample_metric([&](const auto& e, int k) {
    m.push_back(metric<M>(std::string(e.name), CellType::f64, std::string(e.unit), std::string(e.description),
                          e.gridded, [k](const M& r) { return r.sampled[k]; })
                    .labelled(std::string(e.label)));
  });
  if (ctx.path_global && robot.path_global()) {
    m.push_back(metric<M>("opt_start_objective", CellType::f64, "",
                          "global_spline: the objective at the optimiser's start (units of global_objective)", false,
                          [](const M& r) { return r.opt_start_objective; }));
    m.push_back(metric<M>("opt_objective", CellType::f64, "",
                          "global_spline: the objective at the optimum (units of global_objective)", true,
                          [](const M& r) { return r.opt_objective; }));
    m.push_back(metric<M>("opt_evaluations", CellType::f64, "", "global_spline: objective evaluations made", true,
                          [](const M& r) { return r.opt_evaluations; }));
    m.push_back(metric<M>("opt_dt", CellType::f64, "s",
                          "global_spline: the sample step of the grid the optimiser last solved on (dt / 2^k after "
                          "k refinements)",
                          false, [](const M& r) { return r.opt_dt; }));
    m.push_back(metric<M>("dense_E", CellType::f64, "Nm",
                          "global_spline: E of the same trajectory at dt / verify_factor^2 (between the samples)", false,
                          [](const M& r) { return r.dense.E; }));
    m.push_back(metric<M>("dense_tau_inf", CellType::f64, "Nm",
                          "global_spline: max over joints of |tau_i| at dt / verify_factor^2", false,
                          [](const M& r) { return r.dense.tau_inf; }));
    m.push_back(metric<M>("dense_min_manipulability", CellType::f64, "m^2",
                          "global_spline: min manipulability at dt / verify_factor^2", false,
                          [](const M& r) { return r.dense.min_manipulability; }));
    m.push_back(metric<M>("dense_max_tracking_error", CellType::f64, "m",
                          "global_spline: max tracking error at dt / verify_factor^2", false,
                          [](const M& r) { return r.dense.max_tracking_error; }));
    if (robot.chain && robot.limited)
      m.push_back(metric<M>("dense_max_limit_ratio", CellType::f64, "",
                            "global_spline: the largest position, velocity or effort limit ratio at dt / "
                            "verify_factor^2",
                            false, [](const M& r) { return r.dense.max_limit_ratio; }));
    m.push_back(metric<M>("dense_departure", CellType::f64, "",
                          "global_spline: the largest relative departure of the figures at dt / verify_factor and "
                          "dt / verify_factor^2 from those at the samples (inf: the dense evaluation stopped where "
                          "the sampled one did not); above verify_tolerance the run is undersampled",
                          true, [](const M& r) { return r.dense.departure; }));
    m.push_back(metric<M>("opt_gradient_norm", CellType::f64, "",
                          "global_spline: infinity norm of the projected gradient at the optimum, or with active "
                          "limit constraints the KKT residual min over lambda >= 0 of |grad + J^T lambda| "
                          "(objective units per rad)",
                          false, [](const M& r) { return r.opt_gradient_norm; }));
    if (robot.chain)
      m.push_back(metric<M>("opt_solved_joints", CellType::f64, "",
                            "global_spline, joints extension: the joints solved on the task, 1-based, as digits "
                            "(124: joints 1, 2 and 4; NaN: the planar chart)",
                            false, [](const M& r) { return r.opt_solved_joints; }));
    if (robot.chain && robot.limited)
      m.push_back(metric<M>("opt_active_limits", CellType::f64, "",
                            "global_spline: limit constraints (window of samples x limited quantity) active at the "
                            "optimum (ratio within 1e-4 of the bound)",
                            false, [](const M& r) { return r.opt_active_limits; }));
  }
  if (ctx.placement)
    m.push_back(metric<M>("ik_error", CellType::f64, "m",
                          "seed 002's inverse-kinematics error of the placed task (Eqs. 2.24-2.25): the sum over "
                          "its vertices of the distance from each to the tip of the robot's position IK solution "
                          "there, each counted when 1 mm or more (0: every vertex within reach; > 0: the run is "
                          "out_of_reach)",
                          true, [](const M& r) { return r.ik_error; })
                    .labelled("IK error"));
  if (robot.chain) {
    m.push_back(metric<M>("max_q_limit_ratio", CellType::f64, "",
                          "max over samples and joints of |q - mid| / half range (1 = at a position limit; NaN: none)",
                          false, [](const M& r) { return r.max_q_limit_ratio; }));
    m.push_back(metric<M>("max_qd_limit_ratio", CellType::f64, "",
                          "max over samples and joints of |qd| / velocity limit (NaN: none)", false,
                          [](const M& r) { return r.max_qd_limit_ratio; }));
    m.push_back(metric<M>("max_tau_limit_ratio", CellType::f64, "",
                          "max over samples and joints of |tau| / effort limit (NaN: none)", false,
                          [](const M& r) { return r.max_tau_limit_ratio; }));
  }
  return m;
}

}  // namespace ks
