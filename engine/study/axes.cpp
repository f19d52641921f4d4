// Parameter values (type, choices, unit, domain) and the axis forms of [block.axes]: value lists,
// range, linspace, random and Latin-hypercube axes.
#include <algorithm>
#include <cmath>

#include "study/parser.hpp"

namespace ks::study_parse {

std::string Parser::domain_problem(const ParamDef& info, double v) {
  if (auto p = info.domain.problem(info.name, v); !p.empty()) return p;
  if (info.name == "dt" && path_duration_ / v + 1 > kMaxSamples)  // the path's samples bound dt from below
    return "dt = " + fmt(v) + " gives " + fmt(std::floor(path_duration_ / v) + 1) + " samples on the " +
           fmt(path_duration_) + " s path; expected at most " + fmt(kMaxSamples) + " (dt >= " +
           fmt(path_duration_ / (kMaxSamples - 1)) + ")";
  return "";
}

std::string Parser::sampling_problem(const StudyTask& task, double dt) const {
  const std::vector<double> spans = task.sampled_spans();
  if (task.durations.empty() || samples_path(spans, dt)) return "";
  const double shortest = *std::min_element(spans.begin(), spans.end());
  if (task.shape != PathShape::quintic)
    return "dt = " + fmt(dt) + " s samples the " + fmt(shortest) + " s spline path " + fmt(shortest / dt) +
           " times; expected at least " + fmt(kMinSamplesPerSegment) + " samples on the path (dt <= " +
           fmt(shortest / kMinSamplesPerSegment) + " s; a dt axis may go beyond: those runs end undersampled)";
  return "dt = " + fmt(dt) + " s samples the shortest segment (" + fmt(shortest) + " s) " + fmt(shortest / dt) +
         " times; expected at least " + fmt(kMinSamplesPerSegment) + " samples per segment (dt <= " +
         fmt(shortest / kMinSamplesPerSegment) + " s; a dt axis may go beyond: those runs end undersampled)";
}

void Parser::check_block_dt(const BlockDraft& d, const Study& s) {
  if (d.kind != BlockKind::trajectory || d.axis_names.count("dt")) return;
  if (d.optimize)  // dt an optimisation variable: its evaluations beyond the bound end undersampled
    if (const toml::node* v = d.table.get("variables"); v && v->as_table() && v->as_table()->get("dt")) return;
  for (const auto& [name, v] : d.spec.fixed)
    if (name == "dt") {
      if (auto p = sampling_problem(s.task, std::get<double>(v)); !p.empty()) error(*d.table.get("dt"), p);
      return;
    }
  if (task_dt_reported_ || s.task.durations.empty()) return;
  const double dt = s.task.dt;
  std::string p = sampling_problem(s.task, dt);
  if (p.empty() && !task_dt_pos_) {  // the default dt: the path's length bounds it too
    p = domain_problem(*find_param(block_params(BlockKind::trajectory), "dt"), dt);
    if (!p.empty()) p = "the default " + p + " (set [task] dt)";
  } else if (!p.empty() && !task_dt_pos_) {
    p = "the default " + p;
  }
  if (p.empty()) return;
  task_dt_reported_ = true;
  error(task_dt_pos_ ? *task_dt_pos_ : path_pos_, p);
}

std::optional<Cell> Parser::param_value(const ParamDef& info, const toml::node& n) {
  if (info.type == CellType::str) {
    // a yes/no parameter (choices false, true) takes a TOML boolean as its text
    if (const auto* b = n.as_boolean(); b && info.choices == std::vector<std::string>{"false", "true"})
      return Cell(std::string(b->get() ? "true" : "false"));
    const auto* s = n.as_string();
    if (!s) {
      error(n, info.name + " is " + type_name(n) + "; expected a string" +
                   (info.choices.empty() ? "" : " (one of " + join(info.choices) + ")"));
      return std::nullopt;
    }
    const std::string v = s->get();
    if (!info.choices.empty() && std::find(info.choices.begin(), info.choices.end(), v) == info.choices.end()) {
      error(n, "unknown " + info.name + " '" + v + "'; expected one of " + join(info.choices) +
                   suggest(v, info.choices));
      return std::nullopt;
    }
    return Cell(v);
  }
  if (info.type == CellType::i64) {
    auto v = get_integer(n, info.name);
    if (!v) return std::nullopt;
    if (auto p = domain_problem(info, double(*v)); !p.empty()) {
      error(n, p);
      return std::nullopt;
    }
    return Cell(*v);
  }
  auto v = get_number(n, info.name);
  if (!v) return std::nullopt;
  if (auto p = domain_problem(info, *v); !p.empty()) {
    error(n, p);
    return std::nullopt;
  }
  return info.from_file(*v);
}

bool Parser::count_and_interval_ok(const std::string& what, std::int64_t count, const toml::node& count_node,
                                   double from, double to, const toml::node& at) {
  if (count < 1) {
    error(count_node, what + " count = " + std::to_string(count) + "; expected count >= 1");
    return false;
  }
  if (from > to) {
    error(at, what + " has from = " + fmt(from) + " > to = " + fmt(to) + "; expected from <= to");
    return false;
  }
  if (std::uint64_t(count) > max_runs_) {
    error(count_node, what + " count = " + std::to_string(count) + "; expected at most " +
                          std::to_string(max_runs_) + " runs" + limit_hint());
    return false;
  }
  return true;
}

// ---------------------------------------------------------------------------------------------------
std::optional<AxisDraft> Parser::parse_axis(const ParamDef& info_ref, const toml::key& key_node, const toml::node& node,
                                          const toml::node* lhs_node, const std::string& design) {
  const ParamDef* info = &info_ref;
  const toml::node* n = &node;
  const std::string key(key_node.str());
  AxisDraft d;
  d.axis.name = key;
  d.pos = pos_of(key_node.source());
  const std::string what = "axis '" + key + "'";
  const std::string forms =
      info->type == CellType::str
          ? "a list of names [\"a\", \"b\"] or { values = [...] }"
          : "a list [...], { values = [...] }, { from, to, step }, { from, to, count }, { random = { from, to, count, seed } } or { lhs = { from, to } } / { saltelli = { from, to } }";
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
      auto c = param_value(*info, e);
      if (!c) ok = false;
      else d.axis.values.push_back(std::move(*c));
    }
  } else if (t) {
    if (info->type == CellType::str) {
      error(*n, what + " is a numeric range but " + key + " is a name; expected " + forms);
      return std::nullopt;
    }
    const bool is_int = info->type == CellType::i64;
    d.node = n;
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
      if (!count_and_interval_ok(what, *count, *rt->get("count"), *from, *to, *rn)) return std::nullopt;
      if (*seed < 0) {
        error(*rt->get("seed"), what + " seed = " + std::to_string(*seed) + "; expected seed >= 0");
        return std::nullopt;
      }
      d.count = std::uint64_t(*count);
      d.node = rn;
      d.generate = [seed = std::uint64_t(*seed), count = d.count, from = *from, to = *to] {
        return uniform_draws(seed, count, from, to);
      };
    } else if (const toml::node* ln = t->get("lhs") ? t->get("lhs") : t->get("saltelli")) {
      const std::string w = t->get("lhs") ? "lhs" : "saltelli";  // the design the axis belongs to
      check_keys(*t, {w}, what + " (" + w + ")");
      d.axis.form = w;
      d.lhs = true;
      const auto* lt = ln->as_table();
      if (!lt) {
        error(*ln, what + " " + w + " is " + type_name(*ln) + "; expected " + w + " = { from, to }");
        return std::nullopt;
      }
      if (is_int) {
        error(*ln, what + ": " + w + " draws give non-integers; expected a list or an integer range for " + key);
        return std::nullopt;
      }
      check_keys(*lt, {"from", "to"}, what + " " + w);
      auto from = get_number(*lt, "from", "from"), to = get_number(*lt, "to", "to");
      if (!lt->get("from") || !lt->get("to")) error(*ln, what + " " + w + " lacks from or to; expected " + w + " = { from, to }");
      if (!from || !to) return std::nullopt;
      if (*from > *to) {
        error(*ln, what + " has from = " + fmt(*from) + " > to = " + fmt(*to) + "; expected from <= to");
        return std::nullopt;
      }
      for (double v : {*from, *to})
        if (auto p = value_problem(*info, what, v); !p.empty()) {
          error(*ln, p);
          return std::nullopt;
        }
      if (!lhs_node || design != w) {
        error(*ln, what + " uses " + w + " but the block has no " + w + " settings; expected " + w +
                       " = { count = N, seed = S } in the block" + (lhs_node ? " (it has " + design + ")" : ""));
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
          error(*n, what + " has " + std::to_string(cnt) + " values; expected at most " + std::to_string(max_runs_) +
                        " runs" + limit_hint());
          return std::nullopt;
        }
        d.count = cnt;
        d.generate = [from = *from, to = *to, step = *step] { return range_values(from, to, step); };
      } else {
        if (is_int) {
          error(*t->get("count"), what + ": linspace gives non-integers in general; expected a list or { from, to, step } for " + key);
          return std::nullopt;
        }
        auto count = get_integer(*t->get("count"), "count");
        if (!count) return std::nullopt;
        if (!count_and_interval_ok(what, *count, *t->get("count"), *from, *to, *n)) return std::nullopt;
        d.count = std::uint64_t(*count);
        d.generate = [from = *from, to = *to, count = d.count] { return linspace_values(from, to, count); };
      }
    } else {
      const std::vector<std::string> axis_keys{"values", "from", "to", "step", "count", "random", "lhs", "saltelli"};
      for (auto&& [k, v] : ordered(*t))
        if (std::find(axis_keys.begin(), axis_keys.end(), k->str()) == axis_keys.end()) {
          error(*k, what + " has the unknown key '" + std::string(k->str()) + "' and so gives no values; expected " +
                        forms + suggest(k->str(), axis_keys));
          return std::nullopt;
        }
      error(*n, what + " gives no values; expected " + forms);
      return std::nullopt;
    }
  } else {
    error(*n, what + " is " + type_name(*n) + " (a single value); expected " + forms +
                  " (a fixed value belongs in the block, outside [block.axes])");
    return std::nullopt;
  }
  if (!ok) return std::nullopt;
  if (!d.generate && !d.lhs) d.count = d.axis.values.size();
  return d;
}

std::string Parser::value_problem(const ParamDef& info, const std::string& what, double v) {
  if (info.type == CellType::i64 && std::abs(v - std::round(v)) > 1e-9 * std::max(1.0, std::abs(v)))
    return what + " yields " + fmt(v) + "; expected integer values for " + info.name;
  if (auto p = domain_problem(info, v); !p.empty()) return what + " yields " + p;
  return "";
}

}  // namespace ks::study_parse
