// Study-file parser: TOML (toml++) -> validated Study. Collects every error it can, each located.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <toml++/toml.h>

#include "methods/seed_cases.hpp"
#include "study/sha256.hpp"
#include "study/study.hpp"

namespace ks {

// ---------------------------------------------------------------------------------------------------
std::string StudyDiagnostic::str() const {
  return file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": error: " + message;
}

namespace {
std::string join_diagnostics(const std::vector<StudyDiagnostic>& d) {
  std::string s;
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (i) s += '\n';
    s += d[i].str();
  }
  return s;
}
}  // namespace

StudyError::StudyError(std::vector<StudyDiagnostic> diagnostics)
    : std::runtime_error(join_diagnostics(diagnostics)), diagnostics_(std::move(diagnostics)) {}

std::string HistoryPolicy::str() const {
  switch (mode) {
    case Mode::full: return "full";
    case Mode::none: return "none";
    case Mode::every: return "every=" + std::to_string(stride);
  }
  return "?";
}

std::size_t Study::block_index(std::string_view n) const {
  for (std::size_t i = 0; i < blocks.size(); ++i)
    if (blocks[i].name() == n) return i;
  return Block::npos;
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;

std::string lower(std::string_view s) {
  std::string o(s);
  for (char& c : o) c = char(std::tolower(static_cast<unsigned char>(c)));
  return o;
}

/// "; did you mean 'x'?" for the closest candidate (case-insensitive edit distance), or "".
std::string suggest(std::string_view word, const std::vector<std::string>& candidates) {
  std::size_t best = std::string::npos;
  std::string pick;
  for (const auto& c : candidates) {
    const std::size_t d = edit_distance(lower(word), lower(c));
    if (d < best) {
      best = d;
      pick = c;
    }
  }
  if (pick.empty() || best > std::max<std::size_t>(2, word.size() / 2)) return "";
  return "; did you mean '" + pick + "'?";
}

/// A suggestion among `mine`, else among the other kind's parameters (saying so).
std::string suggest_either(std::string_view word, const std::vector<std::string>& mine,
                           const std::vector<ParamInfo>& other, const std::string& other_kind) {
  if (auto s = suggest(word, mine); !s.empty()) return s;
  std::vector<std::string> names;
  for (const auto& i : other) names.push_back(i.name);
  auto s = suggest(word, names);
  if (s.empty()) return s;
  s.pop_back();  // '?'
  return s + " (" + (other_kind == "ik" ? "an " : "a ") + other_kind + " parameter, not allowed here)?";
}

std::string join(const std::vector<std::string>& v, std::string_view sep = ", ") {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) s += sep;
    s += v[i];
  }
  return s;
}
const std::vector<std::string>& to_strings(const std::vector<std::string>& v) { return v; }
std::vector<std::string> to_strings(std::span<const std::string_view> v) {
  return std::vector<std::string>(v.begin(), v.end());
}

std::string type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::array: return "an array";
    case toml::node_type::table: return "a table";
    default: return "a date/time";
  }
}

std::string fmt(double v) {
  std::ostringstream o;
  o.precision(12);
  o << v;
  return o.str();
}

struct Pos {
  int line = 1, column = 1;
};
Pos pos_of(const toml::source_region& r) {
  Pos p;
  if (r.begin.line > 0) p.line = int(r.begin.line);
  if (r.begin.column > 0) p.column = int(r.begin.column);
  return p;
}

/// A table's entries in file order (toml++ tables iterate by key).
std::vector<std::pair<const toml::key*, const toml::node*>> ordered(const toml::table& t) {
  std::vector<std::pair<const toml::key*, const toml::node*>> v;
  for (auto&& [k, n] : t) v.emplace_back(&k, &n);
  std::stable_sort(v.begin(), v.end(), [](const auto& a, const auto& b) {
    const auto& ra = a.first->source().begin;
    const auto& rb = b.first->source().begin;
    return std::pair(ra.line, ra.column) < std::pair(rb.line, rb.column);
  });
  return v;
}

struct AxisDraft {
  Axis axis;
  Pos pos;                                   // the axis key
  bool lhs = false;
  std::pair<double, double> lhs_range{0, 0};  // LHS axes: [from, to) in file units
};

// ---------------------------------------------------------------------------------------------------
class Parser {
 public:
  Parser(std::string file, StudyOptions options) : file_(std::move(file)), options_(options) {}

  Study run(std::string_view text);

 private:
  void error(const toml::source_region& r, std::string msg) { error(pos_of(r), std::move(msg)); }
  void error(Pos p, std::string msg) { diags_.push_back({file_, p.line, p.column, std::move(msg)}); }
  void error(const toml::node& n, std::string msg) { error(n.source(), std::move(msg)); }
  void error(const toml::key& k, std::string msg) { error(k.source(), std::move(msg)); }

  /// Report keys of `t` not in `allowed` (with a suggestion).
  void check_keys(const toml::table& t, const std::vector<std::string>& allowed, std::string_view where);

  // Typed reads: the value, or nullopt (with an error when present but wrong).
  std::optional<std::string> get_string(const toml::table& t, std::string_view key, std::string_view what);
  std::optional<double> get_number(const toml::node& n, std::string_view what);
  std::optional<double> get_number(const toml::table& t, std::string_view key, std::string_view what);
  std::optional<std::int64_t> get_integer(const toml::node& n, std::string_view what);
  std::optional<std::vector<double>> get_numbers(const toml::table& t, std::string_view key, std::size_t count,
                                                 std::string_view what);

  void parse_study_table(const toml::table& root, Study& s);
  void parse_robot(const toml::table& root, Study& s);
  void parse_task(const toml::table& root, Study& s);
  void parse_blocks(const toml::table& root, Study& s);
  std::optional<Block> parse_block(const toml::table& b, std::size_t index, const Study& s,
                                   std::map<std::string, Pos>& names, bool optimize = false);
  // [[optimize]] tables (issue 6): a block (parse_block with optimize = true) + the optimisation keys.
  void parse_optimizations(const toml::table& root, Study& s);
  std::optional<opt::StageOptions> parse_stage(const toml::node& n, bool global, OptimizeBlock& ob);

  /// One axis of [block.axes] (its values in stored units; LHS axes get their values later).
  std::optional<AxisDraft> parse_axis(const ParamInfo& info, const toml::key& key, const toml::node& node, bool scara,
                                      const toml::node* lhs_node);
  /// A parameter value from a node: type + choices + unit conversion + domain. nullopt on error.
  std::optional<Cell> param_value(const ParamInfo& info, const toml::node& n, bool scara);
  /// Check a stored numeric value's domain (expects file units for messages). Empty when fine.
  std::string domain_problem(const std::string& name, double file_value);
  Cell convert(const ParamInfo& info, double file_value, bool scara) const;

  std::string file_;
  StudyOptions options_;
  std::vector<StudyDiagnostic> diags_;
  std::uint64_t max_runs_ = 0;
  double path_duration_ = 2.0;  // [s], the task's; bounds the samples a dt asks for
};

/// At most this many samples per trajectory run (the seed takes 2001): each thread keeps the sampled
/// path, and a full history holds 16 doubles per sample.
constexpr double kMaxSamples = 1e7;

void Parser::check_keys(const toml::table& t, const std::vector<std::string>& allowed, std::string_view where) {
  for (auto&& [k, n] : ordered(t)) {
    if (std::find(allowed.begin(), allowed.end(), k->str()) != allowed.end()) continue;
    error(*k, "unknown key '" + std::string(k->str()) + "' in " + std::string(where) + "; expected one of " +
                  join(allowed) + suggest(k->str(), allowed));
  }
}

std::optional<std::string> Parser::get_string(const toml::table& t, std::string_view key, std::string_view what) {
  const toml::node* n = t.get(key);
  if (!n) return std::nullopt;
  if (const auto* s = n->as_string()) return s->get();
  error(*n, std::string(what) + " is " + type_name(*n) + "; expected a string");
  return std::nullopt;
}

std::optional<double> Parser::get_number(const toml::node& n, std::string_view what) {
  double v;
  if (const auto* i = n.as_integer()) v = double(i->get());
  else if (const auto* f = n.as_floating_point()) v = f->get();
  else {
    error(n, std::string(what) + " is " + type_name(n) + "; expected a number");
    return std::nullopt;
  }
  if (!std::isfinite(v)) {
    error(n, std::string(what) + " is not finite; expected a finite number");
    return std::nullopt;
  }
  return v;
}

std::optional<double> Parser::get_number(const toml::table& t, std::string_view key, std::string_view what) {
  const toml::node* n = t.get(key);
  if (!n) return std::nullopt;
  return get_number(*n, what);
}

std::optional<std::int64_t> Parser::get_integer(const toml::node& n, std::string_view what) {
  if (const auto* i = n.as_integer()) return i->get();
  error(n, std::string(what) + " is " + type_name(n) + "; expected an integer");
  return std::nullopt;
}

std::optional<std::vector<double>> Parser::get_numbers(const toml::table& t, std::string_view key,
                                                       std::size_t count, std::string_view what) {
  const toml::node* n = t.get(key);
  if (!n) return std::nullopt;
  const auto* a = n->as_array();
  if (!a || a->size() != count) {
    error(*n, std::string(what) + " is " + (a ? "an array of " + std::to_string(a->size()) : type_name(*n)) +
                  "; expected an array of " + std::to_string(count) + " numbers");
    return std::nullopt;
  }
  std::vector<double> v;
  for (const auto& e : *a) {
    auto x = get_number(e, std::string(what) + " element");
    if (!x) return std::nullopt;
    v.push_back(*x);
  }
  return v;
}

// ---------------------------------------------------------------------------------------------------
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
                                        join(to_strings(inertia_names())) + suggest(*v, to_strings(inertia_names())));
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
    if (auto p = domain_problem("dt", *v); !p.empty()) error(*t->get("dt"), p + " [s]");
    else s.task.dt = *v;
  }
  if (auto v = get_string(*t, "integrator", "integrator")) {
    if (!parse(*v, s.task.integrator))
      error(*t->get("integrator"), "unknown integrator '" + *v + "'; expected one of " +
                                       join(to_strings(integrator_names())) + suggest(*v, to_strings(integrator_names())));
  }
}

// ---------------------------------------------------------------------------------------------------
std::string Parser::domain_problem(const std::string& name, double v) {
  if ((name == "dt" || name == "torque_bound" || name == "tol") && !(v > 0))
    return name + " = " + fmt(v) + "; expected " + name + " > 0";
  if (name == "dt" && path_duration_ / v + 1 > kMaxSamples)
    return "dt = " + fmt(v) + " gives " + fmt(std::floor(path_duration_ / v) + 1) + " samples on the " +
           fmt(path_duration_) + " s path; expected at most " + fmt(kMaxSamples) + " (dt >= " +
           fmt(path_duration_ / (kMaxSamples - 1)) + ")";
  if ((name == "lambda" || name == "K_N") && v < 0) return name + " = " + fmt(v) + "; expected " + name + " >= 0";
  if (name == "max_iter" && v < 1) return "max_iter = " + fmt(v) + "; expected max_iter >= 1";
  return "";
}

Cell Parser::convert(const ParamInfo& info, double v, bool scara) const {
  if (info.type == CellType::i64) return std::int64_t(std::llround(v));
  if (info.file_unit == FileUnit::deg || (info.name == "q0_3" && !scara)) return v * kDeg;
  return v;
}

std::optional<Cell> Parser::param_value(const ParamInfo& info, const toml::node& n, bool scara) {
  if (info.type == CellType::str) {
    const auto* s = n.as_string();
    if (!s) {
      error(n, info.name + " is " + type_name(n) + "; expected a string" +
                   (info.choices.empty() ? "" : " (one of " + join(to_strings(info.choices)) + ")"));
      return std::nullopt;
    }
    const std::string v = s->get();
    if (!info.choices.empty() && std::find(info.choices.begin(), info.choices.end(), v) == info.choices.end()) {
      error(n, "unknown " + info.name + " '" + v + "'; expected one of " + join(to_strings(info.choices)) +
                   suggest(v, to_strings(info.choices)));
      return std::nullopt;
    }
    return Cell(v);
  }
  if (info.type == CellType::i64) {
    auto v = get_integer(n, info.name);
    if (!v) return std::nullopt;
    if (auto p = domain_problem(info.name, double(*v)); !p.empty()) {
      error(n, p);
      return std::nullopt;
    }
    return Cell(*v);
  }
  auto v = get_number(n, info.name);
  if (!v) return std::nullopt;
  if (auto p = domain_problem(info.name, *v); !p.empty()) {
    error(n, p);
    return std::nullopt;
  }
  return convert(info, *v, scara);
}

// ---------------------------------------------------------------------------------------------------
std::optional<AxisDraft> Parser::parse_axis(const ParamInfo& info_ref, const toml::key& key_node, const toml::node& node,
                                          bool scara, const toml::node* lhs_node) {
  const ParamInfo* info = &info_ref;
  const toml::node* n = &node;
  const std::string key(key_node.str());
  AxisDraft d;
  d.axis.name = key;
  d.pos = pos_of(key_node.source());
  const std::string what = "axis '" + key + "'";
  const std::string forms =
      info->type == CellType::str
          ? "a list of names [\"a\", \"b\"] or { values = [...] }"
          : "a list [...], { values = [...] }, { from, to, step }, { from, to, count }, { random = { from, to, count, seed } } or { lhs = { from, to } }";
  const toml::array* list = n->as_array();
  const toml::table* t = n->as_table();
  if (t && t->get("values")) {
    check_keys(*t, {"values"}, what + " (a value list)");
    list = t->get("values")->as_array();
    if (!list) {
      error(*t->get("values"), what + " values is " + type_name(*t->get("values")) + "; expected an array");
      return std::nullopt;
    }
    t = nullptr;
  }
  bool ok = true;
  if (list) {
    d.axis.form = "values";
    if (list->empty()) {
      error(*n, what + " has an empty value list; expected at least one value");
      return std::nullopt;
    }
    for (const auto& e : *list) {
      auto c = param_value(*info, e, scara);
      if (!c) ok = false;
      else d.axis.values.push_back(std::move(*c));
    }
  } else if (t) {
    if (info->type == CellType::str) {
      error(*n, what + " is a numeric range but " + key + " is a name; expected " + forms);
      return std::nullopt;
    }
    const bool is_int = info->type == CellType::i64;
    auto gen_check = [&](const std::vector<double>& vals, const toml::node& at) {
      for (double v : vals) {
        if (is_int && std::abs(v - std::round(v)) > 1e-9 * std::max(1.0, std::abs(v))) {
          error(at, what + " yields " + fmt(v) + "; expected integer values for " + key);
          return false;
        }
        if (auto p = domain_problem(key, v); !p.empty()) {
          error(at, what + " yields " + p);
          return false;
        }
      }
      return true;
    };
    auto fill = [&](const std::vector<double>& vals) {
      for (double v : vals) d.axis.values.push_back(convert(*info, v, scara));
    };
    if (const toml::node* rn = t->get("random")) {
      check_keys(*t, {"random"}, what + " (random)");
      d.axis.form = "random";
      const auto* rt = rn->as_table();
      if (!rt) {
        error(*rn, what + " random is " + type_name(*rn) + "; expected random = { from, to, count, seed }");
        return std::nullopt;
      }
      if (is_int) {
        error(*rn, what + ": random draws give non-integers; expected a list or an integer range for " + key);
        return std::nullopt;
      }
      check_keys(*rt, {"from", "to", "count", "seed"}, what + " random");
      auto from = get_number(*rt, "from", "from"), to = get_number(*rt, "to", "to");
      std::optional<std::int64_t> count, seed;
      if (rt->get("count")) count = get_integer(*rt->get("count"), "count");
      if (rt->get("seed")) seed = get_integer(*rt->get("seed"), "seed");
      for (const char* req : {"from", "to", "count", "seed"})
        if (!rt->get(req))
          error(*rn, what + " random has no " + req + "; expected random = { from, to, count, seed }");
      if (!from || !to || !count || !seed) return std::nullopt;
      if (*count < 1) {
        error(*rt->get("count"), what + " count = " + std::to_string(*count) + "; expected count >= 1");
        return std::nullopt;
      }
      if (*seed < 0) {
        error(*rt->get("seed"), what + " seed = " + std::to_string(*seed) + "; expected seed >= 0");
        return std::nullopt;
      }
      if (*from > *to) {
        error(*rn, what + " has from = " + fmt(*from) + " > to = " + fmt(*to) + "; expected from <= to");
        return std::nullopt;
      }
      if (std::uint64_t(*count) > max_runs_) {
        error(*rt->get("count"), what + " count = " + std::to_string(*count) + "; expected at most max_runs = " +
                                     std::to_string(max_runs_));
        return std::nullopt;
      }
      const auto vals = uniform_draws(std::uint64_t(*seed), std::uint64_t(*count), *from, *to);
      if (!gen_check(vals, *rn)) return std::nullopt;
      fill(vals);
    } else if (const toml::node* ln = t->get("lhs")) {
      check_keys(*t, {"lhs"}, what + " (lhs)");
      d.axis.form = "lhs";
      d.lhs = true;
      const auto* lt = ln->as_table();
      if (!lt) {
        error(*ln, what + " lhs is " + type_name(*ln) + "; expected lhs = { from, to }");
        return std::nullopt;
      }
      if (is_int) {
        error(*ln, what + ": LHS draws give non-integers; expected a list or an integer range for " + key);
        return std::nullopt;
      }
      check_keys(*lt, {"from", "to"}, what + " lhs");
      auto from = get_number(*lt, "from", "from"), to = get_number(*lt, "to", "to");
      if (!lt->get("from") || !lt->get("to")) error(*ln, what + " lhs lacks from or to; expected lhs = { from, to }");
      if (!from || !to) return std::nullopt;
      if (*from > *to) {
        error(*ln, what + " has from = " + fmt(*from) + " > to = " + fmt(*to) + "; expected from <= to");
        return std::nullopt;
      }
      if (!gen_check({*from, *to}, *ln)) return std::nullopt;
      if (!lhs_node) {
        error(*ln, what + " uses lhs but the block has no lhs settings; expected lhs = { count = N, seed = S } in the block");
        return std::nullopt;
      }
      d.lhs_range = {*from, *to};
    } else if (t->get("step") || t->get("count")) {
      const bool is_range = t->get("step") != nullptr;
      d.axis.form = is_range ? "range" : "linspace";
      if (t->get("step") && t->get("count")) {
        error(*n, what + " has both step and count; expected { from, to, step } or { from, to, count }");
        return std::nullopt;
      }
      check_keys(*t, {"from", "to", is_range ? "step" : "count"}, what + (is_range ? " (range)" : " (linspace)"));
      if (!t->get("from") || !t->get("to")) {
        error(*n, what + " lacks from or to; expected { from, to, " + (is_range ? "step }" : "count }"));
        return std::nullopt;
      }
      auto from = get_number(*t, "from", "from"), to = get_number(*t, "to", "to");
      if (!from || !to) return std::nullopt;
      std::vector<double> vals;
      if (is_range) {
        auto step = get_number(*t, "step", "step");
        if (!step) return std::nullopt;
        if (*step == 0) {
          error(*t->get("step"), what + " has step = 0; expected a nonzero step");
          return std::nullopt;
        }
        const std::uint64_t cnt = range_count(*from, *to, *step);
        if (cnt == 0) {
          error(*n, what + " is an empty range: from = " + fmt(*from) + (*step > 0 ? " > " : " < ") + "to = " +
                        fmt(*to) + " with step = " + fmt(*step) + "; expected from " + (*step > 0 ? "<=" : ">=") +
                        " to (or a step of the other sign)");
          return std::nullopt;
        }
        if (cnt > max_runs_) {
          error(*n, what + " has " + std::to_string(cnt) + " values; expected at most max_runs = " +
                        std::to_string(max_runs_));
          return std::nullopt;
        }
        vals = range_values(*from, *to, *step);
      } else {
        if (is_int) {
          error(*t->get("count"), what + ": linspace gives non-integers in general; expected a list or { from, to, step } for " + key);
          return std::nullopt;
        }
        auto count = get_integer(*t->get("count"), "count");
        if (!count) return std::nullopt;
        if (*count < 1) {
          error(*t->get("count"), what + " count = " + std::to_string(*count) + "; expected count >= 1");
          return std::nullopt;
        }
        if (*from > *to) {
          error(*n, what + " has from = " + fmt(*from) + " > to = " + fmt(*to) + "; expected from <= to");
          return std::nullopt;
        }
        if (std::uint64_t(*count) > max_runs_) {
          error(*t->get("count"), what + " count = " + std::to_string(*count) + "; expected at most max_runs = " +
                                      std::to_string(max_runs_));
          return std::nullopt;
        }
        vals = linspace_values(*from, *to, std::uint64_t(*count));
      }
      if (!gen_check(vals, *n)) return std::nullopt;
      fill(vals);
    } else {
      std::vector<std::string> axis_keys{"values", "from", "to", "step", "count", "random", "lhs"};
      check_keys(*t, axis_keys, what);
      error(*n, what + " gives no values; expected " + forms);
      return std::nullopt;
    }
  } else {
    error(*n, what + " is " + type_name(*n) + " (a single value); expected " + forms +
                  " (a fixed value belongs in the block, outside [block.axes])");
    return std::nullopt;
  }
  if (!ok) return std::nullopt;
  return d;
}

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
      error(np, "duplicate block name '" + *v + "' (first at line " + std::to_string(it->second.line) +
                    "); expected unique block names");
    else names.emplace(*v, np);
    spec.name = *v;
  } else if (!b.get("name") && optimize && b.get("preset") && b.get("preset")->as_string()) {
    spec.name = b.get("preset")->as_string()->get();  // an optimisation of a seed row is named after it
    if (auto it = names.find(spec.name); it != names.end())
      error(bpos, label + " is named '" + spec.name + "' after its preset, like the one at line " +
                      std::to_string(it->second.line) + "; expected unique names (give name = \"...\")");
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
  const auto infos = block_params(kind, nverts);
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
  if (axes_t)
    for (auto&& [k, n] : *axes_t) axis_names.insert(std::string(k.str()));

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
          error(*node, "problem '" + p + "' mixes the SCARA (mm) with the planar 3R (m, deg) problems in one block; "
                       "expected separate blocks for scara and planar3r_* problems");
          break;
        }
    }
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
          error(*k, "vertex_alpha and " + pname + " both given; expected one or the other");
          continue;
        }
        if (auto c = param_value(*info_of(pname), *a->get(i), scara)) spec.fixed.emplace_back(pname, *c);
      }
      continue;
    }
    const ParamInfo* info = info_of(key);
    if (!info) continue;
    if (axis_names.count(key)) {
      error(*k, "'" + key + "' is both a fixed parameter and an axis; expected one or the other");
      continue;
    }
    if (auto c = param_value(*info, *n, scara)) spec.fixed.emplace_back(key, *c);
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
      if (auto d = parse_axis(*info, *k, *n, scara, lhs_node)) drafts.push_back(std::move(*d));
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
        for (double v : draws[i]) lhs_axes[i]->axis.values.push_back(convert(*info, v, scara));
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
      std::set<std::string> zipped;
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
          if (!zipped.insert(nm).second) {
            error(e, "axis '" + nm + "' is zipped twice; expected each axis in at most one zip group");
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
          if (len && *len != it->axis.values.size()) unequal = true;
          len = it->axis.values.size();
          group.push_back(nm);
        }
        if (unequal) {
          error(g, "zipped axes have different lengths: " + join(lens) + "; expected equal lengths");
          ok = false;
        }
        if (ok) spec.groups.push_back(group);
      }
    }
  }
  if (!lhs_group.empty()) spec.groups.push_back(lhs_group);

  // Swept parameters that a run would ignore would only repeat runs: reject them.
  auto axis_values = [&](std::string_view nm) -> const std::vector<Cell>* {
    for (const auto& d : drafts)
      if (d.axis.name == nm) return &d.axis.values;
    return nullptr;
  };
  auto fixed_value = [&](std::string_view nm) -> const Cell* {
    for (const auto& [n, v] : spec.fixed)
      if (n == nm) return &v;
    return nullptr;
  };
  auto possible = [&](std::string_view nm, std::string dflt) {
    std::vector<std::string> out;
    if (const Cell* c = fixed_value(nm)) out.push_back(std::get<std::string>(*c));
    else if (const auto* vs = axis_values(nm))
      for (const auto& c : *vs) out.push_back(std::get<std::string>(c));
    else out.push_back(std::move(dflt));
    return out;
  };
  std::vector<std::string> methods;
  if (kind == BlockKind::trajectory) {
    if (fixed_value("method") || axis_values("method")) methods = possible("method", "");
    else if (fixed_value("preset") || axis_values("preset")) {
      for (const auto& p : possible("preset", ""))
        if (const SeedCase* c = find_seed_case(p)) methods.emplace_back(to_string(c->method));
    } else methods = {"local_weighted"};
  } else {
    methods = possible("method", "newton");
  }
  const std::vector<std::string> problems = kind == BlockKind::ik ? possible("problem", "scara") : std::vector<std::string>{};
  auto reject_if = [&](const AxisDraft& d, const std::vector<std::string>& controlling, auto unused,
                       const std::string& ctl_name, const std::string& expectation) {
    for (const auto& m : controlling)
      if (unused(m)) {
        error(d.pos, "axis '" + d.axis.name + "' has no effect when " + ctl_name + " = '" + m +
                         "' (its runs would repeat); expected " + expectation + " (split the block)");
        return true;
      }
    return false;
  };
  for (const auto& d : drafts) {
    const std::string& nm = d.axis.name;
    if (kind == BlockKind::trajectory) {
      if (nm == "k" || nm == "K_N")
        reject_if(d, methods, [](const std::string& m) { return m == "vertex_alpha"; }, "method",
                  "a " + nm + " axis only in blocks whose methods are local_weighted / local_unweighted");
      if (nm.starts_with("vertex_alpha_"))
        reject_if(d, methods, [](const std::string& m) { return m != "vertex_alpha"; }, "method",
                  "a " + nm + " axis only in blocks whose method is vertex_alpha");
    } else {
      if (nm == "lambda")
        reject_if(d, methods, [](const std::string& m) { return m != "lm" && m != "lm_adaptive"; }, "method",
                  "a lambda axis only in blocks whose methods are lm / lm_adaptive");
      if (nm.starts_with("q0_"))
        reject_if(d, methods, [](const std::string& m) { return m == "analytic"; }, "method",
                  "no initial-guess axis for the analytic method");
      if (nm == "target_alpha")
        reject_if(d, problems, [](const std::string& p) { return p != "planar3r_pose"; }, "problem",
                  "a target_alpha axis only for problem planar3r_pose");
      if (nm == "target_z" || nm == "z_mode")
        reject_if(d, problems, [](const std::string& p) { return p != "scara"; }, "problem",
                  "a " + nm + " axis only for problem scara");
    }
  }

  if (diags_.size() != errors_before) return std::nullopt;
  for (auto& d : drafts) spec.axes.push_back(std::move(d.axis));
  BlockContext ctx;
  ctx.path_vertices = nverts;
  ctx.integrator = s.task.integrator;
  ctx.dt = s.task.dt;
  ctx.inertia = s.robot.inertia_form;
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
  for (std::size_t i = 0; i < a->size(); ++i) {
    const auto& bt = *a->get(i)->as_table();
    auto block = parse_block(bt, i, s, names);
    if (!block) continue;
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

// ---------------------------------------------------------------------------------------------------
// [[optimize]] tables (issue 6).
std::vector<std::string> objective_names(BlockKind k) {
  if (k == BlockKind::ik) return {"iterations", "failure_rate", "error"};
  return {"E", "E_M", "tau_inf", "tau1_inf", "tau2_inf", "tau3_inf", "min_manipulability", "torque_sq_integral",
          "power_sq_integral", "max_tracking_error", "final_alpha"};
}

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
    const auto infos = block_params(kind, nverts);
    const std::vector<Cell> base = block->params(0);
    std::string method;
    bool scara = true;
    if (kind == BlockKind::trajectory) method = std::get<std::string>(base[block->column_index("method")]);
    else scara = ik_problem_is_scara(std::get<std::string>(base[block->column_index("problem")]));
    std::set<std::string> axis_names;
    for (const auto& ax : block->axes()) axis_names.insert(ax.name);

    // variables = { name = [lower, upper] | { from, to, start }, ... } (file units)
    const toml::node* vn = t.get("variables");
    const auto* vt = vn ? vn->as_table() : nullptr;
    const SeedCase* seed_row = ob.preset.empty() ? nullptr : find_seed_case(ob.preset);
    if (!vn && seed_row && kind == BlockKind::trajectory) {
      // A seed row's own design variables (Table 4): k and/or alpha1A, or the five vertex alphas.
      const std::string_view p = ob.preset;
      auto add = [&](const std::string& nm, double lo, double hi) {
        if (axis_names.count(nm)) return;
        OptimizeVariable v;
        v.name = nm;
        v.unit = block->columns()[block->column_index(nm)].unit;
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
      if (ob.variables.empty())
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
        const ParamInfo* info = nullptr;
        for (const auto& in : infos)
          if (in.name == params.front()) info = &in;
        if (!info) {
          error(*k, "unknown variable '" + key + "' for " + std::string(to_string(kind)) + " runs; expected a numeric parameter: " +
                        join(f64_names) + suggest(key, f64_names));
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
        if (kind == BlockKind::trajectory) {
          if ((key == "k" || key == "K_N") && method == "vertex_alpha") {
            error(*k, "variable '" + key + "' has no effect when method = 'vertex_alpha'; expected it only with local_weighted / local_unweighted");
            bad = true;
          }
          if (key.starts_with("vertex_alpha") && method != "vertex_alpha") {
            error(*k, "variable '" + key + "' has no effect when method = '" + method + "'; expected it only with method vertex_alpha");
            bad = true;
          }
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
          if (auto p = domain_problem(key, v); !p.empty() && !dom) {
            error(*node, "variable '" + key + "' bound: " + p);
            dom = true;
          }
        if (bad || dom) continue;
        for (const auto& pn : params) {
          OptimizeVariable v;
          v.name = pn;
          v.unit = block->columns()[block->column_index(pn)].unit;
          v.lower = std::get<double>(convert(*info, lo, scara));
          v.upper = std::get<double>(convert(*info, hi, scara));
          if (start) v.start = std::get<double>(convert(*info, *start, scara));
          ob.variables.push_back(std::move(v));
        }
      }
    }

    // objective = "E" | { E = 1, tau_inf = 0.01 }
    const auto allowed = objective_names(kind);
    auto check_metric = [&](const std::string& m, const toml::node& at) {
      if (std::find(allowed.begin(), allowed.end(), m) != allowed.end()) return true;
      error(at, "unknown objective '" + m + "' for " + std::string(to_string(kind)) + " runs; expected one of " +
                    join(allowed) + " or a weighted sum { metric = weight, ... }" + suggest(m, allowed));
      return false;
    };
    if (const toml::node* on = t.get("objective")) {
      if (const auto* os = on->as_string()) {
        if (check_metric(os->get(), *on)) ob.objective.emplace_back(os->get(), 1.0);
      } else if (const auto* ot = on->as_table()) {
        if (ot->empty()) error(*on, "objective is an empty table; expected { metric = weight, ... }");
        for (auto&& [k, wn] : ordered(*ot)) {
          const std::string m(k->str());
          if (!check_metric(m, *wn)) continue;
          if (auto w = get_number(*wn, "weight of " + m)) {
            if (*w == 0) error(*wn, "weight of " + m + " is 0; expected a nonzero weight (negative: maximise)");
            else ob.objective.emplace_back(m, *w);
          }
        }
      } else {
        error(*on, "objective is " + type_name(*on) + "; expected a metric name (\"E\") or { metric = weight, ... }");
      }
    } else {
      // Default: E (case 3 of the seed minimises mean sqrt(tau^T M^-1 tau): E_M); IK: iterations.
      ob.objective.emplace_back(kind == BlockKind::ik ? "iterations" : ob.preset == "3" ? "E_M" : "E", 1.0);
    }
    for (std::size_t j = 0; j < ob.objective.size(); ++j) {
      const auto& [m, w] = ob.objective[j];
      if (j) ob.objective_text += " + ";
      if (w != 1.0) ob.objective_text += fmt(w) + "*";
      ob.objective_text += m;
    }

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
    s.optimizations.push_back(std::move(ob));
  }
}

Study Parser::run(std::string_view text) {
  Study s;
  s.file = file_;
  s.text = std::string(text);
  s.sha256 = sha256_hex(text);
  toml::table root;
  try {
    root = toml::parse(text, file_);
  } catch (const toml::parse_error& e) {
    error(e.source(), "TOML syntax: " + std::string(e.description()) + "; expected valid TOML (https://toml.io)");
    throw StudyError(diags_);
  }
  check_keys(root, {"study", "robot", "task", "block", "optimize"}, "the top level");
  parse_study_table(root, s);
  parse_robot(root, s);
  parse_task(root, s);
  if (root.get("block") || !root.get("optimize")) parse_blocks(root, s);
  parse_optimizations(root, s);
  if (!diags_.empty()) {
    std::stable_sort(diags_.begin(), diags_.end(), [](const StudyDiagnostic& a, const StudyDiagnostic& b) {
      return std::pair(a.line, a.column) < std::pair(b.line, b.column);
    });
    throw StudyError(diags_);
  }
  return s;
}
}  // namespace

Study parse_study(std::string_view text, std::string_view file, const StudyOptions& options) {
  return Parser(std::string(file), options).run(text);
}

Study load_study(const std::filesystem::path& file, const StudyOptions& options) {
  std::ifstream in(file, std::ios::binary);
  if (!in)
    throw StudyError({{file.string(), 1, 1, "cannot read the study file; expected a readable TOML file"}});
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_study(ss.str(), file.string(), options);
}

}  // namespace ks
