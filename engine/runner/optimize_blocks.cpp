// Optimisation blocks (see optimize_blocks.hpp).
#include "runner/optimize_blocks.hpp"

#include <tbb/enumerable_thread_specific.h>
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
#include "runner/placed_task.hpp"

namespace ks {

namespace {
constexpr double kRad2Deg = 180.0 / std::numbers::pi;
const double kNaN = std::numeric_limits<double>::quiet_NaN();


/// Everything an evaluation needs, shared by the objective's copies (thread-safe: per-thread
/// workspaces). Evaluates typed runs: the evaluation set's specs with the variables set to x.
struct Evaluator {
  const Study* study = nullptr;
  Scenario scenario;
  const OptimizeBlock* ob = nullptr;
  const Block* block = nullptr;              // the block whose runs are evaluated
  BlockKind kind = BlockKind::trajectory;
  std::vector<RunSpec> set;                  // the evaluation set's runs
  std::vector<const ParamDef*> vars;         // the variables' table entries
  /// One objective term: scale * metric (or scale / metric); scale = weight / reference value.
  struct Term {
    const MetricDef* metric = nullptr;  // nullptr: failure_rate
    double scale = 1.0;
    bool reciprocal = false;
    double of(double m) const { return reciprocal ? scale * (1.0 / m) : scale * m; }
  };
  std::vector<Term> terms;
  const MetricDef* stop_time = nullptr;      // trajectory: penalty of runs that stopped early
  const MetricDef* ik_error = nullptr;       // trajectory, a placed task: penalty of runs out of reach
  double duration = 0.0;
  bool reach_varies = false;
  /// A normalised objective: each term's metric and the design at the reference, as stored in
  /// /optimizations/<name> ("<metric>_0", "<variable>_0").
  std::vector<std::pair<std::string, double>> references;
  tbb::enumerable_thread_specific<RunWorkspace> workspaces;

  RunSpec run_at(std::size_t run, std::span<const double> x) const {
    RunSpec r = set[run];
    for (std::size_t i = 0; i < vars.size(); ++i) vars[i]->set(r, Cell(x[i]));
    return r;
  }

  /// Reach margin of a run: its start (local methods) or every vertex (vertex_alpha).
  double margin_of(const RunSpec& r) const {
    const TaskPlacement& p = std::get<TrajectoryRun>(r).placement;  // the vertices at the run's place
    const StudyTask placed = p.identity() ? StudyTask{} : place_task(study->task, p, true);
    const auto& verts = p.identity() ? study->task.vertices : placed.vertices;
    const TrajectoryOptions& o = std::get<TrajectoryRun>(r).options;
    double m = reach_margin(study->robot, verts.front(), o.alpha1A);
    if (o.method == TrajectoryMethod::vertex_alpha)
      for (std::size_t v = 2; v <= verts.size() && v - 2 < o.vertex_alpha.size(); ++v)
        m = std::max(m, reach_margin(study->robot, verts[v - 1], o.vertex_alpha[v - 2]));
    return m;
  }
  double constraint(std::span<const double> x) const {
    double m = -std::numeric_limits<double>::infinity();
    for (std::size_t r = 0; r < set.size(); ++r) m = std::max(m, margin_of(run_at(r, x)));
    return m;
  }

  /// The objective of a run with status `good` (ok / converged) and metric values `metric(def)`
  /// (from a fresh outcome or from a results file), penalised when it failed.
  template <class MetricOf>
  double value_of(const RunSpec& r, bool good, std::string_view status, MetricOf metric) const {
    double v = 0.0;
    if (kind == BlockKind::trajectory) {
      if (good) {
        for (const Term& t : terms) v += t.metric ? t.of(metric(*t.metric)) : 0.0;  // failure_rate: 0 for a good run
      } else if (status == to_string(RunStatus::unreachable_start)) {
        v = ob->penalty * (2.0 + std::max(0.0, margin_of(r)));
      } else if (status == to_string(RunStatus::out_of_reach) && ik_error) {
        // a placed task out of reach: the farther (seed 002's IK error [m]), the worse
        const double e = metric(*ik_error);
        v = ob->penalty * (2.0 + (std::isfinite(e) ? e : 1.0));
      } else {  // singular / diverged: the earlier it stopped, the worse
        const double t = metric(*stop_time);
        const double d = duration * std::get<TrajectoryRun>(r).placement.time_scale;  // the run's path
        v = ob->penalty * (1.0 + std::clamp(1.0 - (std::isfinite(t) ? t : 0.0) / d, 0.0, 1.0));
      }
    } else {
      for (const Term& t : terms) {
        if (!t.metric) v += t.scale * (good ? 0.0 : 1.0);
        else if (t.metric->if_failed && !good) v += t.of(t.metric->if_failed(r));
        else v += t.of(metric(*t.metric));
      }
    }
    if (!std::isfinite(v)) v = ob->penalty * 3.0;
    return v;
  }

  /// One run's objective and status.
  std::pair<double, std::string> run_value(std::size_t run, std::span<const double> x, int stride, RunOutcome* keep) {
    const RunSpec r = run_at(run, x);
    RunOutcome o = execute(scenario, r, stride, workspaces.local());
    const double v = value_of(r, o.good(), o.status(), [&](const MetricDef& m) { return cell_number(m.get(o)); });
    std::string status(o.status());
    if (keep) *keep = std::move(o);
    return {v, std::move(status)};
  }

  opt::Evaluation evaluate(std::span<const double> x) {
    const std::size_t n = set.size();
    if (n == 1) {
      auto [v, s] = run_value(0, x, 0, nullptr);
      return {v, s};
    }
    std::vector<std::pair<double, std::string>> r(n);
    const std::vector<double> xc(x.begin(), x.end());
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) { r[i] = run_value(i, xc, 0, nullptr); });
    double sum = 0.0;
    std::size_t bad = 0;
    std::string first_bad;
    const std::string good(statuses(kind).front());
    for (const auto& [v, s] : r) {
      sum += v;
      if (s != good && bad++ == 0) first_bad = s;
    }
    std::string status = bad == 0 ? good : first_bad + " (" + std::to_string(bad) + "/" + std::to_string(n) + " runs)";
    return {sum / static_cast<double>(n), status};
  }
};

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

/// The evaluator of optimisation `index` over `block`, its terms divided by their reference values
/// when the objective is normalised (seed 002 Eq. 7.6: f1^0 / f1, f6 / f6^0): each term's value
/// averaged over the base block's runs at the reference design. Throws std::runtime_error when a
/// reference run is not good or a term's reference value is 0 or not finite.
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
}  // namespace

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
