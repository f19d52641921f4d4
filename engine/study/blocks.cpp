// [[block]] tables: parse_block and its first steps (name, kind, the table's keys, the IK problem
// family, fixed parameters; the axes' steps, with the run-count limit, are in block_axes.cpp).
#include <algorithm>
#include <map>
#include <set>

#include "methods/closed_form/seed_cases.hpp"
#include "study/parser.hpp"

namespace ks::study_parse {

namespace {

/// What the block inherits from the study, for its problem family.
KindContext block_context(const Study& s, bool scara) {
  KindContext ctx;
  ctx.path_vertices = s.task.vertices.size();
  ctx.integrator = s.task.integrator;
  ctx.dt = s.task.dt;
  ctx.inertia = s.robot.inertia_form;
  ctx.scara = scara;
  ctx.robot = s.robot_shape();
  if (!s.task.vertices.empty()) ctx.first_vertex = s.task.vertex(0);
  return ctx;
}

/// Whether the block's method (fixed, or one value of its axis) is global_spline.
bool names_global_spline(const toml::table& b) {
  const auto is_global = [](const toml::node* n) {
    if (!n) return false;
    if (const auto* v = n->as_string()) return v->get() == "global_spline";
    if (const auto* a = n->as_array())
      for (const toml::node& e : *a)
        if (const auto* v = e.as_string(); v && v->get() == "global_spline") return true;
    return false;
  };
  if (is_global(b.get("method"))) return true;
  const toml::table* axes = b.get("axes") ? b.get("axes")->as_table() : nullptr;
  return axes && is_global(axes->get("method"));
}

/// Whether the block names a task placement parameter: a key of the table, of its axes or (an
/// [[optimize]] table) of its variables.
bool names_placement(const toml::table& b) {
  const auto any_in = [](const toml::node* n) {
    const toml::table* t = n ? n->as_table() : nullptr;
    if (!t) return false;
    for (auto&& [k, v] : *t)
      if (is_placement_param(k.str())) return true;
    return false;
  };
  return any_in(&b) || any_in(b.get("axes")) || any_in(b.get("variables"));
}

/// Why `name` cannot name an HDF5 group (/landscapes/<block>, /optimizations/<name>); "" when it can.
std::string hdf5_name_problem(const std::string& name) {
  if (name == "." || name == "..") return "is '" + name + "', which HDF5 paths reserve";
  if (name.find('/') != std::string::npos) return "contains '/', which separates HDF5 path components";
  for (unsigned char c : name)
    if (c < 0x20 || c == 0x7f) return "contains a control character";
  return "";
}

}  // namespace

bool is_placement_param(std::string_view name) {
  return name == "task_rotation" || name == "task_dx" || name == "task_dy" || name == "task_dz" ||
         name == "task_time_scale";
}

std::vector<std::string> placement_names(const RobotShape& robot) {
  std::vector<std::string> n{"task_rotation", "task_dx", "task_dy"};
  if (!robot.planar) n.emplace_back("task_dz");
  n.emplace_back("task_time_scale");
  return n;
}

std::string placement_refusal(std::string_view name, const RobotShape& robot) {
  if (name != "task_dz" || !robot.planar) return "";
  return "task_dz would move the task out of the plane the planar robot moves in; expected task_dx, task_dy, "
         "task_rotation (about the plane's normal) or task_time_scale";
}

const ParamDef* BlockDraft::info_of(std::string_view n) const {
  for (const auto& i : infos)
    if (i.name == n) return &i;
  return nullptr;
}

bool BlockDraft::belongs_to_other(std::string_view n) const {
  if (kind == BlockKind::ik && (n == "vertex_alpha" || n.starts_with("vertex_alpha_"))) return true;
  for (const auto& i : other)
    if (i.name == n) return true;
  return false;
}

std::optional<Block> Parser::parse_block(const toml::table& b, std::size_t index, const Study& s,
                                         std::map<std::string, Pos>& names, bool optimize) {
  const std::size_t errors_before = diags_.size();
  BlockDraft d(b, optimize, (optimize ? "[[optimize]] #" : "[[block]] #") + std::to_string(index + 1));
  d.nverts = s.task.vertices.size();
  d.scara = !s.chain;  // an IK block without a problem: the SCARA, or the study's chain's position problem
  d.ctx = block_context(s, d.scara);
  d.ctx.path_global = names_global_spline(b);
  d.ctx.placement = names_placement(b);

  read_block_name(d, names);
  if (!read_block_kind(d)) return std::nullopt;
  if (d.kind == BlockKind::motion && !s.chain) {
    error(d.table.get("kind")->source(),
          "kind = \"motion\" plans the motions of a chain robot, not of the seed's closed-form 3R; expected a [robot] "
          "chain: an n-link planar arm with recursive dynamics (e.g. [robot] l = [1, 1, 1] with dynamics = \"recursive\"), "
          "a DH table or a URDF robot");
    return std::nullopt;
  }
  check_block_keys(d);
  find_axes_table(d);
  read_ik_family(d);
  read_fixed_params(d);
  check_block_dt(d, s);
  read_block_lhs(d);
  read_axes(d);
  read_zip_groups(d);
  if (!check_block_runs(d)) return std::nullopt;  // nothing generated for a block too large
  generate_axes(d);
  if (!d.lhs_group.empty()) d.spec.groups.push_back(d.lhs_group);  // after the zip groups
  d.ctx = block_context(s, d.scara);
  d.ctx.path_global = names_global_spline(d.table);
  d.ctx.placement = names_placement(d.table);
  check_robot_supports(d, s);
  check_motion_world(d, s);
  reject_ineffective_axes(d);
  return finish_block(d, errors_before);
}

void Parser::read_block_name(BlockDraft& d, std::map<std::string, Pos>& names) {
  const toml::table& b = d.table;
  if (auto v = get_string(b, "name", "block name")) {
    const Pos np = pos_of(b.get("name")->source());
    const std::string what = d.optimize ? "optimisation name" : "block name";
    if (v->empty()) error(np, what + " is empty; expected a non-empty, unique name");
    else if (const std::string why = hdf5_name_problem(*v); !why.empty())
      error(np, what + " '" + *v + "' " + why + "; expected a name without '/' or control characters, "
                "other than '.' and '..' (it names a group in the results file)");
    else if (auto it = names.find(*v); it != names.end())
      note(error(np, "duplicate block name '" + *v + "' (first at line " + std::to_string(it->second.line) +
                         "); expected unique block names"),
           it->second, std::string(d.optimize ? "optimisation '" : "block '") + *v + "' first defined here");
    else names.emplace(*v, np);
    d.spec.name = *v;
  } else if (!b.get("name") && d.optimize && b.get("preset") && b.get("preset")->as_string()) {
    d.spec.name = b.get("preset")->as_string()->get();  // an optimisation of a seed row is named after it
    if (auto it = names.find(d.spec.name); it != names.end())
      note(error(d.pos, d.label + " is named '" + d.spec.name + "' after its preset, like the one at line " +
                            std::to_string(it->second.line) + "; expected unique names (give name = \"...\")"),
           it->second, "'" + d.spec.name + "' first defined here");
    else names.emplace(d.spec.name, d.pos);
  } else if (!b.get("name")) {
    error(d.pos, d.label + " has no name; expected name = \"...\" (unique)" + (d.optimize ? " or a preset" : ""));
  }
}

bool Parser::read_block_kind(BlockDraft& d) {
  const toml::table& b = d.table;
  BlockKind kind{};
  bool kind_ok = false;
  if (auto v = get_string(b, "kind", "block kind")) {
    kind_ok = parse(*v, kind);
    if (!kind_ok)
      error(*b.get("kind"), "unknown block kind '" + *v + "'; expected \"trajectory\", \"ik\" or \"motion\"" +
                                suggest(*v, {"trajectory", "ik", "motion"}));
  } else if (!b.get("kind") && d.optimize) {
    kind = BlockKind::trajectory;  // optimisation blocks default to trajectory
    kind_ok = true;
  } else if (!b.get("kind")) {
    error(d.pos, d.label + " has no kind; expected kind = \"trajectory\", \"ik\" or \"motion\"");
  }
  if (!kind_ok) return false;
  d.kind = kind;
  d.spec.kind = kind;
  // the kind whose parameters a misplaced key is looked up in (did-you-mean): ik's for a trajectory
  // block, trajectory's for the others
  const BlockKind other_kind = kind == BlockKind::trajectory ? BlockKind::ik : BlockKind::trajectory;
  d.kname = std::string(to_string(kind));
  d.other_kname = std::string(to_string(other_kind));
  d.a_kind = (kind == BlockKind::ik ? "an " : "a ") + d.kname;
  d.a_other = (kind == BlockKind::ik ? "a " : "an ") + d.other_kname;
  d.infos = params(kind, d.ctx);  // the default family's units until the block's problem family is known
  d.other = params(other_kind, d.ctx);
  for (const auto& i : d.infos) d.param_names.push_back(i.name);
  return true;
}

std::vector<std::string> with_placement(std::vector<std::string> names, const BlockDraft& d) {
  if (d.kind != BlockKind::trajectory) return names;
  for (std::string& n : placement_names(d.ctx.robot))
    if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(std::move(n));
  return names;
}

void Parser::check_block_keys(const BlockDraft& d) {
  std::vector<std::string> block_keys{"name", "kind", "axes", "zip", "lhs", "saltelli"};
  if (d.optimize)
    for (const char* k : {"variables", "objective", "reference", "trade_off", "global", "local", "polish_from", "seed",
                          "constraint", "penalty"})
      block_keys.push_back(k);
  for (const auto& n : d.param_names) block_keys.push_back(n);
  if (d.kind == BlockKind::trajectory) block_keys.push_back("vertex_alpha");
  for (auto&& [k, n] : ordered(d.table)) {
    const std::string key(k->str());
    if (std::find(block_keys.begin(), block_keys.end(), key) != block_keys.end()) continue;
    if (d.kind == BlockKind::trajectory)
      if (const std::string why = placement_refusal(key, d.ctx.robot); !why.empty()) {
        error(*k, why);
        continue;
      }
    if (d.belongs_to_other(key))
      error(*k, "parameter '" + key + "' does not belong to " + d.a_kind + " block (it is " + d.a_other +
                    " parameter); expected " + d.a_kind + " parameter: " + join(d.param_names));
    else
      error(*k, "unknown key '" + key + "' in " + d.kname + " block '" + d.spec.name +
                    "'; expected name, kind, axes, zip, lhs, saltelli" +
                    (d.kind == BlockKind::trajectory ? ", vertex_alpha" : "") + " or " + d.a_kind +
                    " parameter: " + join(d.param_names) + suggest_either(key, with_placement(block_keys, d), d.other, d.other_kname));
  }
}

void Parser::find_axes_table(BlockDraft& d) {
  if (const toml::node* an = d.table.get("axes")) {
    d.axes_t = an->as_table();
    if (!d.axes_t) error(*an, "axes is " + type_name(*an) + "; expected a table [block.axes] of parameter = values");
  }
  if (d.axes_t)
    for (auto&& [k, n] : *d.axes_t) {
      d.axis_names.insert(std::string(k.str()));
      d.axis_keys.emplace(std::string(k.str()), pos_of(k.source()));
    }
}

// q0_3's unit depends on the family: it is read from the fixed problem or the problem axis.
void Parser::read_ik_family(BlockDraft& d) {
  if (d.kind != BlockKind::ik) return;
  std::vector<std::pair<std::string, const toml::node*>> probs;
  if (const toml::node* p = d.table.get("problem"); p && p->as_string()) probs.emplace_back(p->as_string()->get(), p);
  if (d.axes_t)
    if (const toml::node* p = d.axes_t->get("problem")) {
      const toml::array* a = p->as_array();
      if (!a && p->as_table()) {
        if (const toml::node* vv = p->as_table()->get("values")) a = vv->as_array();
      }
      if (a)
        for (const auto& e : *a)
          if (e.as_string()) probs.emplace_back(e.as_string()->get(), &e);
    }
  if (!probs.empty()) {
    d.scara = ik_problem_is_scara(probs.front().first);
    for (const auto& [p, node] : probs)
      if (ik_problem_is_scara(p) != d.scara) {
        note(error(*node, "problem '" + p + "' mixes the SCARA (mm) with the arm's (m, deg) problems in one "
                          "block; expected separate blocks for scara and the other problems"),
             pos_of(probs.front().second->source()),
             "the block's first problem, '" + probs.front().first + "', is " +
                 (d.scara ? "the SCARA problem (mm)" : "an arm problem (m, deg)"));
        break;
      }
  }
  d.ctx.scara = d.scara;
  d.infos = params(d.kind, d.ctx);
}

void Parser::read_fixed_params(BlockDraft& d) {
  const toml::table& b = d.table;
  const std::size_t nverts = d.nverts;
  for (auto&& [k, n] : ordered(b)) {
    const std::string key(k->str());
    if (key == "vertex_alpha" && d.kind == BlockKind::trajectory) {
      if (!d.info_of("vertex_alpha_2")) {  // the robot or task has no vertex_alpha_i parameters
        const RobotShape& r = d.ctx.robot;
        error(*k, std::string("vertex_alpha = [...] sets the tip angle at vertices 2.." + std::to_string(nverts) +
                              " (vertex_alpha_2 ..), parameters of the seed's non-redundant vertex_alpha method, "
                              "defined for a planar 3-joint arm on a position path, not for ") +
                      (!r.planar             ? "a spatial robot"
                       : r.pose_task         ? "an orientation path"
                                             : "a planar arm of " + std::to_string(r.joints) + " joints") +
                      "; expected no vertex_alpha (the local methods take no vertex angles)");
        continue;
      }
      const auto* a = n->as_array();
      if (!a || a->size() + 1 != nverts) {
        error(*n, "vertex_alpha is " + (a ? "an array of " + std::to_string(a->size()) : type_name(*n)) +
                      "; expected an array of " + std::to_string(nverts - 1) + " angles [deg] (vertices 2.." +
                      std::to_string(nverts) + ")");
        continue;
      }
      for (std::size_t i = 0; i < a->size(); ++i) {
        const std::string pname = "vertex_alpha_" + std::to_string(i + 2);
        if (b.get(pname) || d.axis_names.count(pname)) {
          auto& diag = error(*k, "vertex_alpha and " + pname + " both given; expected one or the other");
          if (auto it = b.find(pname); it != b.end()) note(diag, pos_of(it->first.source()), pname + " given here");
          else note(diag, d.axis_keys.at(pname), pname + " is an axis here");
          note(diag, Pos{0, 0}, "vertex_alpha = [...] is shorthand for vertex_alpha_2 .. vertex_alpha_" +
                                    std::to_string(nverts));
          continue;
        }
        if (const ParamDef* info = d.info_of(pname))
          if (auto c = param_value(*info, *a->get(i))) d.spec.fixed.emplace_back(pname, *c);
      }
      continue;
    }
    const ParamDef* info = d.info_of(key);
    if (!info) continue;
    if (d.axis_names.count(key)) {
      note(error(*k, "'" + key + "' is both a fixed parameter and an axis; expected one or the other"),
           d.axis_keys.at(key), "'" + key + "' is an axis here");
      continue;
    }
    if (auto c = param_value(*info, *n)) d.spec.fixed.emplace_back(key, *c);
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
    s.blocks.push_back(std::move(*block));
  }
}

void Parser::check_robot_supports(const BlockDraft& d, const Study& s) {
  if (d.kind != BlockKind::trajectory || !s.chain) return;
  const RobotShape& r = d.ctx.robot;
  const int m = (r.planar ? 2 : 3) + (s.task.orientation.empty() ? 0 : 1) + (s.task.hold_orientation ? 3 : 0);
  // a spatial arm may have no redundancy (J qdd = b); a planar arm's start fixes its tip angle too
  if (m > r.joints || (r.planar && m == r.joints)) {
    error(d.pos, d.label + " follows a path of " + std::to_string(m) + " task equations with a robot of " +
                     std::to_string(r.joints) + " joints; expected " +
                     (r.planar ? "a planar robot with more joints than task equations (its start fixes the tip angle too)"
                               : "a robot with at least as many joints as task equations") +
                     ", or a position task");
    return;
  }
  // global_spline on a chain: revolute joints, a position path; cubic splines from a local or random
  // start (the vertex family and start are the seed's 3R's)
  bool prismatic = false;
  for (int j = 0; j < r.joints; ++j) prismatic = prismatic || r.is_prismatic(j);
  const char* global_why = m == r.joints ? "a robot without redundancy (as many joints as task equations)"
                           : r.pose_task || s.task.hold_orientation ? "an orientation path"
                           : prismatic ? "prismatic joints" : nullptr;
  const auto refuse_global = [&](const std::string& key, const std::string& value, const std::string& why,
                                 const auto& at, bool axis) {
    error(at, key + " = \"" + value + "\" " + why + (axis ? " (the " + key + " axis includes it)" : "") + "; expected " +
                  (key == "method" ? "local_weighted or local_unweighted" : key == "spline" ? "cubic" : "local or random"));
  };
  const auto check_global = [&](const std::string& key, const std::string& value, const auto& at, bool axis) {
    if (key == "method" && value == "global_spline" && global_why) {
      refuse_global(key, value, std::string("is the path-global method of arms of revolute joints on a position path, not of ") + global_why, at, axis);
      return true;
    }
    if ((key == "spline" && value == "vertex_quintic") || (key == "global_start" && value == "vertex")) {
      refuse_global(key, value, "is the seed's vertex family, defined for its closed-form 3R arm, not for a chain robot", at, axis);
      return true;
    }
    return false;
  };
  for (const auto& [name, v] : d.spec.fixed)
    if (const std::string* t = std::get_if<std::string>(&v); t && check_global(name, *t, d.table.get(name)->source(), false)) return;
  for (const AxisDraft& a : d.drafts)
    for (const auto& v : a.axis.values)
      if (const std::string* t = std::get_if<std::string>(&v); t && check_global(a.axis.name, *t, a.pos, true)) return;
  if (r.vertex_alpha()) return;
  // vertex_alpha: named by method (fixed or axis) or by a preset of cases 3-5
  auto uses = [&](const std::string& name, const Cell& v) {
    const std::string* t = std::get_if<std::string>(&v);
    if (!t) return false;
    if (name == "method") return *t == "vertex_alpha";
    if (name == "preset")
      if (const SeedCase* c = find_seed_case(*t)) return c->method == TrajectoryMethod::vertex_alpha;
    return false;
  };
  const char* why = !r.planar ? "a spatial robot" : r.pose_task ? "an orientation path" : "a planar arm of more than 3 joints";
  const std::string reason = std::string("vertex_alpha prescribes the tip angle at the vertices: the seed's "
                                         "non-redundant baseline, defined for a planar 3-joint arm on a position path, "
                                         "not for ") + why;
  for (const auto& [name, v] : d.spec.fixed)
    if (uses(name, v)) {
      error(d.table.get(name)->source(), reason + "; expected local_weighted or local_unweighted");
      return;
    }
  for (const AxisDraft& a : d.drafts)
    for (const auto& v : a.axis.values)
      if (uses(a.axis.name, v)) {
        error(a.pos, reason + " (the " + a.axis.name + " axis includes it); expected local methods only");
        return;
      }
}

void Parser::check_motion_world(const BlockDraft& d, const Study& s) {
  if (d.kind != BlockKind::motion || s.world.has_obstacles()) return;
  const auto positive = [](const Cell& v) {
    const double* x = std::get_if<double>(&v);
    return x && *x > 0.0;
  };
  const std::string why = "w_clearance weighs the least clearance from the [world] obstacles, and the study has none; "
                          "expected w_clearance = 0, or [world] obstacles with link_radius";
  for (const auto& [name, v] : d.spec.fixed)
    if (name == "w_clearance" && positive(v)) {
      error(d.table.get(name)->source(), why);
      return;
    }
  for (const AxisDraft& a : d.drafts)
    if (a.axis.name == "w_clearance" && std::any_of(a.axis.values.begin(), a.axis.values.end(), positive)) {
      error(a.pos, why + " (the w_clearance axis has a positive value)");
      return;
    }
}

}  // namespace ks::study_parse
