// The motion kind's parameters and metrics (see schema/params.hpp): one rest-to-rest point-to-point
// motion of a chain robot per run (motion/solve_motion.hpp).
#include "common/name_table.hpp"
#include "schema/kind_tables.hpp"
#include "schema/table_builders.hpp"

namespace ks {

using namespace schema_detail;
using Run = MotionRun;

namespace {
constexpr NameTable<MotionStatus, 5> kMotionStatuses{{{MotionStatus::ok, "ok"},
                                                      {MotionStatus::infeasible, "infeasible"},
                                                      {MotionStatus::collision, "collision"},
                                                      {MotionStatus::max_evaluations, "max_evaluations"},
                                                      {MotionStatus::failure, "failure"}}};

/// A yes/no parameter stored as the text "true" or "false" (a study file writes a TOML boolean or
/// that text), its value the bool `field(run)`.
template <class Field>
ParamDef flag(std::string name, std::string description, Field field, EffectRule effect = {}) {
  ParamDef p;
  p.name = std::move(name);
  p.type = CellType::str;
  p.choices = {"false", "true"};
  p.description = std::move(description);
  p.effect = std::move(effect);
  p.get = [field](const RunSpec& r) { return Cell(std::string(field(std::get<Run>(r)) ? "true" : "false")); };
  p.set = [field, name = p.name](RunSpec& r, const Cell& c) {
    const std::string& v = std::get<std::string>(c);
    if (v != "true" && v != "false") throw std::invalid_argument("unknown " + name + " '" + v + "'");
    field(std::get<Run>(r)) = v == "true";
  };
  return p;
}
}  // namespace

std::string_view to_string(MotionStatus s) { return name_of(kMotionStatuses, s); }

MotionRun MotionRun::defaults(const std::vector<bool>& prismatic, int joints) {
  MotionRun r;
  r.start = VecN::Zero(joints);
  r.goal = VecN::Zero(joints);
  for (int j = 0; j < joints; ++j) r.goal[j] = j < int(prismatic.size()) && prismatic[j] ? 0.0 : 30.0 * kDeg;
  return r;
}

std::vector<ParamDef> motion_params(const KindContext& ctx) {
  const RobotShape& robot = ctx.robot;
  std::vector<ParamDef> t;
  for (const char* end : {"start", "goal"})
    for (int j = 0; j < robot.joints; ++j) {
      const std::string i = std::to_string(j + 1);
      const bool m = robot.is_prismatic(j), start = std::string(end) == "start";
      t.push_back(real<Run>(std::string(end) + "_" + i, m ? FileUnit::none : FileUnit::deg, m ? "m" : "rad",
                            Domain::any(), std::string(start ? "start" : "goal") + " of joint " + i + " (at rest)",
                            [j, start](auto& r) -> auto& { return start ? r.start[j] : r.goal[j]; }));
    }
  t.push_back(real<Run>("duration", FileUnit::none, "s", Domain::positive(),
                        "duration T of the motion (the start value when vary_duration)",
                        [](auto& r) -> auto& { return r.duration; }));
  t.push_back(flag("vary_duration", "T is a variable of the solve, within [min_duration, max_duration]",
                   [](auto& r) -> auto& { return r.vary_duration; }));
  const EffectRule varied{"vary_duration", {"true"}};
  t.push_back(real<Run>("min_duration", FileUnit::none, "s", Domain::positive(), "least T (vary_duration)",
                        [](auto& r) -> auto& { return r.min_duration; }, varied));
  t.push_back(real<Run>("max_duration", FileUnit::none, "s", Domain::positive(), "largest T (vary_duration)",
                        [](auto& r) -> auto& { return r.max_duration; }, varied));
  t.push_back(integer<Run>("controls", "", MotionRun::controls_rule,
                           "K control values per joint (spline nodes between start and goal; 0: the cubic)",
                           [](auto& r) -> auto& { return r.controls; }));
  t.push_back(integer<Run>("samples", "", MotionRun::samples_rule,
                           "least number of samples in time (raised so that every spline node is one)",
                           [](auto& r) -> auto& { return r.samples; }));
  const auto weight = [&](const char* name, std::string what, auto field) {
    t.push_back(real<Run>(name, FileUnit::none, "", Domain::nonnegative(), "objective weight of " + what, field));
  };
  weight("w_torque", "f5 = torque_sq_integral", [](auto& r) -> auto& { return r.w_torque; });
  weight("w_power", "f6 = power_sq_integral", [](auto& r) -> auto& { return r.w_power; });
  weight("w_time", "the duration T", [](auto& r) -> auto& { return r.w_time; });
  weight("w_peak", "peak_torque", [](auto& r) -> auto& { return r.w_peak; });
  weight("w_jerk", "jerk_sq_integral", [](auto& r) -> auto& { return r.w_jerk; });
  weight("w_manipulability", "min_manipulability (raised: the term is subtracted)",
         [](auto& r) -> auto& { return r.w_manipulability; });
  weight("w_clearance", "min_clearance (raised: the term is subtracted; needs [world] obstacles)",
         [](auto& r) -> auto& { return r.w_clearance; });
  t.push_back(flag("normalise", "divide each weighted term by the initial cubic's value (seed 002 Eq. 7.1)",
                   [](auto& r) -> auto& { return r.normalise; }));
  t.push_back(flag("solve", "minimise the objective (false: evaluate the initial rest-to-rest cubic only)",
                   [](auto& r) -> auto& { return r.solve; }));
  const EffectRule solving{"solve", {"true"}};
  t.push_back(integer<Run>("starts", "", MotionRun::starts_rule,
                           "SLSQP starts: the cubic, then seeded perturbations of it (the best feasible end wins)",
                           [](auto& r) -> auto& { return r.starts; }, solving));
  t.push_back(integer<Run>("max_evaluations", "", MotionRun::evaluations_rule, "SLSQP evaluations per start",
                           [](auto& r) -> auto& { return r.max_evaluations; }, solving));
  t.push_back(real<Run>("clearance_margin", FileUnit::none, "m", Domain::nonnegative(),
                        "the links keep at least this clearance from the obstacles (a constraint; with obstacles)",
                        [](auto& r) -> auto& { return r.clearance_margin; }));
  t.push_back(real<Run>("limit_margin", FileUnit::none, "", Domain::within(0.0, 0.99),
                        "each limited ratio (position from mid-range over half the range, |velocity|, |torque| "
                        "over its limit) is kept <= 1 - limit_margin at the samples (room for the dense check)",
                        [](auto& r) -> auto& { return r.limit_margin; }));
  t.push_back(integer<Run>("check_factor", "", MotionRun::check_factor_rule,
                           "the end is checked at check_factor times as many samples (limits, clearance, f5, f6)",
                           [](auto& r) -> auto& { return r.check_factor; }));
  return t;
}

std::vector<MetricDef> motion_metrics(const KindContext& ctx) {
  using R = MotionResult;
  const auto f = [](std::string name, std::string unit, std::string what, auto get) {
    return metric<R>(std::move(name), CellType::f64, std::move(unit), std::move(what), true, get);
  };
  return {
      f("final_duration", "s", "duration T of the motion at the end (the duration parameter unless vary_duration)",
        [](const R& r) { return r.duration; }),
      f("torque_sq_integral", "N^2 m^2 s", "f5: integral of the sum of squared joint torques (trapezoidal rule)",
        [](const R& r) { return r.torque_sq; })
          .labelled("f5 (∫Στ² dt)"),
      f("power_sq_integral", "W^2 s", "f6: integral of the sum of squared joint powers tau_i qd_i (trapezoidal rule)",
        [](const R& r) { return r.power_sq; })
          .labelled("f6 (∫Σ(τq̇)² dt)"),
      f("peak_torque", "Nm", "largest |tau_i| over the samples and joints (N for prismatic joints)",
        [](const R& r) { return r.peak_torque; }),
      f("jerk_sq_integral", "rad^2/s^5", "integral of the sum of squared joint jerks (exact per spline segment)",
        [](const R& r) { return r.jerk_sq; }),
      f("min_manipulability", ctx.robot.planar ? "m^2" : "m^3",
        "least sqrt(det(J_p J_p^T)) over the samples (J_p: the tip's position rows)",
        [](const R& r) { return r.min_manipulability; }),
      f("min_clearance", "m", "least clearance of the link capsules from the [world] obstacles (NaN: no obstacles)",
        [](const R& r) { return r.min_clearance; }),
      f("torque_sq_integral_0", "N^2 m^2 s", "f5 of the initial rest-to-rest cubic (the normalisation's reference)",
        [](const R& r) { return r.torque_sq_0; }),
      f("power_sq_integral_0", "W^2 s", "f6 of the initial rest-to-rest cubic (the normalisation's reference)",
        [](const R& r) { return r.power_sq_0; }),
      f("objective", "", "the weighted (normalised) objective at the end", [](const R& r) { return r.objective; }),
      metric<R>("evaluations", CellType::i64, "", "objective evaluations over every start (0 without solve)", true,
                [](const R& r) { return std::int64_t(r.evaluations); }),
      f("max_constraint", "", "largest constraint value at the end (<= 0: every limit and margin kept)",
        [](const R& r) { return r.max_constraint; }),
      metric<R>("check_samples", CellType::i64, "", "samples of the dense check of the end (check_factor times denser)",
                true, [](const R& r) { return std::int64_t(r.check_samples); }),
      f("check_min_clearance", "m", "least clearance at the dense check samples (NaN: no obstacles; < 0: collision)",
        [](const R& r) { return r.check_min_clearance; }),
      f("check_max_limit", "", "largest limited ratio minus 1 at the dense check samples (<= 0: every limit kept)",
        [](const R& r) { return r.check_max_limit; }),
      f("check_torque_sq_change", "", "relative change of f5 from the samples to the dense check samples",
        [](const R& r) { return r.check_torque_sq_change; }),
      f("check_power_sq_change", "", "relative change of f6 from the samples to the dense check samples",
        [](const R& r) { return r.check_power_sq_change; }),
  };
}

}  // namespace ks
