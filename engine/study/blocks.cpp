// [[block]] tables: name and kind, fixed parameters, the block's axes, its LHS and zip groups, the
// rejection of axes a run would ignore, and the study-wide run-count limit.
#include <algorithm>
#include <map>
#include <set>

#include "methods/seed_cases.hpp"
#include "study/parser.hpp"

namespace ks::study_parse {

std::optional<Block> Parser::parse_block(const toml::table& b, std::size_t index, const Study& s,
                                         std::map<std::string, Pos>& names, bool optimize) {
  const std::size_t errors_before = diags_.size();
  const Pos bpos = pos_of(b.source());
  const std::string label = (optimize ? "[[optimize]] #" : "[[block]] #") + std::to_string(index + 1);

  BlockSpec spec;
  // name
  if (auto v = get_string(b, "name", "block name")) {
    const Pos np = pos_of(b.get("name")->source());
    if (v->empty()) error(np, "block name is empty; expected a non-empty, unique name");
    else if (auto it = names.find(*v); it != names.end())
      note(error(np, "duplicate block name '" + *v + "' (first at line " + std::to_string(it->second.line) +
                         "); expected unique block names"),
           it->second, std::string(optimize ? "optimisation '" : "block '") + *v + "' first defined here");
    else names.emplace(*v, np);
    spec.name = *v;
  } else if (!b.get("name") && optimize && b.get("preset") && b.get("preset")->as_string()) {
    spec.name = b.get("preset")->as_string()->get();  // an optimisation of a seed row is named after it
    if (auto it = names.find(spec.name); it != names.end())
      note(error(bpos, label + " is named '" + spec.name + "' after its preset, like the one at line " +
                           std::to_string(it->second.line) + "; expected unique names (give name = \"...\")"),
           it->second, "'" + spec.name + "' first defined here");
    else names.emplace(spec.name, bpos);
  } else if (!b.get("name")) {
    error(bpos, label + " has no name; expected name = \"...\" (unique)" + (optimize ? " or a preset" : ""));
  }
  // kind
  BlockKind kind{};
  bool kind_ok = false;
  if (auto v = get_string(b, "kind", "block kind")) {
    kind_ok = parse(*v, kind);
    if (!kind_ok)
      error(*b.get("kind"), "unknown block kind '" + *v + "'; expected \"trajectory\" or \"ik\"" +
                                suggest(*v, {"trajectory", "ik"}));
  } else if (!b.get("kind") && optimize) {
    kind = BlockKind::trajectory;  // optimisation blocks default to trajectory
    kind_ok = true;
  } else if (!b.get("kind")) {
    error(bpos, label + " has no kind; expected kind = \"trajectory\" or \"ik\"");
  }
  if (!kind_ok) return std::nullopt;
  spec.kind = kind;
  const std::string kname(to_string(kind));
  const std::string other_kname(to_string(kind == BlockKind::trajectory ? BlockKind::ik : BlockKind::trajectory));
  const std::string a_kind = (kind == BlockKind::ik ? "an " : "a ") + kname;
  const std::string a_other = (kind == BlockKind::ik ? "a " : "an ") + other_kname;

  const std::size_t nverts = s.task.vertices.size();
  auto infos = block_params(kind, nverts);  // SCARA units until the block's problem family is known
  const auto other = block_params(kind == BlockKind::trajectory ? BlockKind::ik : BlockKind::trajectory, nverts);
  std::vector<std::string> param_names;
  for (const auto& i : infos) param_names.push_back(i.name);
  auto info_of = [&](std::string_view n) -> const ParamInfo* {
    for (const auto& i : infos)
      if (i.name == n) return &i;
    return nullptr;
  };
  auto belongs_to_other = [&](std::string_view n) {
    if (kind == BlockKind::ik && (n == "vertex_alpha" || n.starts_with("vertex_alpha_"))) return true;
    for (const auto& i : other)
      if (i.name == n) return true;
    return false;
  };

  // Keys of the block table.
  std::vector<std::string> block_keys{"name", "kind", "axes", "zip", "lhs"};
  if (optimize)
    for (const char* k : {"variables", "objective", "global", "local", "polish_from", "seed", "constraint", "penalty"})
      block_keys.push_back(k);
  for (const auto& n : param_names) block_keys.push_back(n);
  if (kind == BlockKind::trajectory) block_keys.push_back("vertex_alpha");
  for (auto&& [k, n] : ordered(b)) {
    const std::string key(k->str());
    if (std::find(block_keys.begin(), block_keys.end(), key) != block_keys.end()) continue;
    if (belongs_to_other(key))
      error(*k, "parameter '" + key + "' does not belong to " + a_kind + " block (it is " + a_other +
                    " parameter); expected " + a_kind + " parameter: " + join(param_names));
    else
      error(*k, "unknown key '" + key + "' in " + kname + " block '" + spec.name + "'; expected name, kind, axes, zip, lhs" +
                    (kind == BlockKind::trajectory ? ", vertex_alpha" : "") + " or " + a_kind +
                    " parameter: " + join(param_names) + suggest_either(key, block_keys, other, other_kname));
  }

  const toml::table* axes_t = nullptr;
  if (const toml::node* an = b.get("axes")) {
    axes_t = an->as_table();
    if (!axes_t) error(*an, "axes is " + type_name(*an) + "; expected a table [block.axes] of parameter = values");
  }
  std::set<std::string> axis_names;
  std::map<std::string, Pos> axis_keys;  // where each axis is written
  if (axes_t)
    for (auto&& [k, n] : *axes_t) {
      axis_names.insert(std::string(k.str()));
      axis_keys.emplace(std::string(k.str()), pos_of(k.source()));
    }

  // IK problem family, needed for q0_3's unit: from the fixed problem or the problem axis.
  bool scara = true;
  if (kind == BlockKind::ik) {
    std::vector<std::pair<std::string, const toml::node*>> probs;
    if (const toml::node* p = b.get("problem"); p && p->as_string()) probs.emplace_back(p->as_string()->get(), p);
    if (axes_t)
      if (const toml::node* p = axes_t->get("problem")) {
        const toml::array* a = p->as_array();
        if (!a && p->as_table()) {
          if (const toml::node* vv = p->as_table()->get("values")) a = vv->as_array();
        }
        if (a)
          for (const auto& e : *a)
            if (e.as_string()) probs.emplace_back(e.as_string()->get(), &e);
      }
    if (!probs.empty()) {
      scara = ik_problem_is_scara(probs.front().first);
      for (const auto& [p, node] : probs)
        if (ik_problem_is_scara(p) != scara) {
          note(error(*node, "problem '" + p + "' mixes the SCARA (mm) with the planar 3R (m, deg) problems in one "
                            "block; expected separate blocks for scara and planar3r_* problems"),
               pos_of(probs.front().second->source()),
               "the block's first problem, '" + probs.front().first + "', is " +
                   (scara ? "the SCARA problem (mm)" : "a planar 3R problem (m, deg)"));
          break;
        }
    }
    if (!scara) infos = block_params(kind, nverts, false);
  }

  // Fixed parameters.
  for (auto&& [k, n] : ordered(b)) {
    const std::string key(k->str());
    if (key == "vertex_alpha" && kind == BlockKind::trajectory) {
      const auto* a = n->as_array();
      if (!a || a->size() + 1 != nverts) {
        error(*n, "vertex_alpha is " + (a ? "an array of " + std::to_string(a->size()) : type_name(*n)) +
                      "; expected an array of " + std::to_string(nverts - 1) + " angles [deg] (vertices 2.." +
                      std::to_string(nverts) + ")");
        continue;
      }
      for (std::size_t i = 0; i < a->size(); ++i) {
        const std::string pname = "vertex_alpha_" + std::to_string(i + 2);
        if (b.get(pname) || axis_names.count(pname)) {
          auto& d = error(*k, "vertex_alpha and " + pname + " both given; expected one or the other");
          if (auto it = b.find(pname); it != b.end()) note(d, pos_of(it->first.source()), pname + " given here");
          else note(d, axis_keys.at(pname), pname + " is an axis here");
          note(d, Pos{0, 0}, "vertex_alpha = [...] is shorthand for vertex_alpha_2 .. vertex_alpha_" +
                                 std::to_string(nverts));
          continue;
        }
        if (auto c = param_value(*info_of(pname), *a->get(i))) spec.fixed.emplace_back(pname, *c);
      }
      continue;
    }
    const ParamInfo* info = info_of(key);
    if (!info) continue;
    if (axis_names.count(key)) {
      note(error(*k, "'" + key + "' is both a fixed parameter and an axis; expected one or the other"),
           axis_keys.at(key), "'" + key + "' is an axis here");
      continue;
    }
    if (auto c = param_value(*info, *n)) spec.fixed.emplace_back(key, *c);
  }

  // Block-level LHS settings.
  std::optional<std::uint64_t> lhs_count, lhs_seed;
  const toml::node* lhs_node = b.get("lhs");
  if (lhs_node) {
    if (const auto* lt = lhs_node->as_table()) {
      check_keys(*lt, {"count", "seed"}, "lhs");
      if (const toml::node* c = lt->get("count")) {
        if (auto v = get_integer(*c, "lhs count")) {
          if (*v < 1) error(*c, "lhs count = " + std::to_string(*v) + "; expected count >= 1");
          else if (std::uint64_t(*v) > max_runs_)
            error(*c, "lhs count = " + std::to_string(*v) + "; expected at most max_runs = " + std::to_string(max_runs_));
          else lhs_count = std::uint64_t(*v);
        }
      } else error(*lhs_node, "lhs has no count; expected lhs = { count = N, seed = S }");
      if (const toml::node* c = lt->get("seed")) {
        if (auto v = get_integer(*c, "lhs seed")) {
          if (*v < 0) error(*c, "lhs seed = " + std::to_string(*v) + "; expected seed >= 0");
          else lhs_seed = std::uint64_t(*v);
        }
      } else error(*lhs_node, "lhs has no seed; expected lhs = { count = N, seed = S }");
    } else {
      error(*lhs_node, "lhs is " + type_name(*lhs_node) + "; expected lhs = { count = N, seed = S }");
    }
  }

  // Axes.
  std::vector<AxisDraft> drafts;
  if (axes_t) {
    for (auto&& [k, n] : ordered(*axes_t)) {
      const std::string key(k->str());
      const ParamInfo* info = info_of(key);
      if (!info) {
        if (key == "vertex_alpha" && kind == BlockKind::trajectory)
          error(*k, "vertex_alpha cannot be an axis as a whole; expected one axis per vertex: vertex_alpha_2 .. vertex_alpha_" +
                        std::to_string(nverts));
        else if (belongs_to_other(key))
          error(*k, "axis '" + key + "' does not belong to " + a_kind + " block (it is " + a_other +
                        " parameter); expected " + a_kind + " parameter: " + join(param_names));
        else
          error(*k, "unknown axis '" + key + "' in " + kname + " block '" + spec.name + "'; expected " + a_kind +
                        " parameter: " + join(param_names) + suggest_either(key, param_names, other, other_kname));
        continue;
      }
      if (auto d = parse_axis(*info, *k, *n, lhs_node)) drafts.push_back(std::move(*d));
    }
  }

  // LHS group: draw now that all its axes are known.
  std::vector<std::string> lhs_group;
  {
    std::vector<std::pair<double, double>> ranges;
    std::vector<AxisDraft*> lhs_axes;
    for (auto& d : drafts)
      if (d.lhs) {
        ranges.push_back(d.lhs_range);
        lhs_axes.push_back(&d);
      }
    if (lhs_node && lhs_axes.empty() && lhs_node->as_table())
      error(*lhs_node, "lhs settings given but no axis uses them; expected axes written { lhs = { from, to } }");
    if (!lhs_axes.empty() && lhs_count && lhs_seed) {
      const auto draws = lhs_draws(*lhs_seed, *lhs_count, ranges);
      for (std::size_t i = 0; i < lhs_axes.size(); ++i) {
        const ParamInfo* info = info_of(lhs_axes[i]->axis.name);
        for (double v : draws[i]) lhs_axes[i]->axis.values.push_back(info->from_file(v));
        lhs_group.push_back(lhs_axes[i]->axis.name);
      }
    }
    // Drop LHS axes that got no values (their settings were bad: already reported).
    std::erase_if(drafts, [](const AxisDraft& d) { return d.axis.values.empty(); });
  }

  // zip groups.
  if (const toml::node* zn = b.get("zip")) {
    const auto* za = zn->as_array();
    if (!za) error(*zn, "zip is " + type_name(*zn) + "; expected zip = [[\"a\", \"b\"], ...]");
    else {
      std::map<std::string, Pos> zipped;  // axis -> its first zip entry
      std::vector<std::string> all_axes(axis_names.begin(), axis_names.end());
      for (const auto& g : *za) {
        const auto* ga = g.as_array();
        if (!ga) {
          error(g, "a zip group is " + type_name(g) + "; expected an array of axis names [\"a\", \"b\"]");
          continue;
        }
        if (ga->size() < 2) {
          error(g, "a zip group has " + std::to_string(ga->size()) + " axis; expected at least 2 axes to zip");
          continue;
        }
        std::vector<std::string> group;
        std::vector<std::string> lens;
        std::vector<std::pair<Pos, std::string>> len_notes;  // at each axis: its length
        std::optional<std::size_t> len;
        bool unequal = false, ok = true;
        for (const auto& e : *ga) {
          const auto* s = e.as_string();
          if (!s) {
            error(e, "a zip entry is " + type_name(e) + "; expected an axis name");
            ok = false;
            continue;
          }
          const std::string nm = s->get();
          if (!axis_names.count(nm)) {
            error(e, "zip names '" + nm + "', which is not an axis of block '" + spec.name + "'; expected one of " +
                         join(all_axes) + suggest(nm, all_axes));
            ok = false;
            continue;
          }
          if (auto [first, fresh] = zipped.emplace(nm, pos_of(e.source())); !fresh) {
            note(error(e, "axis '" + nm + "' is zipped twice; expected each axis in at most one zip group"),
                 first->second, "'" + nm + "' first zipped here");
            ok = false;
            continue;
          }
          auto it = std::find_if(drafts.begin(), drafts.end(), [&](const AxisDraft& d) { return d.axis.name == nm; });
          if (it == drafts.end()) {  // the axis had errors
            ok = false;
            continue;
          }
          if (it->lhs) {
            error(e, "axis '" + nm + "' is an LHS axis (LHS axes already advance together); expected no LHS axis in zip");
            ok = false;
            continue;
          }
          lens.push_back(nm + " (" + std::to_string(it->axis.values.size()) + ")");
          len_notes.emplace_back(it->pos, "axis '" + nm + "' has " + std::to_string(it->axis.values.size()) +
                                              (it->axis.values.size() == 1 ? " value" : " values"));
          if (len && *len != it->axis.values.size()) unequal = true;
          len = it->axis.values.size();
          group.push_back(nm);
        }
        if (unequal) {
          auto& d = error(g, "zipped axes have different lengths: " + join(lens) + "; expected equal lengths");
          for (const auto& [at, msg] : len_notes) note(d, at, msg);
          ok = false;
        }
        if (ok) spec.groups.push_back(group);
      }
    }
  }
  if (!lhs_group.empty()) spec.groups.push_back(lhs_group);

  // Swept parameters that a run would ignore would only repeat runs: reject them (the tables' effect rules).
  BlockContext ctx;
  ctx.path_vertices = nverts;
  ctx.integrator = s.task.integrator;
  ctx.dt = s.task.dt;
  ctx.inertia = s.robot.inertia_form;
  ctx.scara = scara;
  const RunSpec defaults = default_run(kind, ctx);
  auto explicit_values = [&](std::string_view nm) {
    std::vector<Cell> out;
    for (const auto& [n, v] : spec.fixed)
      if (n == nm) out.push_back(v);
    for (const auto& d : drafts)
      if (d.axis.name == nm) out.insert(out.end(), d.axis.values.begin(), d.axis.values.end());
    return out;
  };
  // The values a controlling parameter takes in the block's runs: its own, else those the leading
  // parameters (a preset) set, else its default.
  auto controller_values = [&](const ParamInfo& ctl) {
    std::vector<Cell> vs = explicit_values(ctl.name);
    if (vs.empty())
      for (const ParamInfo& lead : infos)
        if (lead.leading)
          for (const Cell& v : explicit_values(lead.name)) {
            RunSpec r = defaults;
            lead.set(r, v);
            vs.push_back(ctl.get(r));
          }
    if (vs.empty()) vs.push_back(ctl.get(defaults));
    return vs;
  };
  for (const auto& d : drafts) {
    const ParamInfo* p = info_of(d.axis.name);
    const ParamInfo* ctl = p && !p->effect.always() ? info_of(p->effect.controller) : nullptr;
    if (!ctl) continue;
    for (const Cell& c : controller_values(*ctl)) {
      const std::string& v = std::get<std::string>(c);
      if (p->effect.applies(v)) continue;
      error(d.pos, "axis '" + d.axis.name + "' has no effect when " + ctl->name + " = '" + v +
                       "' (its runs would repeat); expected a " + d.axis.name + " axis " + p->effect.str() +
                       " (split the block)");
      break;
    }
  }

  if (diags_.size() != errors_before) return std::nullopt;
  for (auto& d : drafts) spec.axes.push_back(std::move(d.axis));
  try {
    return Block(std::move(spec), ctx);
  } catch (const std::exception& e) {
    error(bpos, std::string("invalid block: ") + e.what() + "; expected a consistent block");
    return std::nullopt;
  }
}

void Parser::parse_blocks(const toml::table& root, Study& s) {
  const toml::node* n = root.get("block");
  if (!n) {
    error(Pos{1, 1}, "the study has no blocks; expected at least one [[block]] table");
    return;
  }
  const auto* a = n->as_array();
  if (!a || !a->is_array_of_tables()) {
    error(*n, "'block' is " + (a ? std::string("an array of non-tables") : type_name(*n)) +
                  "; expected [[block]] tables (an array of tables)");
    return;
  }
  std::map<std::string, Pos> names;
  std::uint64_t total = 0;
  bool reported_total = false;
  std::optional<std::pair<bool, Pos>> ik_family;  // the first IK block's family (SCARA?) and place
  for (std::size_t i = 0; i < a->size(); ++i) {
    const auto& bt = *a->get(i)->as_table();
    auto block = parse_block(bt, i, s, names);
    if (!block) continue;
    if (block->kind() == BlockKind::ik) {
      // The problem families store q0_3, target_* and tol in different units (mm; rad, m): one
      // /runs column cannot say both.
      const bool scara = block->context().scara;
      if (!ik_family) {
        ik_family.emplace(scara, pos_of(bt.source()));
      } else if (ik_family->first != scara) {
        auto fam = [](bool sc) { return std::string(sc ? "the SCARA problem (mm)" : "planar 3R problems (m, rad)"); };
        note(error(bt.source(), "ik block '" + block->name() + "' solves " + fam(scara) + " but an earlier ik block solves " +
                                    fam(ik_family->first) + "; their q0_3, target_* and tol columns would mix units; "
                                    "expected the SCARA and the planar 3R IK blocks in separate studies"),
             ik_family->second, "the first ik block, with " + fam(ik_family->first));
      }
    }
    const bool over = block->overflowed() || total + block->run_count() < total ||
                      total + block->run_count() > max_runs_;
    if (over && !reported_total) {
      error(bt.source(), "too many runs: block '" + block->name() + "' has " +
                             (block->overflowed() ? std::string("more than 2^64") : std::to_string(block->run_count())) +
                             " runs, the study " +
                             (block->overflowed() ? std::string("overflows") : std::to_string(total + block->run_count())) +
                             "; expected at most " + std::to_string(max_runs_) +
                             " runs in all (set [study] max_runs to allow more)");
      reported_total = true;
    }
    if (!block->overflowed()) total += block->run_count();
    s.blocks.push_back(std::move(*block));
  }
}

}  // namespace ks::study_parse
