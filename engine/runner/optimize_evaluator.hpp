#pragma once
// The objective of an optimisation block: the evaluator of its evaluation set's runs at a design x
// (a weighted sum of metric terms, normalised or not, with the penalties of runs that fail), and the
// text helpers its report shares. Internal to runner/optimize_blocks.cpp.
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "optimize/optimize.hpp"
#include "runner/execute.hpp"
#include "runner/optimize_blocks.hpp"
#include "runner/placed_task.hpp"
#include "study/study.hpp"

namespace ks::optimize_detail {

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

/// The evaluator of optimisation `index` over `block`, its terms divided by their reference values
/// when the objective is normalised (seed 002 Eq. 7.6: f1^0 / f1, f6 / f6^0): each term's value
/// averaged over the base block's runs at the reference design. Throws std::runtime_error when a
/// reference run is not good or a term's reference value is 0 or not finite.
std::shared_ptr<Evaluator> make_evaluator(const Study& study, std::size_t index, const Block& block);

/// "name = value unit, ..." of design x (angles in degrees).
std::string fmt_x(const std::vector<std::string>& names, const std::vector<std::string>& units, std::span<const double> x);

/// The stage's options as a study file writes them ("<what>.algorithm = ...", one a line).
std::string stage_text(const char* what, const opt::StageOptions& s);

}  // namespace ks::optimize_detail
