// The objective of an optimisation block (see optimize_evaluator.hpp).
#include "runner/optimize_evaluator.hpp"

#include <numbers>
#include <sstream>
#include <stdexcept>

#include "methods/closed_form/seed_cases.hpp"
#include "runner/placed_task.hpp"

namespace ks::optimize_detail {

namespace {
constexpr double kRad2Deg = 180.0 / std::numbers::pi;

/// The evaluator of optimisation `index` over the runs of `block` (its base block, or the
/// polish_from block whose cells are ranked).
std::shared_ptr<Evaluator> make_plain_evaluator(const Study& study, std::size_t index, const Block& block) {
  const OptimizeBlock& ob = study.optimizations.at(index);
  auto e = std::make_shared<Evaluator>();
  e->study = &study;
  e->scenario = Scenario::of(study);
  e->ob = &ob;
  e->block = &block;
  e->kind = block.kind();
  for (std::uint64_t r = 0; r < block.run_count(); ++r) e->set.push_back(block.run(r));
  for (const auto& v : ob.variables) {
    const ParamDef* p = find_param(block.table(), v.name);
    if (!p) throw std::invalid_argument("optimization " + ob.name + ": no parameter " + v.name);
    e->vars.push_back(p);
    if (p->file_unit == FileUnit::deg && e->kind == BlockKind::trajectory) e->reach_varies = true;
  }
  const auto& ms = block.metrics();
  auto metric = [&](std::string_view n) -> const MetricDef* {
    for (const MetricDef& m : ms)
      if (m.name == n) return &m;
    return nullptr;
  };
  for (const ObjectiveTerm& t : ob.objective) {
    if (t.metric == kFailureRate) e->terms.push_back({nullptr, t.weight, false});
    else if (const MetricDef* d = metric(t.metric)) e->terms.push_back({d, t.weight, t.reciprocal});
    else throw std::invalid_argument("optimization " + ob.name + ": no metric " + t.metric);
  }
  e->stop_time = metric("stop_time");
  e->ik_error = metric("ik_error");
  for (double d : study.task.durations) e->duration += d;
  if (e->duration <= 0) e->duration = 1.0;
  return e;
}

/// The reference design of a normalised objective [stored units]: each variable at the value the
/// reference names, else at its start (the file's start, else the block's value).
std::vector<double> reference_x(const OptimizeBlock& ob, const Evaluator& base) {
  std::vector<double> x;
  for (std::size_t i = 0; i < ob.variables.size(); ++i) {
    const OptimizeVariable& v = ob.variables[i];
    double value = std::isnan(v.start) ? cell_number(base.vars[i]->get(base.set.front())) : v.start;
    for (const auto& [name, d] : ob.reference.design)
      if (name == v.name) value = d;
    x.push_back(value);
  }
  return x;
}

}  // namespace

std::shared_ptr<Evaluator> make_evaluator(const Study& study, std::size_t index, const Block& block) {
  auto e = make_plain_evaluator(study, index, block);
  const OptimizeBlock& ob = study.optimizations.at(index);
  if (!ob.reference.active()) return e;
  auto base = &block == &ob.block() ? e : make_plain_evaluator(study, index, ob.block());
  const std::vector<double> x = reference_x(ob, *base);
  auto where = [&] {
    std::vector<std::string> names, units;
    for (const auto& v : ob.variables) names.push_back(v.name), units.push_back(v.unit);
    return fmt_x(names, units, x);
  };
  std::vector<double> raw(e->terms.size(), 0.0);  // each term without its weight: metric or 1 / metric
  for (std::size_t r = 0; r < base->set.size(); ++r) {
    const RunOutcome o = execute(base->scenario, base->run_at(r, x), 0, base->workspaces.local());
    if (!o.good())
      throw std::runtime_error("optimization " + ob.name + ": the reference design (" + where() + ") ended " +
                               std::string(o.status()) + " (run " + std::to_string(r + 1) + " of " +
                               std::to_string(base->set.size()) +
                               "); a normalised objective needs a good reference run: expected another reference");
    for (std::size_t j = 0; j < e->terms.size(); ++j) {
      const double m = cell_number(e->terms[j].metric->get(o));
      raw[j] += e->terms[j].reciprocal ? 1.0 / m : m;
    }
  }
  for (std::size_t j = 0; j < e->terms.size(); ++j) {
    Evaluator::Term& t = e->terms[j];
    const double ref = raw[j] / static_cast<double>(base->set.size());
    const double metric = t.reciprocal ? 1.0 / ref : ref;
    if (!std::isfinite(ref) || ref == 0.0 || !std::isfinite(metric))
      throw std::runtime_error("optimization " + ob.name + ": " + t.metric->name + " at the reference design (" +
                               where() + ") is " + [&] { std::ostringstream os; os.precision(6); os << metric; return os.str(); }() +
                               "; a normalised objective divides by it: expected a reference where it is finite and nonzero");
    e->references.emplace_back(t.metric->name + "_0", metric);
    t.scale /= ref;  // weight / (the term at the reference)
  }
  for (std::size_t i = 0; i < x.size(); ++i) e->references.emplace_back(ob.variables[i].name + "_0", x[i]);
  return e;
}

std::string fmt_x(const std::vector<std::string>& names, const std::vector<std::string>& units, std::span<const double> x) {
  std::ostringstream os;
  os.precision(6);
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (i) os << ", ";
    if (units[i] == "rad") os << names[i] << " = " << x[i] * kRad2Deg << " deg";
    else os << names[i] << " = " << x[i] << (units[i].empty() ? "" : " " + units[i]);
  }
  return os.str();
}

std::string stage_text(const char* what, const opt::StageOptions& s) {
  std::ostringstream os;
  os << what << ".algorithm = " << opt::to_string(s.algorithm) << '\n';
  auto put = [&](const char* k, double v) {
    if (v > 0) os << what << '.' << k << " = " << v << '\n';
  };
  put("max_evals", s.max_evals);
  put("population", s.population);
  if (s.islands > 1) put("islands", s.islands);
  put("max_time", s.max_time_s);
  put("xtol_rel", s.xtol_rel);
  put("xtol_abs", s.xtol_abs);
  put("ftol_rel", s.ftol_rel);
  put("ftol_abs", s.ftol_abs);
  if (s.algorithm == opt::Algorithm::LD_SLSQP) put("fd_step", s.fd_step);
  put("initial_step", s.initial_step);
  if (std::isfinite(s.stopval)) os << what << ".stopval = " << s.stopval << '\n';
  return os.str();
}

}  // namespace ks::optimize_detail
