// The parameter and metric tables (engine/schema): a walk over every declared parameter through the
// study parser (accepted with its file unit, stored in its unit, its domain and choices enforced, an
// axis refused where its effect rule says it does nothing), the accessors against the typed fields
// they name, IsValid naming the field and the rule, and the metrics against a run's outcome.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "runner/execute.hpp"
#include "runner/schema.hpp"
#include "schema/params.hpp"
#include "study/study.hpp"

using namespace ks;

namespace {

struct Family {
  BlockKind kind;
  bool scara;
  std::string base;     // the block table's first three lines
  std::string problem;  // the line that selects the family ("" for the defaults)
  std::string header;   // base + problem
};
std::vector<Family> families() {
  const std::string t = "[[block]]\nname = \"b\"\nkind = \"trajectory\"\n", i = "[[block]]\nname = \"b\"\nkind = \"ik\"\n",
                    planar = "problem = \"planar3r_pose\"\n";
  return {{BlockKind::trajectory, true, t, "", t}, {BlockKind::ik, true, i, "", i},
          {BlockKind::ik, false, i, planar, i + planar}};
}
KindContext context_of(const Family& f) {
  KindContext c;
  c.scara = f.scara;
  return c;
}

/// A value inside the parameter's domain, as the study file writes it (TOML text) and as a double.
std::pair<std::string, double> inside(const ParamDef& p, const Family& f) {
  if (p.type == CellType::str) {
    if (p.name == "problem") return {f.scara ? "\"scara\"" : "\"planar3r_position\"", 0};
    return {"\"" + p.choices.back() + "\"", 0};
  }
  switch (p.domain.rule) {
    case Domain::Rule::positive: return {"0.03125", 0.03125};  // a dt that samples each 0.5 s segment 16 times
    case Domain::Rule::nonnegative: return {"0.25", 0.25};
    case Domain::Rule::at_least:
    case Domain::Rule::within: return {"7", 7.0};
    case Domain::Rule::any: break;
  }
  return {"0.375", 0.375};
}
/// A value outside the domain (none for `any`).
std::string outside(const ParamDef& p) {
  switch (p.domain.rule) {
    case Domain::Rule::positive: return "0";
    case Domain::Rule::nonnegative: return "-0.5";
    case Domain::Rule::at_least:
    case Domain::Rule::within: return std::to_string(static_cast<long long>(p.domain.bound) - 1);
    case Domain::Rule::any: break;
  }
  return "";
}

/// The units the study files and results had before the tables existed (file unit / stored unit):
/// an oracle written out by hand, so a wrongly declared table entry fails the walk.
std::string expected_units(const Family& f, const std::string& name) {
  if (f.kind == BlockKind::trajectory) {
    if (name == "alpha1A" || name.starts_with("vertex_alpha_")) return "deg/rad";
    if (name == "K_N") return "1/s";
    if (name == "dt") return "s";
    if (name == "torque_bound") return "Nm";
    if (name == "K_P" || name == "K_L") return "1/s^2";
    if (name == "K_D") return "1/s";
    if (name == "tracking_bound") return "m";
    if (name == "orientation_bound") return "deg/rad";
    if (name == "end_window") return "s";
    if (name == "end_gain") return "1/s";
    return "";
  }
  if (name == "q0_1" || name == "q0_2" || name == "target_alpha") return "deg/rad";
  if (name == "q0_3") return f.scara ? "mm" : "deg/rad";
  if (name.starts_with("target_")) return f.scara ? "mm" : "m";
  if (name == "tol") return f.scara ? "mm" : "";
  return "";
}

std::string error_text(const std::string& text) {
  try {
    parse_study(text, "walk.toml");
  } catch (const StudyError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SchemaWalk, EveryParameterIsAcceptedWithItsUnitAndDomain) {
  for (const Family& f : families()) {
    for (const ParamDef& p : params(f.kind, context_of(f))) {
      if (!f.scara && p.name == "problem") continue;  // fixed by the planar header
      SCOPED_TRACE(std::string(to_string(f.kind)) + (f.scara ? "" : " planar") + ": " + p.name);
      const auto [text, value] = inside(p, f);
      const Study s = parse_study(f.header + p.name + " = " + text + "\n", "walk.toml");
      const Block& b = s.blocks.at(0);
      const std::size_t c = b.column_index(p.name);
      ASSERT_NE(c, Block::npos);
      EXPECT_EQ(b.columns()[c].unit, p.unit);
      const std::string units = expected_units(f, p.name);
      EXPECT_EQ(p.file_unit == FileUnit::deg ? "deg/" + p.unit : p.unit, units);
      EXPECT_EQ(b.columns()[c].role, Role::parameter);
      EXPECT_EQ(b.columns()[c].kinds, std::string(to_string(f.kind)));
      const Cell stored = b.params(0)[c];
      if (p.type == CellType::str) {
        EXPECT_EQ(std::get<std::string>(stored), text.substr(1, text.size() - 2));
      } else if (p.type == CellType::i64) {
        EXPECT_EQ(std::get<std::int64_t>(stored), static_cast<std::int64_t>(value));
      } else {
        const double expect = p.file_unit == FileUnit::deg ? value * std::numbers::pi / 180.0 : value;
        EXPECT_DOUBLE_EQ(std::get<double>(stored), expect);
        EXPECT_EQ(p.file_unit == FileUnit::deg, p.unit == "rad");
      }
      // The same value as a one-value axis decodes to the same cell (with a controller value under
      // which the parameter has an effect: an axis without effect is refused, see below).
      std::string ctl;
      bool axis_ok = true;
      if (!p.effect.always()) {
        const std::string& w = p.effect.when.front();
        if (p.effect.controller == "problem") axis_ok = (w == "scara") == f.scara && (f.scara || w == "planar3r_pose");
        else ctl = p.effect.controller + " = \"" + w + "\"\n";
      }
      if (axis_ok) {
        const Study sa = parse_study(f.header + ctl + "[block.axes]\n" + p.name + " = [" + text + "]\n", "walk.toml");
        EXPECT_EQ(sa.blocks.at(0).params(0)[c], stored);
      }
      // Outside the domain: refused at the value, naming the rule.
      if (const std::string bad = outside(p); !bad.empty()) {
        const std::string e = error_text(f.header + p.name + " = " + bad + "\n");
        EXPECT_NE(e.find("walk.toml:" + std::to_string(4 + !f.scara) + ":"), std::string::npos) << e;
        EXPECT_NE(e.find("expected " + p.domain.str(p.name)), std::string::npos) << e;
      }
      if (!p.choices.empty()) {
        const std::string e = error_text(f.header + p.name + " = \"no_such_" + p.name + "\"\n");
        EXPECT_NE(e.find("expected one of"), std::string::npos) << e;
      }
    }
  }
}

TEST(SchemaWalk, AnAxisWithoutEffectIsRefusedWhereTheRuleSays) {
  for (const Family& f : families()) {
    const auto table = params(f.kind, context_of(f));
    for (const ParamDef& p : table) {
      if (p.effect.always()) continue;
      const ParamDef* ctl = find_param(table, p.effect.controller);
      ASSERT_NE(ctl, nullptr) << p.name;
      for (const std::string& v : ctl->choices) {
        if (!f.scara && p.effect.controller == "problem" && v == "scara") continue;  // another family
        if (f.scara && p.effect.controller == "problem" && v != "scara") continue;
        SCOPED_TRACE(p.name + " with " + ctl->name + " = " + v);
        const auto [text, value] = inside(p, f);
        const std::string head = (ctl->name == "problem" ? f.base : f.header) + ctl->name + " = \"" + v + "\"\n";
        const std::string study = head + "[block.axes]\n" + p.name + " = [" + text + ", " + text + "]\n";
        const std::string e = error_text(study);
        if (p.effect.applies(v)) EXPECT_EQ(e.find("has no effect"), std::string::npos) << e;
        else EXPECT_NE(e.find("has no effect"), std::string::npos) << study;
      }
    }
  }
}

TEST(SchemaAccessors, NameTheTypedFields) {
  const Study s = parse_study(
      "[[block]]\nname = \"t\"\nkind = \"trajectory\"\nk = 0.25\nK_N = 2\ndt = 0.002\ntorque_bound = 50\n"
      "alpha1A = 90\nmethod = \"local_unweighted\"\nintegrator = \"rk4\"\ninertia = \"thesis_m11\"\n"
      "[[block]]\nname = \"i\"\nkind = \"ik\"\nlambda = 3\ntol = 0.5\nmax_iter = 9\nq0_3 = 7\ntarget_z = 4\n"
      "method = \"lm\"\nz_mode = \"physical\"\n",
      "fields.toml");
  const auto t = std::get<TrajectoryRun>(s.blocks[0].run(0));
  EXPECT_EQ(t.options.k, 0.25);
  EXPECT_EQ(t.options.null_damping, 2.0);
  EXPECT_EQ(t.options.dt, 0.002);
  EXPECT_EQ(t.options.torque_bound, 50.0);
  EXPECT_DOUBLE_EQ(t.options.alpha1A, std::numbers::pi / 2);
  EXPECT_EQ(t.options.method, TrajectoryMethod::local_unweighted);
  EXPECT_EQ(t.options.integrator, Integrator::rk4);
  EXPECT_EQ(t.inertia, InertiaForm::thesis_m11);
  const auto i = std::get<IkRun>(s.blocks[1].run(0));
  EXPECT_EQ(i.options.lambda, 3.0);
  EXPECT_EQ(i.options.tolerance, 0.5);
  EXPECT_EQ(i.options.max_iter, 9);
  EXPECT_EQ(i.q0[2], 7.0);  // the SCARA's d [mm]
  EXPECT_EQ(i.target[2], 4.0);
  EXPECT_EQ(i.options.method, ik::Method::lm);
  EXPECT_EQ(i.z_mode, ZMode::physical);
}

TEST(SchemaDefaults, OmittedKeysTakeTheSeedsDefaults) {
  // Seed 000's runs (Table 4 row 1a's settings) and seed 001's SCARA problem; the planar 3R IK problem
  // of the basin studies. Literal values: what the study files have always meant by an omitted key.
  const Study s = parse_study("[[block]]\nname = \"t\"\nkind = \"trajectory\"\n[[block]]\nname = \"i\"\nkind = \"ik\"\n",
                              "defaults.toml");
  const Study planar =
      parse_study("[[block]]\nname = \"p\"\nkind = \"ik\"\nproblem = \"planar3r_pose\"\n", "planar.toml");
  const auto t = std::get<TrajectoryRun>(s.blocks[0].run(0));
  EXPECT_EQ(t.preset, "");
  EXPECT_EQ(t.options.method, TrajectoryMethod::local_weighted);
  EXPECT_EQ(t.options.k, 0.0);
  EXPECT_EQ(t.options.alpha1A, 0.0);
  EXPECT_EQ(t.options.null_damping, 0.0);
  EXPECT_EQ(t.options.vertex_alpha, std::vector<double>(4, 0.0));
  EXPECT_EQ(t.options.integrator, Integrator::semi_implicit_euler);
  EXPECT_EQ(t.options.dt, 1e-3);
  EXPECT_EQ(t.options.torque_bound, 1e6);
  EXPECT_EQ(t.inertia, InertiaForm::physical);
  const double deg = std::numbers::pi / 180.0;
  const auto i = std::get<IkRun>(s.blocks[1].run(0));
  EXPECT_EQ(i.problem, IkProblem::scara);
  EXPECT_EQ(i.options.method, ik::Method::newton);
  EXPECT_EQ(i.options.lambda, 0.1);
  EXPECT_EQ(i.options.tolerance, 1e-6);  // mm
  EXPECT_EQ(i.options.max_iter, 1000);
  EXPECT_EQ(i.q0, Eigen::Vector3d(60 * deg, 45 * deg, 50.0));
  EXPECT_EQ(i.target, Eigen::Vector3d(50.0, -80.0, 10.0));  // mm
  EXPECT_TRUE(std::isnan(i.target_alpha));
  EXPECT_EQ(i.z_mode, ZMode::thesis);
  const auto p = std::get<IkRun>(planar.blocks[0].run(0));
  EXPECT_EQ(p.q0, Eigen::Vector3d(0.0, 90 * deg, -90 * deg));
  EXPECT_EQ(p.target.head<2>(), Eigen::Vector2d(1.5, 1.5));  // m
  EXPECT_TRUE(std::isnan(p.target[2]));
  EXPECT_EQ(p.target_alpha, 0.0);
  EXPECT_EQ(p.z_mode, ZMode::unset);
  EXPECT_EQ(p.options.max_iter, 1000);
}

TEST(OptionsIsValid, NamesTheFieldAndTheRule) {
  std::string why;
  TrajectoryOptions t;
  EXPECT_TRUE(t.IsValid(&why)) << why;
  t.dt = -1e-3;
  EXPECT_FALSE(t.IsValid(&why));
  EXPECT_EQ(why, "dt = -0.001; expected dt > 0");
  t = {};
  t.null_damping = -1;
  EXPECT_FALSE(t.IsValid(&why));
  EXPECT_EQ(why, "null_damping = -1; expected null_damping >= 0");
  t = {};
  t.k = std::nan("");
  EXPECT_FALSE(t.IsValid(&why));
  EXPECT_NE(why.find("k is not finite"), std::string::npos);
  ik::Options o;
  EXPECT_TRUE(o.IsValid(&why)) << why;
  o.max_iter = 0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why, "max_iter = 0; expected max_iter within [1, 1000000000]");
  o = {};
  o.cycle_window = 17;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("cycle_window = 17"), std::string::npos);
}

TEST(SchemaMetrics, ReadTheOutcomeOfARun) {
  const Study s = parse_study("[[block]]\nname = \"t\"\nkind = \"trajectory\"\npreset = \"1a\"\n", "m.toml");
  RunWorkspace ws;
  const RunSpec run = s.blocks[0].run(0);
  const RunOutcome o = execute(Scenario::of(s), run, 0, ws);
  const auto& m = std::get<TrajectoryMetrics>(o.result);
  EXPECT_TRUE(o.good());
  EXPECT_EQ(o.status(), "ok");
  const StudySchema schema = make_schema(s);
  const Record row = schema.row(0, 0, s.blocks[0], run, o, 0.0);
  auto cell = [&](const std::string& n) {
    for (std::size_t i = 0; i < schema.columns.size(); ++i)
      if (schema.columns[i].name == n) return row.cells[i];
    ADD_FAILURE() << n;
    return Cell();
  };
  EXPECT_EQ(std::get<double>(cell("E")), m.E);
  EXPECT_EQ(std::get<double>(cell("tau2_inf")), m.tau_inf[1]);
  EXPECT_EQ(std::get<double>(cell("tau_inf")), m.tau_inf.maxCoeff());
  EXPECT_EQ(std::get<std::int64_t>(cell("samples")), 2001);  // the seed's square at 1 ms
  EXPECT_EQ(std::get<std::string>(cell("status")), "ok");
  EXPECT_EQ(std::get<std::string>(cell("preset")), "1a");
  for (const ColumnSpec& c : schema.columns) {
    const bool bookkeeping = c.name == "run_id" || c.name == "block" || c.name == "status" || c.name == "wall_time";
    EXPECT_EQ(c.role == Role::bookkeeping, bookkeeping) << c.name;
  }
  // seed 000 Table 4, row 1a (thesis' printed E = 50.89 Nm with the thesis inertia; physical: within 0.4 %)
  EXPECT_NEAR(m.E, 50.89, 0.004 * 50.89);
}
