#include "cli/schema_command.hpp"

#include <cstdio>
#include <iostream>
#include <set>

#include "schema/params.hpp"

namespace ks::cli {

namespace {

/// v with `digits` significant digits (12 for reading, 17 to round-trip a double).
std::string num(double v, int digits = 12) {
  char b[40];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}
/// `s` in a markdown table cell.
std::string cell(std::string_view s) {
  std::string o;
  for (char c : s) o += c == '|' ? std::string("\\|") : std::string(1, c);
  return o;
}
std::string type_name(CellType t) { return t == CellType::f64 ? "f64" : t == CellType::i64 ? "i64" : "str"; }

/// A parameter's value in run `r`, as the study file writes it (angles in degrees).
std::string file_value(const ParamDef& p, const RunSpec& r) {
  const Cell c = p.get(r);
  if (const double* d = std::get_if<double>(&c)) return num(p.file_unit == FileUnit::deg ? *d / kDeg : *d);
  if (const std::int64_t* i = std::get_if<std::int64_t>(&c)) return std::to_string(*i);
  return "\"" + std::get<std::string>(c) + "\"";
}

std::string json_str(std::string_view s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    o += c;
  }
  return o + "\"";
}

/// The contexts a kind's table is listed for: trajectory on the seed's square; ik for the SCARA and
/// for the planar 3R problems (their units and defaults differ).
struct Listed {
  BlockKind kind;
  std::string family;
  KindContext context;
};
std::vector<Listed> listed() {
  KindContext planar;
  planar.scara = false;
  KindContext planar4;  // an n-link planar arm (here n = 4): q0_<i> and the per-joint metrics, one per joint
  planar4.robot.chain = true;
  planar4.robot.joints = 4;
  planar4.scara = false;
  planar4.path_global = true;  // global_spline's columns (planar revolute chains on a position path)
  planar4.placement = true;    // the task placement's columns (blocks that place their task)
  KindContext spatial7 = planar4;  // a spatial URDF chain (here 7 revolute joints)
  spatial7.robot.joints = 7;
  spatial7.robot.planar = false;
  spatial7.first_vertex = {0.5, 0.0, 0.5};
  KindContext arm3 = spatial7;  // a spatial arm of 3 revolute joints (motion runs: chain robots only)
  arm3.robot.joints = 3;
  arm3.path_global = arm3.placement = false;
  KindContext seed;  // the seed's 3R, with the columns of global_spline (present in blocks that run it)
  seed.path_global = true;
  seed.placement = true;
  return {{BlockKind::trajectory, "", seed},
          {BlockKind::ik, "scara", {}},
          {BlockKind::ik, "planar3r", planar},
          {BlockKind::trajectory, "chain_planar", planar4},
          {BlockKind::ik, "chain_planar", planar4},
          {BlockKind::trajectory, "chain_spatial", spatial7},
          {BlockKind::ik, "chain_spatial", spatial7},
          {BlockKind::motion, "chain_spatial", arm3}};
}
bool is_chain(const Listed& l) { return l.context.robot.chain; }

}  // namespace

void print_schema_markdown(std::ostream& os) {
  const auto all = listed();
  for (BlockKind kind : block_kinds()) {
    os << "Parameters of `" << to_string(kind) << "` runs (units: in the study file / as stored";
    if (kind == BlockKind::ik) os << "; where they differ, planar3r problems after the semicolon";
    os << ")";
    if (kind == BlockKind::trajectory) os << "; one `vertex_alpha_<i>` per path vertex after the first (the square: 2 .. 5)";
    if (kind == BlockKind::motion)
      os << "; chain robots only, one `start_<i>` and `goal_<i>` per joint (here a 3-joint arm), deg for revolute "
            "joints, m for prismatic ones";
    os << ":\n\n| column | type | unit | domain | default | has an effect | description |\n"
          "|---|---|---|---|---|---|---|\n";
    std::vector<const Listed*> ctx;
    for (const Listed& l : all)
      if (l.kind == kind && !is_chain(l)) ctx.push_back(&l);
    const bool chain_only = ctx.empty();  // motion runs: chain robots only (here a 3-joint spatial arm)
    for (const Listed& l : all)
      if (chain_only && l.kind == kind && ctx.empty()) ctx.push_back(&l);
    std::vector<std::vector<ParamDef>> tables;
    std::vector<RunSpec> defaults;
    for (const Listed* l : ctx) {
      tables.push_back(params(kind, l->context));
      defaults.push_back(default_run(kind, l->context));
    }
    for (std::size_t i = 0; i < tables[0].size(); ++i) {
      auto joined = [&](auto f) {
        std::string s = f(tables[0][i], defaults[0]);
        for (std::size_t c = 1; c < tables.size(); ++c)
          if (const std::string o = f(tables[c][i], defaults[c]); o != s) s += "; " + o;
        return s;
      };
      const ParamDef& p = tables[0][i];
      const std::string unit = joined([](const ParamDef& q, const RunSpec&) {
        return q.file_unit_name() == q.unit ? (q.unit.empty() ? "-" : q.unit) : q.file_unit_name() + " / " + q.unit;
      });
      std::string domain = p.domain.str(p.name);
      if (!p.choices.empty()) {
        domain = "one of";
        for (const auto& c : p.choices) domain += " `" + c + "`";
      }
      const std::string dflt = joined([](const ParamDef& q, const RunSpec& r) { return file_value(q, r); });
      os << "| `" << p.name << "` | " << type_name(p.type) << " | " << unit << " | " << (domain.empty() ? "any" : domain)
         << " | " << dflt << " | " << p.effect.str() << " | " << cell(p.description) << (p.leading ? " (applied first)" : "")
         << " |\n";
    }
    // the columns a chain robot adds (n-link planar arms, URDF robots), and those it has not
    if (!chain_only) {
      std::set<std::string> seed_names;
      for (const auto& t : tables)
        for (const ParamDef& p : t) seed_names.insert(p.name);
      std::set<std::string> shown, chain_names;
      os << "\nOn a chain robot (`[robot]` with n links or a URDF file; here a 4-link planar arm and a 7-joint spatial "
            "arm) `"
         << to_string(kind) << "` runs also have:\n\n| column | type | unit | default | has an effect | description |\n"
         << "|---|---|---|---|---|---|\n";
      for (const Listed& l : all) {
        if (l.kind != kind || !is_chain(l)) continue;
        const RunSpec d = default_run(kind, l.context);
        for (const ParamDef& p : params(kind, l.context)) {
          chain_names.insert(p.name);
          if (seed_names.count(p.name) || !shown.insert(p.name).second) continue;
          const std::string unit = p.file_unit_name() == p.unit ? (p.unit.empty() ? "-" : p.unit)
                                                                : p.file_unit_name() + " / " + p.unit;
          os << "| `" << p.name << "` | " << type_name(p.type) << " | " << unit << " | " << file_value(p, d) << " | "
             << p.effect.str() << " | " << cell(p.description) << " |\n";
        }
      }
      std::string absent;
      for (const std::string& n : seed_names)
        if (!chain_names.count(n)) absent += (absent.empty() ? "" : ", ") + ("`" + n + "`");
      if (!absent.empty()) os << "\nNot on chain robots: " << absent << ".\n";
    }
    os << "\nMetrics of `" << to_string(kind) << "` runs (per-joint metrics: one per joint of the robot, "
          "as many as it has):\n\n| column | type | unit | in /landscapes | description |\n"
          "|---|---|---|---|---|\n";
    KindContext metric_context;
    metric_context.placement = true;  // ik_error: blocks that place their task
    for (const MetricDef& m : metrics(kind, metric_context))
      os << "| `" << m.name << "` | " << type_name(m.type) << " | " << (m.unit.empty() ? "-" : m.unit) << " | "
         << (m.gridded ? "yes" : "no") << " | " << cell(m.description) << " |\n";
    os << "\nStatuses of `" << to_string(kind) << "` runs:";
    for (auto s : statuses(kind)) os << " `" << s << "`";
    os << "\n\n";
  }
  os << "Bookkeeping columns (every run):\n\n| column | type | unit | description |\n|---|---|---|---|\n";
  for (const ColumnSpec& c : {run_id_column(), block_column(), status_column(), wall_time_column()})
    os << "| `" << c.name << "` | " << type_name(c.type) << " | " << (c.unit.empty() ? "-" : c.unit) << " | "
       << cell(c.description) << " |\n";
}

void print_schema_json(std::ostream& os) {
  os << "{\"kinds\": [";
  bool first_kind = true;
  for (const Listed& l : listed()) {
    const auto table = params(l.kind, l.context);
    const RunSpec d = default_run(l.kind, l.context);
    os << (first_kind ? "" : ",") << "\n {\"kind\": " << json_str(to_string(l.kind)) << ", \"family\": "
       << json_str(l.family) << ", \"params\": [";
    first_kind = false;
    for (std::size_t i = 0; i < table.size(); ++i) {
      const ParamDef& p = table[i];
      const Cell c = p.get(d);
      std::string dv;
      if (const double* x = std::get_if<double>(&c)) dv = std::isfinite(*x) ? num(*x, 17) : "null";
      else if (const std::int64_t* n = std::get_if<std::int64_t>(&c)) dv = std::to_string(*n);
      else dv = json_str(std::get<std::string>(c));
      os << (i ? "," : "") << "\n  {\"name\": " << json_str(p.name) << ", \"type\": " << json_str(type_name(p.type))
         << ", \"file_unit\": " << json_str(p.file_unit_name()) << ", \"unit\": " << json_str(p.unit)
         << ", \"domain\": " << json_str(p.domain.str(p.name)) << ", \"default\": " << dv
         << ", \"effect_controller\": " << json_str(p.effect.controller) << ", \"effect_when\": [";
      for (std::size_t w = 0; w < p.effect.when.size(); ++w) os << (w ? ", " : "") << json_str(p.effect.when[w]);
      os << "], \"choices\": [";
      for (std::size_t w = 0; w < p.choices.size(); ++w) os << (w ? ", " : "") << json_str(p.choices[w]);
      os << "], \"leading\": " << (p.leading ? "true" : "false") << ", \"description\": " << json_str(p.description)
         << "}";
    }
    os << "],\n  \"metrics\": [";
    const auto& ms = metrics(l.kind);
    for (std::size_t i = 0; i < ms.size(); ++i)
      os << (i ? "," : "") << "\n  {\"name\": " << json_str(ms[i].name) << ", \"type\": " << json_str(type_name(ms[i].type))
         << ", \"unit\": " << json_str(ms[i].unit) << ", \"gridded\": " << (ms[i].gridded ? "true" : "false")
         << ", \"description\": " << json_str(ms[i].description) << "}";
    os << "],\n  \"statuses\": [";
    const auto st = statuses(l.kind);
    for (std::size_t i = 0; i < st.size(); ++i) os << (i ? ", " : "") << json_str(st[i]);
    os << "]}";
  }
  os << "],\n \"bookkeeping\": [";
  bool first = true;
  for (const ColumnSpec& c : {run_id_column(), block_column(), status_column(), wall_time_column()}) {
    os << (first ? "" : ", ") << json_str(c.name);
    first = false;
  }
  os << "]}\n";
}

int schema_command(const SchemaArgs& a) {
  if (a.format == "json") print_schema_json(std::cout);
  else print_schema_markdown(std::cout);
  return 0;
}

}  // namespace ks::cli
