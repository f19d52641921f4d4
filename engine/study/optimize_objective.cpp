// [[optimize]] objectives: a metric, a weighted sum of terms (a term "1/metric" is its reciprocal),
// normalised by the terms' values at a reference design (seed 002 Eqs. 7.1 and 7.6), and a trade-off
// swept over the weight k of a two-term objective.
#include <algorithm>
#include <cmath>
#include <set>

#include "study/parser.hpp"

namespace ks::study_parse {

namespace {

/// "0.9*min_manipulability_0/min_manipulability + 0.1*power_sq_integral/power_sq_integral_0" and the
/// like: the objective as the optimisation computes it.
std::string objective_text(const std::vector<ObjectiveTerm>& terms, bool normalised) {
  std::string out;
  for (std::size_t j = 0; j < terms.size(); ++j) {
    const ObjectiveTerm& t = terms[j];
    if (j) out += " + ";
    if (t.weight != 1.0) out += fmt(t.weight) + "*";
    if (!normalised) out += t.reciprocal ? "(1/" + t.metric + ")" : t.metric;
    else out += t.reciprocal ? t.metric + "_0/" + t.metric : t.metric + "/" + t.metric + "_0";
  }
  return out;
}

}  // namespace

void Parser::parse_objective(const toml::table& t, const Block& block, BlockKind kind, OptimizeBlock& ob) {
  const auto allowed = objective_names(block.metrics());
  auto check_metric = [&](const std::string& m, const auto& at) {
    if (std::find(allowed.begin(), allowed.end(), m) != allowed.end()) return true;
    error(at, "unknown objective '" + m + "' for " + std::string(to_string(kind)) + " runs; expected one of " +
                  join(allowed) + " or a weighted sum { metric = weight, \"1/metric\" = weight, ... }" +
                  suggest(m, allowed));
    return false;
  };
  if (const toml::node* on = t.get("objective")) {
    if (const auto* os = on->as_string()) {
      if (check_metric(os->get(), *on)) ob.objective.push_back({os->get(), 1.0, false});
    } else if (const auto* ot = on->as_table()) {
      if (ot->empty()) error(*on, "objective is an empty table; expected { metric = weight, ... }");
      for (auto&& [k, wn] : ordered(*ot)) {
        std::string m(k->str());
        const bool reciprocal = m.starts_with("1/");
        if (reciprocal) m = m.substr(2);
        if (m == kFailureRate && reciprocal) {
          error(*k, "\"1/failure_rate\" divides by a rate that is 0 at any good design; expected failure_rate");
          continue;
        }
        if (!check_metric(m, *k)) continue;
        if (auto w = get_number(*wn, "weight of " + m)) {
          if (*w == 0) error(*wn, "weight of " + m + " is 0; expected a nonzero weight (negative: maximise)");
          else ob.objective.push_back({m, *w, reciprocal});
        }
      }
    } else {
      error(*on, "objective is " + type_name(*on) + "; expected a metric name (\"E\") or { metric = weight, ... }");
    }
  } else {
    // Default: the kind's ranking objective (case 3 of the seed minimises mean sqrt(tau^T M^-1 tau): E_M).
    ob.objective.push_back({ob.preset == "3" ? "E_M" : std::string(ranking(kind).objective), 1.0, false});
  }

  // reference = "start" | { variable = value, ... } (file units; the other variables at their start)
  if (const toml::node* rn = t.get("reference")) {
    if (const auto* rs = rn->as_string()) {
      if (rs->get() == "start") ob.reference.start = true;
      else error(*rn, "reference = '" + rs->get() + "'; expected \"start\" (the variables' start point) or "
                      "{ variable = value, ... }" + suggest(rs->get(), {"start"}));
    } else if (const auto* rt = rn->as_table()) {
      if (rt->empty()) error(*rn, "reference is an empty table; expected { variable = value, ... }");
      for (auto&& [k, vn] : ordered(*rt)) {
        const std::string name(k->str());
        auto is_var = [&](const OptimizeVariable& v) { return v.name == name; };
        if (std::none_of(ob.variables.begin(), ob.variables.end(), is_var)) {
          std::vector<std::string> names;
          for (const auto& v : ob.variables) names.push_back(v.name);
          error(*k, "reference names '" + name + "', which is not a variable of this optimisation; expected one of " +
                        join(names) + suggest(name, names));
          continue;
        }
        const ParamDef* info = find_param(block.table(), name);
        if (auto x = get_number(*vn, "reference " + name)) {
          if (auto p = domain_problem(*info, *x); !p.empty()) error(*vn, "reference " + name + ": " + p);
          else ob.reference.design.emplace_back(name, std::get<double>(info->from_file(*x)));
        }
      }
    } else {
      error(*rn, "reference is " + type_name(*rn) + "; expected \"start\" or { variable = value, ... }");
    }
    for (const ObjectiveTerm& term : ob.objective)
      if (term.metric == kFailureRate)
        error(*rn, "a normalised objective divides each term by its reference value, and failure_rate is 0 at a "
                   "good reference; expected an objective without failure_rate");
  }

  // trade_off = [k, ...] | { from, to, step }: weights k and 1 - k on the two terms
  if (const toml::node* tn = t.get("trade_off")) {
    std::vector<double> ks;
    if (const auto* ta = tn->as_array()) {
      for (const auto& e : *ta)
        if (auto v = get_number(e, "trade_off weight")) ks.push_back(*v);
    } else if (const auto* tt = tn->as_table()) {
      check_keys(*tt, {"from", "to", "step"}, "trade_off");
      auto from = get_number(*tt, "from", "from"), to = get_number(*tt, "to", "to"), step = get_number(*tt, "step", "step");
      if (!tt->get("from") || !tt->get("to") || !tt->get("step"))
        error(*tn, "trade_off lacks from, to or step; expected { from = 0, to = 1, step = 0.1 }");
      else if (from && to && step) {
        if (!(*step > 0) || *to < *from) error(*tn, "trade_off from = " + fmt(*from) + ", to = " + fmt(*to) + ", step = " +
                                                   fmt(*step) + "; expected from <= to and step > 0");
        else
          for (long i = 0; *from + double(i) * *step <= *to + 1e-9 * *step; ++i)
            ks.push_back(std::min(*to, *from + double(i) * *step));
      }
    } else {
      error(*tn, "trade_off is " + type_name(*tn) + "; expected [k, ...] or { from = 0, to = 1, step = 0.1 }");
    }
    if (ob.objective.size() != 2)
      error(*tn, "trade_off weighs two terms as k f_a + (1 - k) f_b, and the objective has " +
                     std::to_string(ob.objective.size()) + "; expected objective = { metric_a = 1, metric_b = 1 }");
    std::set<double> seen;
    for (double k : ks) {
      if (!(k >= 0 && k <= 1)) error(*tn, "trade_off weight k = " + fmt(k) + "; expected 0 <= k <= 1");
      else if (!seen.insert(k).second) error(*tn, "trade_off weight k = " + fmt(k) + " given twice; expected each once");
    }
    if (ks.empty()) error(*tn, "trade_off has no weights; expected [k, ...] or { from = 0, to = 1, step = 0.1 }");
    ob.trade_off_k = ks.empty() ? std::numeric_limits<double>::quiet_NaN() : ks.front();
    trade_off_ks_ = ks;
  } else {
    trade_off_ks_.clear();
  }
  ob.objective_text = objective_text(ob.objective, ob.reference.active());
}

std::vector<OptimizeBlock> Parser::expand_trade_off(OptimizeBlock ob) const {
  std::vector<OptimizeBlock> out;
  if (trade_off_ks_.empty()) {
    out.push_back(std::move(ob));
    return out;
  }
  for (double k : trade_off_ks_) {
    OptimizeBlock x = ob;
    x.name = ob.name + "_k" + fmt(k);
    x.trade_off_k = k;
    x.objective[0].weight = k * ob.objective[0].weight;
    x.objective[1].weight = (1.0 - k) * ob.objective[1].weight;
    x.objective_text = objective_text(x.objective, x.reference.active());
    out.push_back(std::move(x));
  }
  return out;
}

}  // namespace ks::study_parse
