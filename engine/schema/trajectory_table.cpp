// The trajectory kind's parameters and metrics (see schema/params.hpp).
#include "methods/seed_cases.hpp"
#include "schema/kind_tables.hpp"
#include "schema/table_builders.hpp"

namespace ks {

using namespace schema_detail;
using Run = TrajectoryRun;

namespace {
const EffectRule kLocalOnly{"method", {"local_weighted", "local_unweighted"}};
const EffectRule kVertexOnly{"method", {"vertex_alpha"}};

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
  t.push_back(named<Run>("method", names_of<TrajectoryMethod>(TrajectoryMethod::local_weighted,
                                                               TrajectoryMethod::local_unweighted,
                                                               TrajectoryMethod::vertex_alpha),
                         "redundancy resolution method", [](auto& r) -> auto& { return r.options.method; }));
  t.push_back(real<Run>("k", FileUnit::none, "", Domain::any(), "gravity weight in the resolution",
                        [](auto& r) -> auto& { return r.options.k; }, kLocalOnly));
  const RobotShape& robot = ctx.robot;
  if (robot.planar && !robot.pose_task)
    t.push_back(real<Run>("alpha1A", FileUnit::deg, "rad", Domain::any(), "end-effector orientation at the start",
                          [](auto& r) -> auto& { return r.options.alpha1A; }));
  t.push_back(real<Run>("K_N", FileUnit::none, "1/s", TrajectoryOptions::null_damping_rule, "null-space damping",
                        [](auto& r) -> auto& { return r.options.null_damping; }, kLocalOnly));
  for (std::size_t v = 2; robot.vertex_alpha() && v <= ctx.path_vertices; ++v) {
    const std::size_t i = v - 2;
    t.push_back(real<Run>("vertex_alpha_" + std::to_string(v), FileUnit::deg, "rad", Domain::any(),
                          "orientation at vertex " + std::to_string(v) + " (vertex_alpha method)",
                          [i](auto& r) -> auto& { return r.options.vertex_alpha[i]; }, kVertexOnly));
  }
  t.push_back(named<Run>("integrator", names_of<Integrator>(Integrator::semi_implicit_euler, Integrator::rk4),
                         "time integrator", [](auto& r) -> auto& { return r.options.integrator; }));
  t.push_back(real<Run>("dt", FileUnit::none, "s", TrajectoryOptions::dt_rule, "sample / integration step",
                        [](auto& r) -> auto& { return r.options.dt; }));
  t.push_back(real<Run>("torque_bound", FileUnit::none, "Nm", TrajectoryOptions::torque_bound_rule,
                        "|tau_i| above this stops the run (diverged)",
                        [](auto& r) -> auto& { return r.options.torque_bound; }));
  if (!robot.chain)
    t.push_back(named<Run>("inertia", names_of<InertiaForm>(InertiaForm::physical, InertiaForm::thesis_m11),
                           "closed form of M(q)", [](auto& r) -> auto& { return r.inertia; }));
  for (int j = 0; robot.chain && j < robot.joints; ++j) {
    const bool prismatic = robot.is_prismatic(j);
    t.push_back(real<Run>("q0_" + std::to_string(j + 1), prismatic ? FileUnit::none : FileUnit::deg,
                          prismatic ? "m" : "rad", Domain::any(),
                          "initial guess of the start configuration, joint " + std::to_string(j + 1) +
                              " (placed on the first vertex by an IK solve)",
                          [j](auto& r) -> auto& { return r.q0[j]; }));
  }
  return t;
}

std::vector<MetricDef> trajectory_metrics(const KindContext& ctx) {
  using M = TrajectoryMetrics;
  std::vector<MetricDef> m{
      metric<M>("E", CellType::f64, "Nm", "mean over samples of sqrt(tau^T tau) (seed Eq. 60)", true,
                [](const M& r) { return r.E; }),
      metric<M>("E_M", CellType::f64, "Nm/sqrt(kg m^2)", "mean over samples of sqrt(tau^T M^-1 tau)", true,
                [](const M& r) { return r.E_M; }),
      metric<M>("tau_inf", CellType::f64, "Nm", "max over samples and joints of |tau_i|", true,
                [](const M& r) { return r.tau_inf.maxCoeff(); }),
      metric<M>("min_manipulability", CellType::f64, "m^2", "min over samples of sqrt(det(J J^T))", true,
                [](const M& r) { return r.min_manipulability; }),
      metric<M>("torque_sq_integral", CellType::f64, "N^2 m^2 s",
                "trapezoidal integral of sum tau_i^2 (seed 002 f5)", false,
                [](const M& r) { return r.torque_sq_integral; }),
      metric<M>("power_sq_integral", CellType::f64, "W^2 s", "trapezoidal integral of sum (tau_i qd_i)^2 (seed 002 f6)",
                false, [](const M& r) { return r.power_sq_integral; }),
      metric<M>("max_tracking_error", CellType::f64, "m", "max over samples of |tip - path| (open-loop drift)", true,
                [](const M& r) { return r.max_tracking_error; }),
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
                               }));
  }
  m.insert(m.begin() + 3, joints.begin(), joints.end());
  return m;
}

}  // namespace ks
