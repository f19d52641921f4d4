// The IK kind's parameters and metrics (see schema/params.hpp).
#include "schema/kind_tables.hpp"
#include "schema/table_builders.hpp"

namespace ks {

using namespace schema_detail;
using Run = IkRun;

IkRun IkRun::planar_defaults() {
  IkRun r;
  r.problem = IkProblem::planar3r_pose;
  r.q0 = {0.0, 90.0 * kDeg, -90.0 * kDeg};
  r.target = {1.5, 1.5, std::numeric_limits<double>::quiet_NaN()};
  r.target_alpha = 0.0;
  r.z_mode = ZMode::unset;
  return r;
}

std::vector<ParamDef> ik_params(const KindContext& ctx) {
  using ik::Method;
  const std::string len = ctx.scara ? "mm" : "m";
  const FileUnit q3_file = ctx.scara ? FileUnit::none : FileUnit::deg;
  std::vector<std::string> iterative;  // every method but analytic: the start matters
  for (Method m : {Method::newton, Method::lm, Method::lm_adaptive, Method::halley_thesis, Method::halley})
    iterative.emplace_back(ik::to_string(m));
  const EffectRule from_start{"method", iterative};
  std::vector<ParamDef> t;
  t.push_back(named<Run>("problem", names_of<IkProblem>(IkProblem::scara, IkProblem::planar3r_pose,
                                                         IkProblem::planar3r_position),
                         "IK problem", [](auto& r) -> auto& { return r.problem; }));
  t.push_back(named<Run>("method",
                         names_of<Method>(Method::newton, Method::lm, Method::lm_adaptive, Method::halley_thesis,
                                          Method::halley, Method::analytic),
                         "IK method", [](auto& r) -> auto& { return r.options.method; }));
  t.push_back(real<Run>("lambda", FileUnit::none, "", ik::Options::lambda_rule,
                        "Levenberg-Marquardt damping (lm, lm_adaptive)", [](auto& r) -> auto& { return r.options.lambda; },
                        EffectRule{"method", {"lm", "lm_adaptive"}}));
  t.push_back(real<Run>("q0_1", FileUnit::deg, "rad", Domain::any(), "initial guess, joint 1",
                        [](auto& r) -> auto& { return r.q0[0]; }, from_start));
  t.push_back(real<Run>("q0_2", FileUnit::deg, "rad", Domain::any(), "initial guess, joint 2",
                        [](auto& r) -> auto& { return r.q0[1]; }, from_start));
  t.push_back(real<Run>("q0_3", q3_file, ctx.scara ? "mm" : "rad", Domain::any(),
                        "initial guess, joint 3 (SCARA: prismatic d)", [](auto& r) -> auto& { return r.q0[2]; },
                        from_start));
  t.push_back(real<Run>("target_x", FileUnit::none, len, Domain::any(), "target x",
                        [](auto& r) -> auto& { return r.target[0]; }));
  t.push_back(real<Run>("target_y", FileUnit::none, len, Domain::any(), "target y",
                        [](auto& r) -> auto& { return r.target[1]; }));
  t.push_back(real<Run>("target_z", FileUnit::none, len, Domain::any(), "target z (SCARA)",
                        [](auto& r) -> auto& { return r.target[2]; }, EffectRule{"problem", {"scara"}}));
  t.push_back(real<Run>("target_alpha", FileUnit::deg, "rad", Domain::any(), "target orientation (planar3r_pose)",
                        [](auto& r) -> auto& { return r.target_alpha; }, EffectRule{"problem", {"planar3r_pose"}}));
  t.push_back(real<Run>("tol", FileUnit::none, ctx.scara ? "mm" : "", ik::Options::tolerance_rule,
                        "stop when the residual norm falls below this",
                        [](auto& r) -> auto& { return r.options.tolerance; }));
  t.push_back(integer<Run>("max_iter", "", ik::Options::max_iter_rule, "iteration cap",
                           [](auto& r) -> auto& { return r.options.max_iter; }));
  t.push_back(named<Run>("z_mode", names_of<ZMode>(ZMode::thesis, ZMode::physical),
                         "SCARA z residual: thesis (+q3) or physical", [](auto& r) -> auto& { return r.z_mode; },
                         EffectRule{"problem", {"scara"}}));
  return t;
}

const std::vector<MetricDef>& ik_metrics() {
  using R = IkResult;
  static const std::vector<MetricDef> m{
      metric<R>("iterations", CellType::i64, "", "updates made (the seed's count)", true,
                [](const R& r) { return std::int64_t(r.iterations); }),
      metric<R>("error", CellType::f64, "problem units", "||F|| at the final iterate (mm for scara, m/rad for planar3r)",
                true, [](const R& r) { return r.error; }),
      metric<R>("solution", CellType::i64, "", "index of the known exact solution reached (mod 2 pi), -1 if none",
                true, [](const R& r) { return std::int64_t(r.solution); }),
      metric<R>("rejected", CellType::i64, "", "lm_adaptive: rejected trial steps", false,
                [](const R& r) { return std::int64_t(r.rejected); }),
      metric<R>("min_rcond", CellType::f64, "", "smallest reciprocal condition number met", false,
                [](const R& r) { return r.min_rcond; }),
      metric<R>("q_final_1", CellType::f64, "rad", "final iterate, joint 1", false, [](const R& r) { return r.q[0]; }),
      metric<R>("q_final_2", CellType::f64, "rad", "final iterate, joint 2", false, [](const R& r) { return r.q[1]; }),
      metric<R>("q_final_3", CellType::f64, "rad or mm", "final iterate, joint 3 (scara: d in mm)", false,
                [](const R& r) { return r.q[2]; }),
  };
  return m;
}

}  // namespace ks
