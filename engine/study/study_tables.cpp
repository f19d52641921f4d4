// The study-wide tables: [study] (name, output, histories, max_runs) and [task] (the path); [robot] is
// in robot_table.cpp.
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>

#include "study/parser.hpp"

namespace ks::study_parse {

void Parser::parse_study_table(const toml::table& root, Study& s) {
  std::string stem = std::filesystem::path(file_).stem().string();
  if (stem.empty() || stem.front() == '<') stem = "study";
  s.name = stem;
  max_runs_ = options_.max_runs;
  const toml::node* n = root.get("study");
  if (!n) {
    s.output = "results/" + s.name + ".h5";
    return;
  }
  const auto* t = n->as_table();
  if (!t) {
    error(*n, "'study' is " + type_name(*n) + "; expected a [study] table");
    return;
  }
  check_keys(*t, {"name", "description", "output", "histories", "max_runs"}, "[study]");
  if (auto v = get_string(*t, "name", "study name")) {
    if (v->empty()) error(*t->get("name"), "study name is empty; expected a non-empty name");
    else s.name = *v;
  }
  if (auto v = get_string(*t, "description", "description")) s.description = *v;
  s.output = "results/" + s.name + ".h5";
  if (auto v = get_string(*t, "output", "output")) {
    const bool hdf5 = v->ends_with(".h5") || v->ends_with(".hdf5");
    if (v->empty()) error(*t->get("output"), "output is empty; expected a file path");
    else if (const auto c = std::find_if(v->begin(), v->end(), [](unsigned char ch) { return ch < 0x20 || ch == 0x7f; });
             c != v->end())
      error(*t->get("output"), std::string("output contains ") + (*c == '\0' ? "a NUL" : "a control") +
                                   " character; expected a file path without control characters");
    else if (!hdf5)
      error(*t->get("output"), "output '" + *v + "': a results file is HDF5; expected a name ending in .h5 (or .hdf5)");
    else s.output = *v;
  }
  if (auto v = get_string(*t, "histories", "histories")) {
    bool ok = true;
    if (*v == "full") s.histories = {HistoryPolicy::Mode::full, 1};
    else if (*v == "none") s.histories = {HistoryPolicy::Mode::none, 0};
    else if (v->starts_with("every=")) {
      const std::string num = v->substr(6);
      ok = !num.empty() && num.size() < 10 && std::all_of(num.begin(), num.end(), ::isdigit) && std::stoll(num) >= 1;
      if (ok) s.histories = {HistoryPolicy::Mode::every, int(std::stoll(num))};
    } else ok = false;
    if (!ok && v->starts_with("every="))
      error(*t->get("histories"), "histories = '" + *v + "' does not give a whole N >= 1; expected \"every=N\" "
                                      "with N >= 1 (every=1 keeps every sample, as \"full\"), \"full\" or \"none\"");
    else if (!ok)
      error(*t->get("histories"), "histories = '" + *v + "'; expected \"full\", \"every=N\" (N >= 1) or \"none\"" +
                                      suggest(*v, {"full", "none",
                                                   "every=" + (v->find('=') == std::string::npos
                                                                   ? std::string("N")
                                                                   : v->substr(v->find('=') + 1))}));
  }
  if (const toml::node* m = t->get("max_runs")) {
    if (auto v = get_integer(*m, "max_runs")) {
      if (*v < 1) error(*m, "max_runs = " + std::to_string(*v) + "; expected max_runs >= 1");
      else if (std::uint64_t(*v) > options_.max_runs)
        error(*m, "max_runs = " + std::to_string(*v) + " is above the caller's limit of " +
                      std::to_string(options_.max_runs) + " runs; expected at most " +
                      std::to_string(options_.max_runs) +
                      " (a study may only lower the limit; kinesweep run --max-runs N raises it)");
      else max_runs_ = std::uint64_t(*v);
    }
  }
}

void Parser::parse_task(const toml::table& root, Study& s) {
  const Path2 sq = seed_square();
  s.task.vertices = sq.vertices();
  s.task.durations = sq.durations();
  const toml::node* n = root.get("task");
  if (!n) return;
  const auto* t = n->as_table();
  if (!t) {
    error(*n, "'task' is " + type_name(*n) + "; expected a [task] table");
    return;
  }
  check_keys(*t, {"vertices", "durations", "waypoints", "spline", "dt", "integrator", "orientation"}, "[task]");
  const bool spatial = s.chain && !s.chain->planar();
  const std::size_t dims = spatial ? 3 : 2;
  const std::string point = spatial ? "[x, y, z]" : "[x, y] (plane coordinates) or [x, y, z] (base frame, on the plane)";
  bool vertices_ok = true;
  // the path: timed waypoints joined by a spline, or vertices and durations joined by quintics
  const toml::node* wn = t->get("waypoints");
  if (wn) {
    for (const char* key : {"vertices", "durations"})
      if (const toml::node* k = t->get(key))
        error(*k, std::string(key) + " given with waypoints; expected either waypoints = [[t, x, y], ...] (a spline "
                                     "through timed waypoints) or vertices and durations (quintics), not both");
    vertices_ok = parse_task_waypoints(*t, s);
  } else if (const toml::node* sn = t->get("spline")) {
    error(*sn, "spline given without waypoints; expected [task] waypoints = [[t, x, y], ...] with it (a spline "
               "joins timed waypoints; vertices and durations are joined by rest-to-rest quintics)");
  }
  if (const toml::node* vn = wn ? nullptr : t->get("vertices")) {
    const auto* a = vn->as_array();
    if (!a || a->size() < 2) {
      error(*vn, "vertices is " + (a ? "an array of " + std::to_string(a->size()) : type_name(*vn)) +
                     "; expected an array of at least 2 " + point + " points [m]");
      vertices_ok = false;
    } else {
      std::vector<Eigen::Vector2d> v;
      std::vector<double> z;
      for (const auto& e : *a) {
        const auto* p = e.as_array();
        const bool base_point = !spatial && s.plane && p && p->size() == 3;  // a planar robot's vertex, base frame
        if (!p || (p->size() != dims && !base_point)) {
          error(e, "a vertex is " + (p ? "an array of " + std::to_string(p->size()) : type_name(e)) + "; expected " +
                       point + " [m]" + (spatial ? " (the robot is spatial)" : ""));
          vertices_ok = false;
          continue;
        }
        auto x = get_number(*p->get(0), "vertex x");
        auto y = get_number(*p->get(1), "vertex y");
        std::optional<double> zz = spatial || base_point ? get_number(*p->get(2), "vertex z") : std::optional<double>(0.0);
        if (x && y && zz && base_point) {
          if (const auto u = vertex_in_plane(e, {*x, *y, *zz}, *s.plane)) v.push_back(*u), z.push_back(0.0);
          else vertices_ok = false;
        } else if (x && y && zz) {
          v.emplace_back(*x, *y), z.push_back(*zz);
        } else {
          vertices_ok = false;
        }
      }
      s.task.vertices = v;
      if (spatial) s.task.z = z;
      if (!t->get("durations") && vertices_ok && v.size() != 5) {
        error(*vn, "vertices given without durations; expected durations = [...] (" + std::to_string(v.size() - 1) +
                       " segment durations [s])");
        vertices_ok = false;
      }
    }
  }
  if (const toml::node* dn = wn ? nullptr : t->get("durations")) {
    const auto* a = dn->as_array();
    if (!a) error(*dn, "durations is " + type_name(*dn) + "; expected an array of segment durations [s]");
    else {
      std::vector<double> d;
      bool ok = true;
      for (const auto& e : *a) {
        auto x = get_number(e, "duration");
        if (!x) ok = false;
        else if (*x <= 0) {
          error(e, "duration = " + fmt(*x) + "; expected a duration > 0 [s]");
          ok = false;
        } else d.push_back(*x);
      }
      if (ok && vertices_ok && d.size() + 1 != s.task.vertices.size())
        error(*dn, "durations has " + std::to_string(d.size()) + " values; expected " +
                       std::to_string(s.task.vertices.size() - 1) + " (one per segment between the " +
                       std::to_string(s.task.vertices.size()) + " vertices)");
      s.task.durations = d;
    }
  }
  if (!s.task.durations.empty()) {
    path_duration_ = 0;
    for (double d : s.task.durations) path_duration_ += d;
  }
  path_pos_ = pos_of((wn                    ? wn
                      : t->get("durations") ? t->get("durations")
                                            : static_cast<const toml::node*>(t))
                         ->source());
  if (t->get("dt")) task_dt_pos_ = pos_of(t->get("dt")->source());
  if (auto v = get_number(*t, "dt", "dt")) {
    if (auto p = domain_problem(*find_param(block_params(BlockKind::trajectory), "dt"), *v); !p.empty()) error(*t->get("dt"), p + " [s]");
    else s.task.dt = *v;
  }
  if (vertices_ok) parse_task_orientation(*t, s);
  if (auto v = get_string(*t, "integrator", "integrator")) {
    if (!parse(*v, s.task.integrator))
      error(*t->get("integrator"), "unknown integrator '" + *v + "'; expected one of " +
                                       join(integrator_names()) + suggest(*v, integrator_names()));
  }
}

void Parser::parse_task_orientation(const toml::table& t, Study& s) {
  const toml::node* n = t.get("orientation");
  if (!n) return;
  if (!s.chain) {
    error(*n, "an orientation path on the seed's closed-form 3R leaves no redundancy; expected a robot with more "
              "joints (l = [...] with 4 or more links, or a URDF robot) for a pose task");
    return;
  }
  if (!s.chain->planar()) {
    if (auto v = n->as_string(); v && v->get() == "hold") s.task.hold_orientation = true;
    else error(*n, "orientation of a spatial robot's path is " + type_name(*n) +
                       "; expected \"hold\" (the start's tip orientation held along the path)");
    return;
  }
  const auto* a = n->as_array();
  if (!a || a->size() != s.task.vertices.size()) {
    error(*n, "orientation is " + (a ? "an array of " + std::to_string(a->size()) : type_name(*n)) + "; expected " +
                  std::to_string(s.task.vertices.size()) + " tip angles [deg], one per " +
                  (s.task.shape == PathShape::quintic ? "vertex" : "waypoint"));
    return;
  }
  std::vector<double> o;
  for (const auto& e : *a)
    if (auto x = get_number(e, "orientation")) o.push_back(*x * kDeg);
  if (o.size() == a->size()) s.task.orientation = o;
}

namespace {

/// A sound bound on how far the tip gets from the first joint: no configuration puts it farther.
struct Reach {
  double bound = 0.0;            ///< [m]; infinite with an unlimited prismatic joint
  Eigen::Vector3d centre;        ///< the first joint's origin (base frame)
  bool in_plane = false;         ///< measured in the base xy plane (from the first joint's axis)
  /// in the plane, revolute joints only: no configuration puts the tip closer than this [m] (0 when
  /// unknown); the links' lengths l_i (the offsets' xy parts, each turned freely by a joint before it)
  /// give max(0, 2 max l_i - sum l_i), limits only keep the tip farther
  double inner = 0.0;
  double longest = 0.0;          ///< the longest l_i [m] (for the message)
};

/// Every joint turns about (or slides across) the base z axis: each origin maps z to +-z and each
/// revolute axis is +-z, so the xy projection of every offset keeps its length in any configuration.
bool moves_in_xy(const Chain& c) {
  const auto along_z = [](const Eigen::Vector3d& v) { return std::abs(std::abs(v.z()) - v.norm()) <= 1e-12 * v.norm(); };
  for (const ChainJoint& j : c.joints)
    if (!along_z(j.origin.R.col(2)) || (j.type == JointType::revolute && !along_z(j.axis))) return false;
  return along_z(c.tip.R.col(2));
}

/// The distance from the first joint to the tip is at most the sum of the frame offsets from the first
/// joint to the tip and of the prismatic travels (the triangle inequality); in the plane, of their xy parts.
Reach reach_of(const Chain& c, bool in_plane) {
  Reach r;
  r.in_plane = in_plane;
  r.centre = c.joints.front().origin.p;
  const auto length = [&](const Eigen::Vector3d& p) { return in_plane ? p.head<2>().norm() : p.norm(); };
  r.bound = length(c.tip.p);
  r.longest = r.bound;
  bool revolute = true;
  for (int j = 0; j < c.dof(); ++j) {
    if (j > 0) r.bound += length(c.joints[j].origin.p), r.longest = std::max(r.longest, length(c.joints[j].origin.p));
    if (c.joints[j].type == JointType::prismatic)
      r.bound += std::max(std::abs(c.joints[j].lower), std::abs(c.joints[j].upper)), revolute = false;
  }
  if (in_plane && revolute) r.inner = std::max(0.0, 2.0 * r.longest - r.bound);
  return r;
}

}  // namespace

void Parser::check_task_fits_robot(const toml::table* task, Study& s) {
  const std::shared_ptr<const Chain> chain = s.robot_chain();  // the seed's 3R as its planar chain too
  if (!chain || chain->dof() == 0) return;
  const bool spatial = s.chain && !s.chain->planar();
  // a planar task's points are (x, y) in the base frame: bounded in the plane only for a chain moving in it
  if (!spatial && !moves_in_xy(*chain)) return;
  const Reach reach = reach_of(*chain, !spatial);
  if (!std::isfinite(reach.bound)) return;
  const std::string bound = fmt(reach.bound) + " m, the sum of the offsets between successive joints from the first "
                            "joint to the tip" + std::string(reach.in_plane ? " in the plane of motion" : "") +
                            (std::any_of(chain->joints.begin(), chain->joints.end(),
                                         [](const ChainJoint& j) { return j.type == JointType::prismatic; })
                                 ? " plus the prismatic travels"
                                 : "");
  const std::string from = reach.in_plane ? "the first joint's axis" : "the first joint";
  const bool waypoints = task && task->get("waypoints");
  const toml::node* vn = task ? task->get(waypoints ? "waypoints" : "vertices") : nullptr;
  const std::string word = waypoints ? "waypoint " : "vertex ";
  for (std::size_t i = 0; i < s.task.vertices.size(); ++i) {
    Eigen::Vector3d v = s.task.vertex(i) - reach.centre;
    if (reach.in_plane) v.z() = 0.0;
    const double d = v.norm();
    const toml::node* at = vn && vn->as_array() ? vn->as_array()->get(i) : nullptr;
    if (d < reach.inner * (1 - 1e-12)) {
      const std::string hole = fmt(reach.inner) + " m: twice the longest link, " + fmt(reach.longest) +
                               " m, minus the sum of the links, " + fmt(reach.bound) + " m, in the plane of motion";
      error(at ? pos_of(at->source()) : vn ? pos_of(vn->source()) : task ? pos_of(task->source()) : Pos{1, 1},
            word + std::to_string(i + 1) + (at ? "" : " of the default path (the seed's square)") + " is " + fmt(d) +
                " m from " + from + ", inside the disc the robot cannot reach (no tip position closer than " + hole +
                "); expected [task] vertices at least " + fmt(reach.inner) + " m from " + from);
      if (!at) return;
      continue;
    }
    if (d <= reach.bound * (1 + 1e-12)) continue;
    if (at) {
      error(*at, word + std::to_string(i + 1) + " is " + fmt(d) + " m from " + from +
                     ", beyond the robot's reach (at most " + bound + "); expected a " + word + "within " + fmt(reach.bound) +
                     " m of " + from);
    } else {
      error(vn ? pos_of(vn->source()) : task ? pos_of(task->source()) : Pos{1, 1},
            "vertex " + std::to_string(i + 1) + " of the default path (the seed's square) is " + fmt(d) + " m from " +
                from + ", beyond the robot's reach (at most " + bound + "); expected [task] vertices within " +
                fmt(reach.bound) + " m of " + from);
      return;  // one message for the default path
    }
  }
}

}  // namespace ks::study_parse
