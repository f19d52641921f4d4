// parse_block's steps for a block's axes: its lhs settings, [block.axes], the LHS group's draw, zip
// groups, the rejection of axes a run would ignore, and the Block built from the draft.
#include <algorithm>
#include <limits>
#include <map>
#include <set>

#include "study/parser.hpp"

namespace ks::study_parse {

void Parser::read_block_lhs(BlockDraft& d) {
  const toml::node* lhs = d.table.get("lhs");
  const toml::node* saltelli = d.table.get("saltelli");
  if (lhs && saltelli)
    error(*saltelli, "the block has both lhs and saltelli; expected one sampled design per block");
  d.lhs_node = lhs ? lhs : saltelli;
  d.design = lhs || !saltelli ? "lhs" : "saltelli";
  const toml::node* lhs_node = d.lhs_node;
  if (!lhs_node) return;
  const std::string& w = d.design;
  const std::string form = w + " = { count = N, seed = S }";
  if (const auto* lt = lhs_node->as_table()) {
    if (w == "saltelli") {
      check_keys(*lt, {"count", "seed", "second_order"}, w);
      if (const toml::node* so = lt->get("second_order"))
        if (auto v = so->value<bool>(); !v || *v)
          error(*so, "saltelli second_order = " + (v ? std::string("true") : type_name(*so)) +
                         "; expected false (the design gives first-order and total indices only)");
    } else {
      check_keys(*lt, {"count", "seed"}, w);
    }
    if (const toml::node* c = lt->get("count")) {
      if (auto v = get_integer(*c, w + " count")) {
        if (*v < 1) error(*c, w + " count = " + std::to_string(*v) + "; expected count >= 1");
        else if (std::uint64_t(*v) > max_runs_)
          error(*c, w + " count = " + std::to_string(*v) + "; expected at most " + std::to_string(max_runs_) + " runs" +
                        limit_hint());
        else d.lhs_count = std::uint64_t(*v);
      }
    } else error(*lhs_node, w + " has no count; expected " + form);
    if (const toml::node* c = lt->get("seed")) {
      if (auto v = get_integer(*c, w + " seed")) {
        if (*v < 0) error(*c, w + " seed = " + std::to_string(*v) + "; expected seed >= 0");
        else d.lhs_seed = std::uint64_t(*v);
      }
    } else error(*lhs_node, w + " has no seed; expected " + form);
  } else {
    error(*lhs_node, w + " is " + type_name(*lhs_node) + "; expected " + form);
  }
}

void Parser::read_axes(BlockDraft& d) {
  if (!d.axes_t) return;
  for (auto&& [k, n] : ordered(*d.axes_t)) {
    const std::string key(k->str());
    const ParamDef* info = d.info_of(key);
    if (!info) {
      if (const std::string why = placement_refusal(key, d.ctx.robot); d.kind == BlockKind::trajectory && !why.empty())
        error(*k, why);
      else if (key == "vertex_alpha" && d.kind == BlockKind::trajectory)
        error(*k, "vertex_alpha cannot be an axis as a whole; expected one axis per vertex: vertex_alpha_2 .. vertex_alpha_" +
                      std::to_string(d.nverts));
      else if (d.belongs_to_other(key))
        error(*k, "axis '" + key + "' does not belong to " + d.a_kind + " block (it is " + d.a_other +
                      " parameter); expected " + d.a_kind + " parameter: " + join(d.param_names));
      else
        error(*k, "unknown axis '" + key + "' in " + d.kname + " block '" + d.spec.name + "'; expected " + d.a_kind +
                      " parameter: " + join(d.param_names) + suggest_either(key, with_placement(d.param_names, d), d.other, d.other_kname));
      continue;
    }
    if (auto a = parse_axis(*info, *k, *n, d.lhs_node, d.design)) d.drafts.push_back(std::move(*a));
  }
}

namespace {
/// a * b, or nullopt past 64 bits.
std::optional<std::uint64_t> times(std::uint64_t a, std::uint64_t b) {
  if (a != 0 && b > std::numeric_limits<std::uint64_t>::max() / a) return std::nullopt;
  return a * b;
}
}  // namespace

bool Parser::check_block_runs(BlockDraft& d) {
  // One factor per dimension: an axis alone, a zip group once (its lengths are equal), the LHS group once.
  std::set<std::string> counted;
  std::optional<std::uint64_t> runs = 1;
  for (const auto& g : d.spec.groups) {
    auto it = std::find_if(d.drafts.begin(), d.drafts.end(), [&](const AxisDraft& a) { return a.axis.name == g.front(); });
    if (it != d.drafts.end() && runs) runs = times(*runs, it->count);
    counted.insert(g.begin(), g.end());
  }
  std::uint64_t sampled = 0;  // axes of the sampled design
  for (const auto& a : d.drafts) {
    if (counted.count(a.axis.name) || !runs) continue;
    if (a.lhs) ++sampled;
    else runs = times(*runs, a.count);
  }
  // the design's points: count (lhs), count (d + 2) (saltelli: A, B and one AB per factor)
  if (sampled && d.lhs_count && runs) runs = times(*runs, *d.lhs_count);
  if (sampled && d.lhs_count && runs && d.design == "saltelli") runs = times(*runs, sampled + 2);
  const std::uint64_t before = d.optimize ? 0 : sweep_runs_;
  const bool over = !runs || *runs > max_runs_ - std::min(before, max_runs_);
  if (!over) {
    if (!d.optimize) sweep_runs_ += *runs;
    return true;
  }
  if (d.optimize)
    error(d.pos, "too many runs per evaluation: " + d.label + " '" + d.spec.name + "' has " +
                     (runs ? std::to_string(*runs) : std::string("more than 2^64")) + " runs; expected at most " +
                     std::to_string(max_runs_) + limit_hint());
  else if (!reported_runs_)
    error(d.pos, "too many runs: block '" + d.spec.name + "' has " +
                     (runs ? std::to_string(*runs) : std::string("more than 2^64")) + " runs, the study " +
                     (runs && before + *runs >= before ? std::to_string(before + *runs) : std::string("overflows")) +
                     "; expected at most " + std::to_string(max_runs_) + " runs in all" + limit_hint());
  reported_runs_ = reported_runs_ || !d.optimize;
  return false;
}

std::string Parser::limit_hint() const {
  if (max_runs_ < options_.max_runs)
    return " (the study's max_runs; the caller allows up to " + std::to_string(options_.max_runs) + ")";
  return " (the caller's limit: kinesweep run --max-runs N raises it)";
}

void Parser::generate_axes(BlockDraft& d) {
  for (auto& a : d.drafts) {
    if (!a.generate) continue;
    const ParamDef* info = d.info_of(a.axis.name);
    const std::string what = "axis '" + a.axis.name + "'";
    const std::vector<double> vals = a.generate();
    a.axis.values.reserve(a.axis.values.size() + vals.size());  // a long axis: no doubling's slack
    for (double v : vals)
      if (auto p = value_problem(*info, what, v); !p.empty()) {
        error(*a.node, p);
        a.axis.values.clear();
        break;
      } else a.axis.values.push_back(info->from_file(v));
  }
  std::vector<std::pair<double, double>> ranges;
  std::vector<AxisDraft*> lhs_axes;
  for (auto& a : d.drafts)
    if (a.lhs) {
      ranges.push_back(a.lhs_range);
      lhs_axes.push_back(&a);
    }
  // An axis written { lhs = ... } or { saltelli = ... } whose settings were refused has its own
  // error: the design's settings are then not unused.
  bool written = false;
  if (d.axes_t)
    for (auto&& [k, n] : *d.axes_t)
      if (const auto* t = n.as_table()) written = written || t->get("lhs") || t->get("saltelli");
  if (d.lhs_node && lhs_axes.empty() && !written && d.lhs_node->as_table())
    error(*d.lhs_node, d.design + " settings given but no axis uses them; expected axes written { " + d.design +
                           " = { from, to } }");
  if (!lhs_axes.empty() && d.lhs_count && d.lhs_seed) {
    const auto draws = d.design == "saltelli" ? saltelli_draws(*d.lhs_seed, *d.lhs_count, ranges)
                                              : lhs_draws(*d.lhs_seed, *d.lhs_count, ranges);
    for (std::size_t i = 0; i < lhs_axes.size(); ++i) {
      const ParamDef* info = d.info_of(lhs_axes[i]->axis.name);
      for (double v : draws[i]) lhs_axes[i]->axis.values.push_back(info->from_file(v));
      d.lhs_group.push_back(lhs_axes[i]->axis.name);
    }
  }
  // Drop axes that got no values (their settings were bad: already reported).
  std::erase_if(d.drafts, [](const AxisDraft& a) { return a.axis.values.empty(); });
}

void Parser::read_zip_groups(BlockDraft& d) {
  const toml::node* zn = d.table.get("zip");
  if (!zn) return;
  const auto* za = zn->as_array();
  if (!za) {
    error(*zn, "zip is " + type_name(*zn) + "; expected zip = [[\"a\", \"b\"], ...]");
    return;
  }
  std::map<std::string, Pos> zipped;  // axis -> its first zip entry
  std::vector<std::string> all_axes(d.axis_names.begin(), d.axis_names.end());
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
      if (!d.axis_names.count(nm)) {
        error(e, "zip names '" + nm + "', which is not an axis of block '" + d.spec.name + "'; expected one of " +
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
      auto it = std::find_if(d.drafts.begin(), d.drafts.end(), [&](const AxisDraft& a) { return a.axis.name == nm; });
      if (it == d.drafts.end()) {  // the axis had errors
        ok = false;
        continue;
      }
      if (it->lhs) {
        error(e, "axis '" + nm + "' is an LHS axis (LHS axes already advance together); expected no LHS axis in zip");
        ok = false;
        continue;
      }
      lens.push_back(nm + " (" + std::to_string(it->count) + ")");
      len_notes.emplace_back(it->pos, "axis '" + nm + "' has " + std::to_string(it->count) +
                                          (it->count == 1 ? " value" : " values"));
      if (len && *len != it->count) unequal = true;
      len = it->count;
      group.push_back(nm);
    }
    if (unequal) {
      auto& diag = error(g, "zipped axes have different lengths: " + join(lens) + "; expected equal lengths");
      for (const auto& [at, msg] : len_notes) note(diag, at, msg);
      ok = false;
    }
    if (ok) d.spec.groups.push_back(group);
  }
}

// Swept parameters that a run would ignore would only repeat runs: rejected by the tables' effect rules.
void Parser::reject_ineffective_axes(const BlockDraft& d) {
  const RunSpec defaults = default_run(d.kind, d.ctx);
  auto explicit_values = [&](std::string_view nm) {
    std::vector<Cell> out;
    for (const auto& [n, v] : d.spec.fixed)
      if (n == nm) out.push_back(v);
    for (const auto& a : d.drafts)
      if (a.axis.name == nm) out.insert(out.end(), a.axis.values.begin(), a.axis.values.end());
    return out;
  };
  // The values a controlling parameter takes in the block's runs: its own, else those the leading
  // parameters (a preset) set, else its default.
  auto controller_values = [&](const ParamDef& ctl) {
    std::vector<Cell> vs = explicit_values(ctl.name);
    if (vs.empty())
      for (const ParamDef& lead : d.infos)
        if (lead.leading)
          for (const Cell& v : explicit_values(lead.name)) {
            RunSpec r = defaults;
            lead.set(r, v);
            vs.push_back(ctl.get(r));
          }
    if (vs.empty()) vs.push_back(ctl.get(defaults));
    return vs;
  };
  for (const auto& a : d.drafts) {
    const ParamDef* p = d.info_of(a.axis.name);
    const ParamDef* ctl = p && !p->effect.always() ? d.info_of(p->effect.controller) : nullptr;
    if (!ctl) continue;
    for (const Cell& c : controller_values(*ctl)) {
      const std::string& v = std::get<std::string>(c);
      if (p->effect.applies(v)) continue;
      error(a.pos, "axis '" + a.axis.name + "' has no effect when " + ctl->name + " = '" + v +
                       "' (its runs would repeat); expected a " + a.axis.name + " axis " + p->effect.str() +
                       " (split the block)");
      break;
    }
  }
}

std::optional<Block> Parser::finish_block(BlockDraft& d, std::size_t errors_before) {
  if (diags_.size() != errors_before) return std::nullopt;
  for (auto& a : d.drafts) d.spec.axes.push_back(std::move(a.axis));
  try {
    return Block(std::move(d.spec), d.ctx);
  } catch (const std::exception& e) {
    error(d.pos, std::string("invalid block: ") + e.what() + "; expected a consistent block");
    return std::nullopt;
  }
}

}  // namespace ks::study_parse
