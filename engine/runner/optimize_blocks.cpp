// Optimisation blocks (see optimize_blocks.hpp).
#include "runner/optimize_blocks.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <numbers>
#include <numeric>
#include <ostream>
#include <sstream>

#include "methods/closed_form/seed_cases.hpp"
#include "runner/execute.hpp"
#include "runner/optimize_evaluator.hpp"
#include "runner/placed_task.hpp"

namespace ks {

namespace {
const double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

using optimize_detail::Evaluator;
using optimize_detail::fmt_x;
using optimize_detail::make_evaluator;
using optimize_detail::stage_text;

double reach_margin(const PlanarArm3& a, const Eigen::Vector2d& p, double alpha) {
  const double x2 = p.x() - a.l[2] * std::cos(alpha), y2 = p.y() - a.l[2] * std::sin(alpha);
  const double c2 = (x2 * x2 + y2 * y2 - a.l[0] * a.l[0] - a.l[1] * a.l[1]) / (2.0 * a.l[0] * a.l[1]);
  return std::abs(c2) - 1.0;
}

opt::Problem make_problem(const Study& study, std::size_t index) {
  const OptimizeBlock& ob = study.optimizations.at(index);
  auto e = make_evaluator(study, index, ob.block());
  opt::Problem p;
  const RunSpec& base = e->set.front();
  for (std::size_t i = 0; i < ob.variables.size(); ++i) {
    const auto& v = ob.variables[i];
    opt::Variable var{v.name, v.unit, v.lower, v.upper, v.start};
    if (std::isnan(var.start)) var.start = cell_number(e->vars[i]->get(base));  // the block's value (the preset's)
    p.variables.push_back(std::move(var));
  }
  p.objective = [e](std::span<const double> x) { return e->evaluate(x); };
  if (e->kind == BlockKind::trajectory && e->reach_varies)
    p.constraint = [e](std::span<const double> x) { return e->constraint(x); };
  return p;
}

std::vector<opt::Start> best_cells(const Study& study, std::size_t index, const OptimizeRunOptions& options) {
  const OptimizeBlock& ob = study.optimizations.at(index);
  std::vector<opt::Start> out;
  if (ob.polish_block.empty() || ob.polish_best <= 0) return out;
  const std::size_t bi = study.block_index(ob.polish_block);
  if (bi == Block::npos) throw std::invalid_argument("optimization " + ob.name + ": no block " + ob.polish_block);
  const Block& lb = study.blocks[bi];
  const std::uint64_t n = lb.run_count(), first = study.first_run(bi);
  // The cells' objective: same weighting and penalties as the optimisation, from the cells' metrics.
  auto e = make_evaluator(study, index, lb);
  e->vars.clear();  // cells keep their own parameters
  std::vector<double> value(n, kNaN);
  std::vector<std::string> status(n);
  bool from_file = false;
  if (options.cells) {
    try {
      const auto done = options.cells->done_mask();
      bool all = done.size() >= first + n;
      for (std::uint64_t r = 0; all && r < n; ++r) all = done[first + r] != 0;
      if (all) {
        std::map<const MetricDef*, std::vector<double>> column;  // the metrics the objective reads
        for (const auto& t : e->terms)
          if (t.metric) column[t.metric] = options.cells->read_f64(t.metric->name);
        if (e->stop_time) column[e->stop_time] = options.cells->read_f64(e->stop_time->name);
        const auto st = options.cells->read_str("status");
        const std::string good(statuses(e->kind).front());
        for (std::uint64_t r = 0; r < n; ++r) {
          const std::size_t g = first + r;
          status[r] = st[g];
          value[r] = e->value_of(e->set[r], st[g] == good, st[g], [&](const MetricDef& m) { return column.at(&m)[g]; });
        }
        from_file = true;
      }
    } catch (const std::exception&) {
      from_file = false;
    }
  }
  if (!from_file) {  // evaluate the cells here, in parallel (indexed: deterministic)
    tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
    arena.execute([&] {
      tbb::parallel_for(std::uint64_t(0), n, [&](std::uint64_t r) {
        const std::vector<double> none;
        auto [v, s] = e->run_value(static_cast<std::size_t>(r), none, 0, nullptr);
        value[r] = v;
        status[r] = s;
      });
    });
  }
  std::vector<std::uint64_t> idx(n);
  std::iota(idx.begin(), idx.end(), 0);
  std::stable_sort(idx.begin(), idx.end(), [&](auto a, auto b) { return value[a] < value[b]; });
  for (std::uint64_t r : idx) {
    if (static_cast<int>(out.size()) >= ob.polish_best) break;
    opt::Start s;
    for (const auto& v : ob.variables) s.x.push_back(cell_number(find_param(lb.table(), v.name)->get(e->set[r])));
    s.value = value[r];
    s.status = status[r];
    s.run = static_cast<std::int64_t>(first + r);
    out.push_back(std::move(s));
  }
  return out;
}

OptimizeResult run_optimization(const Study& study, std::size_t index, const OptimizeRunOptions& options) {
  const OptimizeBlock& ob = study.optimizations.at(index);
  auto e = make_evaluator(study, index, ob.block());
  opt::Problem problem = make_problem(study, index);
  opt::PipelineOptions po;
  po.global = ob.global;
  po.local = ob.local;
  po.local_starts = ob.local_starts;
  po.distinct = ob.distinct;
  po.threads = options.threads;
  po.seed = ob.seed;
  po.constraint = ob.constraint;
  po.stop = options.stop;
  po.starts = best_cells(study, index, options);

  OptimizeResult res;
  {
    tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
    arena.execute([&] { res.summary = opt::optimize(problem, po); });
  }
  const opt::Summary& s = res.summary;
  store::OptimizationRecord& r = res.record;
  r.name = ob.name;
  r.kind = std::string(to_string(ob.block().kind()));
  r.preset = ob.preset;
  r.objective = ob.objective_text;
  r.variables = s.variables;
  r.units = s.units;
  for (const auto& v : problem.variables) {
    r.lower.push_back(v.lower);
    r.upper.push_back(v.upper);
  }
  const std::size_t d = r.variables.size();
  for (const auto& ev : s.evaluations) {
    r.x.insert(r.x.end(), ev.x.begin(), ev.x.end());
    r.value.push_back(ev.value);
    r.constraint.push_back(ev.constraint);
    r.stage.push_back(ev.stage);
    r.status.push_back(ev.status);
    r.start.push_back(ev.start);
  }
  for (const auto& st : s.stages) {
    store::OptimizationStage x;
    x.name = st.name;
    x.algorithm = st.algorithm;
    x.result = st.result;
    x.wall_time_s = st.wall_time_s;
    x.evaluations = static_cast<std::int64_t>(st.evaluations);
    x.best_objective = st.best_value;
    x.best_x = st.best_x.empty() ? std::vector<double>(d, kNaN) : st.best_x;
    x.best_status = st.best_status;
    r.stages.push_back(std::move(x));
  }
  for (std::size_t i = 0; i < s.local_from.size(); ++i) {
    r.local_from.insert(r.local_from.end(), s.local_from[i].begin(), s.local_from[i].end());
    r.local_to.insert(r.local_to.end(), s.local_to[i].begin(), s.local_to[i].end());
    r.local_value.push_back(s.local_values[i]);
  }
  r.best_objective = s.best_value;
  r.best_x = s.best_x;
  r.best_status = s.best_status;
  r.best_stage = s.best_stage;
  r.wall_time_s = s.wall_time_s;
  r.seed = static_cast<std::int64_t>(ob.seed);
  {
    std::ostringstream os;
    os << "objective = " << ob.objective_text << "\nconstraint = "
       << (ob.constraint == opt::ConstraintMode::automatic ? "auto" : "penalty") << "\npenalty = " << ob.penalty
       << "\nseed = " << ob.seed << '\n';
    if (ob.global) os << stage_text("global", *ob.global);
    if (ob.local) os << stage_text("local", *ob.local) << "local.starts = " << ob.local_starts << '\n';
    if (!ob.polish_block.empty()) os << "polish_from = " << ob.polish_block << ", best " << ob.polish_best << '\n';
    os << "evaluation_set = " << e->set.size() << " run(s)\n";
    r.settings = os.str();
  }
  // The best point's run (first of the set): metrics and full history.
  if (!s.best_x.empty()) {
    RunOutcome o;
    e->run_value(0, s.best_x, 1, &o);
    for (const MetricDef& m : e->block->metrics()) r.best_metrics.emplace_back(m.name, cell_number(m.get(o)));
    r.history = std::move(o.history);
  }
  // A seed row: the thesis' optimum and figures, and this objective at the thesis' printed point.
  res.value_at_thesis = kNaN;
  if (const SeedCase* c = ob.preset.empty() ? nullptr : find_seed_case(ob.preset)) {
    r.reference = {{"thesis_E", c->E}, {"thesis_tau1_inf", c->tau_inf[0]}, {"thesis_tau2_inf", c->tau_inf[1]},
                   {"thesis_tau3_inf", c->tau_inf[2]}};
    const TrajectoryOptions to = c->options();
    std::vector<double> xt;
    for (const auto& v : ob.variables) {
      double t = kNaN;
      if (v.name == "k") t = to.k;
      else if (v.name == "alpha1A") t = to.alpha1A;
      else if (v.name.starts_with("vertex_alpha_")) {
        const std::size_t k = std::stoul(v.name.substr(13));
        if (k >= 2 && k - 2 < to.vertex_alpha.size()) t = to.vertex_alpha[k - 2];
      }
      r.reference.emplace_back("thesis_" + v.name, t);
      xt.push_back(t);
    }
    bool ok = true;
    for (double t : xt) ok = ok && std::isfinite(t);
    if (ok && !xt.empty()) {
      res.value_at_thesis = e->evaluate(xt).value;
      r.reference.emplace_back("objective_at_thesis_x", res.value_at_thesis);
    }
  }
  r.reference.insert(r.reference.end(), e->references.begin(), e->references.end());
  if (!std::isnan(ob.trade_off_k)) r.reference.emplace_back("trade_off_k", ob.trade_off_k);
  return res;
}

void print_optimization(std::ostream& os, const Study& study, std::size_t index, const OptimizeResult& res) {
  const OptimizeBlock& ob = study.optimizations.at(index);
  const auto& r = res.record;
  os << "optimization " << ob.name << " (" << r.kind << (ob.preset.empty() ? "" : ", preset " + ob.preset)
     << "): minimise " << ob.objective_text << " over " << r.variables.size() << " variable(s), "
     << r.size() << " evaluations, " << res.summary.wall_time_s << " s\n";
  res.summary.print(os);
  char line[512];
  std::snprintf(line, sizeof line, "  kinesweep: %s = %.6g at %s [%s]\n", ob.objective_text.c_str(), r.best_objective,
                fmt_x(r.variables, r.units, r.best_x).c_str(), r.best_status.c_str());
  os << line;
  BlockKind kind = BlockKind::trajectory;
  bool shown = false;
  if (parse(r.kind, kind))
    for (std::string_view key : key_metrics(kind))
      for (const auto& [k, v] : r.best_metrics)
        if (k == key) {
          std::snprintf(line, sizeof line, "    %s = %.6g", k.c_str(), v);
          os << line;
          shown = true;
        }
  if (shown) os << '\n';
  if (ob.reference.active()) {  // each term normalised at the best point, and their unweighted sum (seed 002 Eq. 7.9)
    double index_sum = 0.0;
    std::string terms;
    for (const ObjectiveTerm& t : ob.objective) {
      double ref = kNaN, best = kNaN;
      for (const auto& [k, v] : r.reference)
        if (k == t.metric + "_0") ref = v;
      for (const auto& [k, v] : r.best_metrics)
        if (k == t.metric) best = v;
      const double ratio = t.reciprocal ? ref / best : best / ref;
      index_sum += ratio;
      std::snprintf(line, sizeof line, "    %s: %.6g at the reference, %.6g at the best (%s = %.4f)\n", t.metric.c_str(),
                    ref, best, t.reciprocal ? "f_0/f" : "f/f_0", ratio);
      terms += line;
    }
    os << terms;
    std::snprintf(line, sizeof line, "    normalised terms' sum (seed 002 Eq. 7.9) = %.4f (%.4f at the reference)\n",
                  index_sum, double(ob.objective.size()));
    os << line;
  }
  if (const SeedCase* c = ob.preset.empty() ? nullptr : find_seed_case(ob.preset)) {
    std::vector<double> xt;
    for (const auto& [k, v] : r.reference)
      if (k.starts_with("thesis_") && k != "thesis_E" && !k.starts_with("thesis_tau")) xt.push_back(v);
    std::snprintf(line, sizeof line, "  thesis:    E = %.2f at %s; kinesweep's %s there = %.6g\n", c->E,
                  xt.size() == r.variables.size() ? fmt_x(r.variables, r.units, xt).c_str() : "?",
                  ob.objective_text.c_str(), res.value_at_thesis);
    os << line;
  }
}

std::vector<OptimizeResult> run_optimizations(const Study& study, store::ResultsWriter* writer,
                                              const OptimizeRunOptions& options, std::ostream* os) {
  std::vector<OptimizeResult> out;
  for (std::size_t i = 0; i < study.optimizations.size(); ++i) {
    if (options.stop && options.stop->load()) break;
    OptimizeResult r = run_optimization(study, i, options);
    const bool empty = r.summary.evaluations.empty();
    if (writer && !empty) writer->write_optimization(r.record);
    if (os && !empty) {
      if (i == 0) *os << '\n';
      print_optimization(*os, study, i, r);
    }
    out.push_back(std::move(r));
    if (out.back().summary.stopped) break;
  }
  return out;
}

}  // namespace ks
