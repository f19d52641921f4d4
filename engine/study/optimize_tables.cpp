// [[optimize]] tables: the block to evaluate, its variables and objective, the global and local stages,
// polish_from, seed, constraint and penalty.
#include <algorithm>
#include <map>
#include <set>

#include "methods/closed_form/seed_cases.hpp"
#include "study/parser.hpp"

namespace ks::study_parse {

std::optional<opt::StageOptions> Parser::parse_stage(const toml::node& n, bool global, OptimizeBlock& ob) {
  const std::string where = global ? "[optimize.global]" : "[optimize.local]";
  const auto* t = n.as_table();
  if (!t) {
    error(n, where + " is " + type_name(n) + "; expected a table (algorithm = \"...\", stopping rules)");
    return std::nullopt;
  }
  std::vector<std::string> keys{"algorithm", "max_evals", "max_time", "xtol_rel", "xtol_abs", "ftol_rel",
                                "ftol_abs",  "stopval",   "population", "fd_step", "initial_step"};
  if (!global) {
    keys.push_back("starts");
    keys.push_back("distinct");
  } else {
    keys.push_back("islands");
  }
  check_keys(*t, keys, where);
  opt::StageOptions st = global ? opt::seed_global() : opt::seed_local();
  bool ok = true;
  if (auto v = get_string(*t, "algorithm", "algorithm")) {
    std::vector<std::string> allowed;
    for (auto a : opt::algorithm_names())
      if (opt::is_global([&] { opt::Algorithm x{}; opt::parse(a, x); return x; }()) == global) allowed.emplace_back(a);
    opt::Algorithm a{};
    if (!opt::parse(*v, a) || opt::is_global(a) != global) {
      error(*t->get("algorithm"), (opt::parse(*v, a) ? "algorithm '" + *v + "' is not a " +
                                                           (global ? "global" : "local") + " algorithm"
                                                     : "unknown algorithm '" + *v + "'") +
                                      "; expected one of " + join(allowed) + suggest(*v, allowed));
      ok = false;
    } else {
      st.algorithm = a;
    }
  }
  auto positive_int = [&](const char* key, int& out) {
    if (const toml::node* x = t->get(key))
      if (auto v = get_integer(*x, key)) {
        if (*v < 1 || *v > 2'000'000'000) {
          error(*x, std::string(key) + " = " + std::to_string(*v) + "; expected an integer >= 1");
          ok = false;
        } else out = int(*v);
      }
  };
  auto nonneg = [&](const char* key, double& out, bool strictly) {
    if (auto v = get_number(*t, key, key)) {
      if (*v < 0 || (strictly && *v == 0)) {
        error(*t->get(key), std::string(key) + " = " + fmt(*v) + "; expected " + key + (strictly ? " > 0" : " >= 0"));
        ok = false;
      } else out = *v;
    }
  };
  positive_int("max_evals", st.max_evals);
  positive_int("population", st.population);
  nonneg("max_time", st.max_time_s, true);
  nonneg("xtol_rel", st.xtol_rel, false);
  nonneg("xtol_abs", st.xtol_abs, false);
  nonneg("ftol_rel", st.ftol_rel, false);
  nonneg("ftol_abs", st.ftol_abs, false);
  nonneg("fd_step", st.fd_step, true);
  nonneg("initial_step", st.initial_step, false);
  if (auto v = get_number(*t, "stopval", "stopval")) st.stopval = *v;
  if (global) positive_int("islands", st.islands);
  if (!global) {
    positive_int("starts", ob.local_starts);
    nonneg("distinct", ob.distinct, false);
  }
  if (!ok) return std::nullopt;
  return st;
}

void Parser::parse_optimizations(const toml::table& root, Study& s) {
  const toml::node* n = root.get("optimize");
  if (!n) return;
  const auto* a = n->as_array();
  if (!a || !a->is_array_of_tables()) {
    error(*n, "'optimize' is " + (a ? std::string("an array of non-tables") : type_name(*n)) +
                  "; expected [[optimize]] tables (an array of tables)");
    return;
  }
  std::map<std::string, Pos> names;
  const std::size_t nverts = s.task.vertices.size();
  for (std::size_t i = 0; i < a->size(); ++i) {
    const auto& t = *a->get(i)->as_table();
    const std::size_t errors_before = diags_.size();
    const Pos bpos = pos_of(t.source());
    const std::string label = "[[optimize]] #" + std::to_string(i + 1);
    auto block = parse_block(t, i, s, names, true);
    if (!block) continue;
    OptimizeBlock ob;
    ob.name = block->name();
    ob.line = bpos.line;
    if (const toml::node* p = t.get("preset"); p && p->as_string()) ob.preset = p->as_string()->get();
    const BlockKind kind = block->kind();
    const auto& infos = block->table();
    std::set<std::string> axis_names;
    for (const auto& ax : block->axes()) axis_names.insert(ax.name);

    // variables = { name = [lower, upper] | { from, to, start }, ... } (file units)
    const toml::node* vn = t.get("variables");
    const auto* vt = vn ? vn->as_table() : nullptr;
    const SeedCase* seed_row = ob.preset.empty() ? nullptr : find_seed_case(ob.preset);
    if (!vn && seed_row && kind == BlockKind::trajectory) {
      // A seed row's own design variables (Table 4): k and/or alpha1A, or the five vertex alphas.
      const std::string_view p = ob.preset;
      bool robot_lacks = false;  // a variable of the seed arm's row that the study's robot has no column for
      auto add = [&](const std::string& nm, double lo, double hi) {
        if (axis_names.count(nm)) return;
        const std::size_t col = block->column_index(nm);
        if (col == Block::npos) {
          if (!robot_lacks)
            error(bpos, label + ": preset '" + ob.preset + "' optimises " + nm + ", which the study's robot has no " +
                            "parameter for (it is the seed's planar 3R's); expected variables = { ... }");
          robot_lacks = true;
          return;
        }
        OptimizeVariable v;
        v.name = nm;
        v.unit = block->columns()[col].unit;
        v.lower = v.unit == "rad" ? lo * kDeg : lo;
        v.upper = v.unit == "rad" ? hi * kDeg : hi;
        ob.variables.push_back(std::move(v));
      };
      if (p == "3" || p == "4") {
        add("alpha1A", -180, 180);
        for (std::size_t v = 2; v <= nverts; ++v) add("vertex_alpha_" + std::to_string(v), -180, 180);
      } else if (p.size() == 2 && (p[1] == 'g' || p[1] == 'h')) {
        add("alpha1A", -180, 180);
        if (p[1] == 'h') add("k", 0, 1);
      } else if (p.size() == 2 && (p[1] == 'b' || p[1] == 'd' || p[1] == 'f')) {
        add("k", 0, 1);
      }
      if (ob.variables.empty() && !robot_lacks)
        error(bpos, label + ": preset '" + ob.preset + "' is not an optimised row of Table 4; expected variables = { ... }");
    } else if (!vn) error(bpos, label + " has no variables; expected variables = { alpha1A = [-40, 40], k = [0, 1] } (or an optimised preset: 1b, 1d, 1f, 1g, 1h, 2b, 2d, 2f, 2g, 2h, 3, 4)");
    else if (!vt || vt->empty())
      error(*vn, "variables is " + (vt ? std::string("empty") : type_name(*vn)) +
                     "; expected variables = { parameter = [lower, upper], ... }");
    std::vector<std::string> f64_names;
    for (const auto& info : infos)
      if (info.type == CellType::f64) f64_names.push_back(info.name);
    if (vt) {
      for (auto&& [k, node] : ordered(*vt)) {
        const std::string key(k->str());
        std::vector<std::string> params;
        if (key == "vertex_alpha" && kind == BlockKind::trajectory)
          for (std::size_t v = 2; v <= nverts; ++v) params.push_back("vertex_alpha_" + std::to_string(v));
        else params.push_back(key);
        const ParamDef* info = nullptr;
        for (const auto& in : infos)
          if (in.name == params.front()) info = &in;
        if (!info && kind == BlockKind::trajectory && !placement_refusal(key, s.robot_shape()).empty()) {
          error(*k, placement_refusal(key, s.robot_shape()));
          continue;
        }
        if (!info) {
          std::vector<std::string> candidates = f64_names;
          if (kind == BlockKind::trajectory)
            for (std::string& n : placement_names(s.robot_shape()))
              if (std::find(candidates.begin(), candidates.end(), n) == candidates.end()) candidates.push_back(n);
          error(*k, "unknown variable '" + key + "' for " + std::string(to_string(kind)) + " runs; expected a numeric parameter: " +
                        join(f64_names) + suggest(key, candidates));
          continue;
        }
        if (info->type != CellType::f64) {
          error(*k, "variable '" + key + "' is " + (info->type == CellType::str ? "a name" : "an integer") +
                        " parameter; expected a continuous (numeric, non-integer) parameter: " + join(f64_names));
          continue;
        }
        bool bad = false;
        for (const auto& pn : params) {
          if (axis_names.count(pn)) {
            error(*k, "variable '" + pn + "' is also an axis (axes are the evaluation set); expected one or the other");
            bad = true;
          }
          for (const auto& v : ob.variables)
            if (v.name == pn) {
              error(*k, "variable '" + pn + "' given twice; expected each variable once");
              bad = true;
            }
        }
        if (!info->effect.always())  // the table's effect rule, on every run of the evaluation set
          for (std::uint64_t r = 0; r < block->run_count(); ++r) {
            const RunSpec run = block->run(r);
            if (has_effect(*info, infos, run)) continue;
            const ParamDef* ctl = find_param(infos, info->effect.controller);
            error(*k, "variable '" + key + "' has no effect when " + ctl->name + " = '" +
                          std::get<std::string>(ctl->get(run)) + "'; expected it " + info->effect.str());
            bad = true;
            break;
          }
        double lo = 0, hi = 0;
        std::optional<double> start;
        if (const auto* arr = node->as_array()) {
          if (arr->size() != 2) {
            error(*node, "variable '" + key + "' bounds are an array of " + std::to_string(arr->size()) +
                             "; expected [lower, upper]");
            continue;
          }
          auto l = get_number(*arr->get(0), "lower bound"), h = get_number(*arr->get(1), "upper bound");
          if (!l || !h) continue;
          lo = *l;
          hi = *h;
        } else if (const auto* bt = node->as_table()) {
          check_keys(*bt, {"from", "to", "start"}, "variable '" + key + "'");
          auto l = get_number(*bt, "from", "from"), h = get_number(*bt, "to", "to");
          if (!bt->get("from") || !bt->get("to")) {
            error(*node, "variable '" + key + "' lacks from or to; expected { from = lower, to = upper[, start = x] }");
            continue;
          }
          if (!l || !h) continue;
          lo = *l;
          hi = *h;
          if (bt->get("start")) {
            start = get_number(*bt, "start", "start");
            if (!start) continue;
          }
        } else {
          error(*node, "variable '" + key + "' is " + type_name(*node) +
                           "; expected [lower, upper] or { from = lower, to = upper, start = x } (file units: deg for angles)");
          continue;
        }
        if (!(lo < hi)) {
          error(*node, "variable '" + key + "' has lower = " + fmt(lo) + " >= upper = " + fmt(hi) + "; expected lower < upper");
          continue;
        }
        if (start && (*start < lo || *start > hi)) {
          error(*node, "variable '" + key + "' start = " + fmt(*start) + " is outside [" + fmt(lo) + ", " + fmt(hi) +
                           "]; expected a start within the bounds");
          continue;
        }
        bool dom = false;
        for (double v : {lo, hi})
          if (auto p = domain_problem(*info, v); !p.empty() && !dom) {
            error(*node, "variable '" + key + "' bound: " + p);
            dom = true;
          }
        if (bad || dom) continue;
        for (const auto& pn : params) {
          OptimizeVariable v;
          v.name = pn;
          v.unit = block->columns()[block->column_index(pn)].unit;
          v.lower = std::get<double>(info->from_file(lo));
          v.upper = std::get<double>(info->from_file(hi));
          if (start) v.start = std::get<double>(info->from_file(*start));
          ob.variables.push_back(std::move(v));
        }
      }
    }

    parse_objective(t, *block, kind, ob);

    // stages
    const toml::node* gn = t.get("global");
    const toml::node* ln = t.get("local");
    if (!gn && !ln) {
      ob.global = opt::seed_global();
      ob.local = opt::seed_local();
    }
    if (gn) ob.global = parse_stage(*gn, true, ob);
    if (ln) ob.local = parse_stage(*ln, false, ob);

    // polish_from = { block = "landscape", best = 5 }
    if (const toml::node* pn = t.get("polish_from")) {
      const auto* pt = pn->as_table();
      if (!pt) error(*pn, "polish_from is " + type_name(*pn) + "; expected polish_from = { block = \"name\", best = N }");
      else {
        check_keys(*pt, {"block", "best"}, "polish_from");
        if (auto b = get_string(*pt, "block", "polish_from block")) {
          std::vector<std::string> bn;
          for (const auto& blk : s.blocks) bn.push_back(blk.name());
          const std::size_t bi = s.block_index(*b);
          if (bi == Block::npos)
            error(*pt->get("block"), "polish_from names block '" + *b + "', which is not a [[block]] of this study; expected one of " +
                                         join(bn) + suggest(*b, bn));
          else if (s.blocks[bi].kind() != kind)
            error(*pt->get("block"), "polish_from block '" + *b + "' is " + std::string(to_string(s.blocks[bi].kind())) +
                                         "; expected a " + std::string(to_string(kind)) + " block like this optimisation");
          else ob.polish_block = *b;
        } else if (!pt->get("block")) {
          error(*pn, "polish_from has no block; expected polish_from = { block = \"name\", best = N }");
        }
        ob.polish_best = 5;
        if (const toml::node* bn = pt->get("best"))
          if (auto v = get_integer(*bn, "best")) {
            if (*v < 1 || *v > 100000) error(*bn, "best = " + std::to_string(*v) + "; expected 1 <= best <= 100000");
            else ob.polish_best = int(*v);
          }
        if (!ob.local && (gn || ln))
          error(*pn, "polish_from without a local stage; expected an [optimize.local] table to polish the cells with");
      }
    }
    if (const toml::node* sn = t.get("seed"))
      if (auto v = get_integer(*sn, "seed")) {
        if (*v < 0) error(*sn, "seed = " + std::to_string(*v) + "; expected seed >= 0");
        else ob.seed = std::uint64_t(*v);
      }
    if (auto v = get_string(t, "constraint", "constraint")) {
      if (*v == "auto") ob.constraint = opt::ConstraintMode::automatic;
      else if (*v == "penalty") ob.constraint = opt::ConstraintMode::penalty;
      else error(*t.get("constraint"), "constraint = '" + *v + "'; expected \"auto\" or \"penalty\"" + suggest(*v, {"auto", "penalty"}));
    }
    if (auto v = get_number(t, "penalty", "penalty")) {
      if (!(*v > 0)) error(*t.get("penalty"), "penalty = " + fmt(*v) + "; expected penalty > 0");
      else ob.penalty = *v;
    }
    if (diags_.size() != errors_before) continue;
    ob.base.push_back(std::move(*block));
    for (OptimizeBlock& x : expand_trade_off(std::move(ob))) {
      for (const OptimizeBlock& y : s.optimizations)
        if (y.name == x.name)
          error(bpos, label + ": trade_off names an optimisation '" + x.name + "', which another [[optimize]] has; "
                      "expected distinct names");
      s.optimizations.push_back(std::move(x));
    }
  }
}

}  // namespace ks::study_parse
