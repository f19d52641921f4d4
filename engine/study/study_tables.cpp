// The study-wide tables: [study] (name, output, histories, max_runs), [robot] (the arm), [task] (the path).
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
    if (v->empty()) error(*t->get("output"), "output is empty; expected a file path");
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
    if (!ok)
      error(*t->get("histories"), "histories = '" + *v + "'; expected \"full\", \"every=N\" (N >= 1) or \"none\"" +
                                      suggest(*v, {"full", "none",
                                                   "every=" + (v->find('=') == std::string::npos
                                                                   ? std::string("N")
                                                                   : v->substr(v->find('=') + 1))}));
  }
  if (const toml::node* m = t->get("max_runs")) {
    if (auto v = get_integer(*m, "max_runs")) {
      if (*v < 1) error(*m, "max_runs = " + std::to_string(*v) + "; expected max_runs >= 1");
      else max_runs_ = std::uint64_t(*v);
    }
  }
}

void Parser::parse_robot(const toml::table& root, Study& s) {
  std::array<double, 3> l{1, 1, 1}, m{5, 2, 1};
  double b = 0.1, g = 9.81;
  InertiaForm form = InertiaForm::physical;
  if (const toml::node* n = root.get("robot")) {
    if (const auto* t = n->as_table()) {
      check_keys(*t, {"l", "m", "b", "g", "inertia"}, "[robot]");
      if (auto v = get_numbers(*t, "l", 3, "robot l")) {
        for (std::size_t i = 0; i < 3; ++i) l[i] = (*v)[i];
        if (*std::min_element(v->begin(), v->end()) <= 0)
          error(*t->get("l"), "a link length is <= 0; expected lengths > 0 [m]");
      }
      if (auto v = get_numbers(*t, "m", 3, "robot m")) {
        for (std::size_t i = 0; i < 3; ++i) m[i] = (*v)[i];
        if (*std::min_element(v->begin(), v->end()) <= 0)
          error(*t->get("m"), "a link mass is <= 0; expected masses > 0 [kg]");
      }
      if (auto v = get_number(*t, "b", "robot b")) {
        if (*v < 0) error(*t->get("b"), "b = " + fmt(*v) + "; expected b >= 0 [m]");
        else b = *v;
      }
      if (auto v = get_number(*t, "g", "robot g")) g = *v;
      if (auto v = get_string(*t, "inertia", "inertia")) {
        if (!parse(*v, form))
          error(*t->get("inertia"), "unknown inertia '" + *v + "'; expected one of " +
                                        join(inertia_names()) + suggest(*v, inertia_names()));
      }
    } else {
      error(*n, "'robot' is " + type_name(*n) + "; expected a [robot] table");
    }
  }
  s.robot = PlanarArm3::bars(l, m, b, g);
  s.robot.inertia_form = form;
  s.robot_b = b;
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
  check_keys(*t, {"vertices", "durations", "dt", "integrator"}, "[task]");
  bool vertices_ok = true;
  if (const toml::node* vn = t->get("vertices")) {
    const auto* a = vn->as_array();
    if (!a || a->size() < 2) {
      error(*vn, "vertices is " + (a ? "an array of " + std::to_string(a->size()) : type_name(*vn)) +
                     "; expected an array of at least 2 [x, y] points [m]");
      vertices_ok = false;
    } else {
      std::vector<Eigen::Vector2d> v;
      for (const auto& e : *a) {
        const auto* p = e.as_array();
        if (!p || p->size() != 2) {
          error(e, "a vertex is " + (p ? "an array of " + std::to_string(p->size()) : type_name(e)) +
                       "; expected [x, y] [m]");
          vertices_ok = false;
          continue;
        }
        auto x = get_number(*p->get(0), "vertex x");
        auto y = get_number(*p->get(1), "vertex y");
        if (x && y) v.emplace_back(*x, *y);
        else vertices_ok = false;
      }
      s.task.vertices = v;
      if (!t->get("durations") && vertices_ok && v.size() != 5) {
        error(*vn, "vertices given without durations; expected durations = [...] (" + std::to_string(v.size() - 1) +
                       " segment durations [s])");
        vertices_ok = false;
      }
    }
  }
  if (const toml::node* dn = t->get("durations")) {
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
  if (auto v = get_number(*t, "dt", "dt")) {
    if (auto p = domain_problem(*find_param(block_params(BlockKind::trajectory), "dt"), *v); !p.empty()) error(*t->get("dt"), p + " [s]");
    else s.task.dt = *v;
  }
  if (auto v = get_string(*t, "integrator", "integrator")) {
    if (!parse(*v, s.task.integrator))
      error(*t->get("integrator"), "unknown integrator '" + *v + "'; expected one of " +
                                       join(integrator_names()) + suggest(*v, integrator_names()));
  }
}

}  // namespace ks::study_parse
