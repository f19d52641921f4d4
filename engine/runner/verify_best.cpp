// The best runs of a results file against their grid (runner/verify_best.hpp).
#include "runner/verify_best.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <ostream>

#include "motion/motion_problem.hpp"
#include "runner/execute.hpp"
#include "schema/params.hpp"

namespace ks {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// The parameters whose value splits a method's runs into separate problems when they have an
/// effect on the run: the state the arm must end in, the robot model (the seed arm's inertia form).
constexpr std::string_view kConditionParams[] = {"end_state", "inertia"};

std::size_t column_of(const std::vector<ColumnSpec>& columns, std::string_view name) {
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (columns[i].name == name) return i;
  return static_cast<std::size_t>(-1);
}

std::string text_of(const Cell& c) {
  if (const auto* s = std::get_if<std::string>(&c)) return *s;
  return "";
}
}  // namespace

std::vector<BestRunRef> best_runs_to_verify(const Study& study, const store::ResultsReader& file,
                                            const std::vector<std::string>& rank_by) {
  std::vector<BestRunRef> out;
  const auto& columns = file.columns();
  const std::size_t status_col = column_of(columns, "status"), method_col = column_of(columns, "method");
  for (std::size_t b = 0; b < study.blocks.size(); ++b) {
    const Block& block = study.blocks[b];
    const bool motion = block.kind() == BlockKind::motion;
    if ((block.kind() != BlockKind::trajectory && !motion) || block.run_count() == 0) continue;
    if (status_col >= columns.size() || (!motion && method_col >= columns.size())) continue;
    // the metrics ranked by (the kind's objective first, with its tie metric), as columns
    const Ranking rank = ranking(block.kind());
    std::vector<std::string> by{std::string(rank.objective)};
    for (const std::string& m : rank_by)
      if (std::find(by.begin(), by.end(), m) == by.end()) by.push_back(m);
    std::vector<std::pair<std::size_t, std::size_t>> by_cols;  // metric column, tie column
    std::vector<std::string> by_names;
    for (const std::string& m : by)
      if (column_of(columns, m) < columns.size()) {
        by_names.push_back(m);
        by_cols.emplace_back(column_of(columns, m), m == rank.objective && !rank.tie.empty()
                                                        ? column_of(columns, rank.tie) : static_cast<std::size_t>(-1));
      }
    // the condition parameters of this block: their column, and the column that controls their effect
    struct Condition {
      std::string name;
      std::size_t col, controller;
      const EffectRule* effect;
    };
    std::vector<Condition> conditions;
    for (std::string_view name : kConditionParams)
      if (const ParamDef* p = find_param(block.table(), name); p && column_of(columns, name) < columns.size())
        conditions.push_back({std::string(name), column_of(columns, name),
                              p->effect.always() ? static_cast<std::size_t>(-1) : column_of(columns, p->effect.controller),
                              &p->effect});
    const std::string good(statuses(block.kind()).front());
    // group -> per ranked metric, its best run
    std::map<std::string, std::vector<std::optional<std::pair<RankKey, BestRunRef>>>> best;
    const std::uint64_t first = study.first_run(b), n = block.run_count();
    constexpr std::uint64_t kPiece = store::kRunsChunkRows;
    for (std::uint64_t at = 0; at < n; at += kPiece) {
      const auto count = static_cast<std::int64_t>(std::min(kPiece, n - at));
      const auto done = file.done_mask(static_cast<std::int64_t>(first + at), count);
      const auto rows = file.read_rows(static_cast<std::int64_t>(first + at), count);
      for (std::size_t i = 0; i < rows.size() && i < done.size(); ++i) {
        if (!done[i]) continue;
        const auto& cells = rows[i].cells;
        if (text_of(cells[status_col]) != good) continue;
        BestRunRef ref;
        ref.run = first + at + i;
        ref.block = b;
        ref.method = motion ? "" : text_of(cells[method_col]);
        ref.group = motion ? "block=" + block.name() : "method=" + ref.method;
        for (const Condition& c : conditions) {
          const bool applies =
              c.controller >= columns.size() ? c.effect->always() : c.effect->applies(text_of(cells[c.controller]));
          if (applies) ref.group += ", " + c.name + "=" + text_of(cells[c.col]);
        }
        auto& slots = best[ref.group];
        slots.resize(by_cols.size());
        for (std::size_t m = 0; m < by_cols.size(); ++m) {
          const double v = cell_number(cells[by_cols[m].first]);
          if (!std::isfinite(v)) continue;  // never a best run (as the run summary)
          const RankKey key = rank_key(v, by_cols[m].second < columns.size() ? cell_number(cells[by_cols[m].second]) : 0.0,
                                       ref.run);
          if (!slots[m] || key < slots[m]->first) slots[m] = std::make_pair(key, ref);
        }
      }
    }
    for (auto& [group, slots] : best) {  // each run once, saying what it is the lowest of
      std::vector<BestRunRef> runs;
      std::vector<std::string> lowest;
      for (std::size_t m = 0; m < slots.size(); ++m) {
        if (!slots[m]) continue;
        const auto run = slots[m]->second.run;  // named: clang 14 cannot capture a structured binding
        auto it = std::find_if(runs.begin(), runs.end(), [&](const BestRunRef& r) { return r.run == run; });
        if (it == runs.end()) {
          runs.push_back(slots[m]->second);
          lowest.push_back(by_names[m]);
        } else {
          lowest[static_cast<std::size_t>(it - runs.begin())] += ", " + by_names[m];
        }
      }
      for (std::size_t r = 0; r < runs.size(); ++r) {
        runs[r].group = "lowest " + lowest[r] + " of " + runs[r].group;
        out.push_back(std::move(runs[r]));
      }
    }
  }
  return out;
}

namespace {
/// What a refinement changes: a trajectory run's dt or knots, a motion run's samples or controls.
enum class Refinement { dt, knots, samples, controls };
constexpr const char* kRefinementNames[] = {"dt", "knots", "samples", "controls"};

/// One refined computation: a run's spec with one refinement applied.
struct Task {
  std::size_t ref = 0;      // index into the runs verified
  Refinement refinement = Refinement::dt;
  int grid = 0;             // 0 (finest) or 1
  bool runnable = true;     // false: beyond the parameter's domain, not run
  RunSpec run;
  RunOutcome outcome;
  bool done = false;
};

/// The refinements of a run: dt (and knots for global_spline's cubic splines), or a motion's samples
/// (and controls when it solves with controls).
std::vector<Refinement> refinements_of(const RunSpec& spec) {
  if (const auto* traj = std::get_if<TrajectoryRun>(&spec)) {
    const TrajectoryOptions& o = traj->options;
    if (o.method == TrajectoryMethod::global_spline && o.global.spline == AlphaSpline::cubic)
      return {Refinement::dt, Refinement::knots};
    return {Refinement::dt};
  }
  if (const auto* m = std::get_if<MotionRun>(&spec)) {
    if (m->solve && m->controls > 0) return {Refinement::samples, Refinement::controls};
    return {Refinement::samples};
  }
  return {};
}

/// The value of metric `name` of `metrics` in outcome `o` (NaN when absent or not numeric).
double metric_value(const std::vector<MetricDef>& metrics, const std::string& name, const RunOutcome& o) {
  for (const MetricDef& m : metrics)
    if (m.name == name) return cell_number(m.get(o));
  return kNaN;
}
}  // namespace

store::VerificationTable verify_best_runs(const Study& study, const store::ResultsReader& file,
                                          const std::vector<BestRunRef>& runs, const BestRunVerifyOptions& options) {
  store::VerificationTable table;
  table.safety_factor = options.gci.safety_factor;
  // The refined specs: grid 0 is the finest (dt/4 or 4K), grid 1 the middle one (dt/2 or 2K).
  std::vector<Task> tasks;
  double duration = 0.0;  // of the study's path [s]
  for (const double d : study.task.durations) duration += d;
  auto affordable = [&](double dt) { return duration / dt + 1.0 <= options.max_samples; };
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const Block& block = study.blocks[runs[i].block];
    const RunSpec spec = block.run(runs[i].run - study.first_run(runs[i].block));
    for (const Refinement refinement : refinements_of(spec))
      for (int grid = 0; grid < 2; ++grid) {
        const int factor = grid == 0 ? 4 : 2;  // kGridRatio^2, kGridRatio
        Task t;
        t.ref = i, t.grid = grid, t.refinement = refinement, t.run = spec;
        if (auto* traj = std::get_if<TrajectoryRun>(&t.run)) {
          TrajectoryOptions& o = traj->options;
          if (refinement == Refinement::dt) {
            o.dt /= factor;
            t.runnable = affordable(o.dt);
          } else {
            const double knots = static_cast<double>(o.global.knots) * factor;
            o.global.knots = static_cast<std::int64_t>(knots);
            t.runnable = PathGlobalOptions::knots_rule.holds(knots) && affordable(o.dt);
          }
        } else if (auto* m = std::get_if<MotionRun>(&t.run)) {
          if (refinement == Refinement::samples) {  // the sample intervals divided by the factor
            m->samples = factor * (motion::motion_sample_count(m->samples, m->controls) - 1) + 1;
            t.runnable = MotionRun::samples_rule.holds(m->samples);
          } else {
            m->controls *= factor;
            t.runnable = MotionRun::controls_rule.holds(m->controls);
          }
        }
        tasks.push_back(std::move(t));
      }
  }
  const Scenario scenario = Scenario::of(study);
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(std::size_t(0), tasks.size(), [&](std::size_t i) {
      Task& t = tasks[i];
      if (!t.runnable || (options.stop && options.stop->load())) return;
      RunWorkspace workspace;
      t.outcome = execute(scenario, t.run, 0, workspace);
      t.done = true;
    });
  });
  // The rows: per run, per refinement, per quantity; grid 3 from the stored row.
  const auto& columns = file.columns();
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const BestRunRef& ref = runs[i];
    const Block& block = study.blocks[ref.block];
    const RunSpec spec = block.run(ref.run - study.first_run(ref.block));
    const auto* traj = std::get_if<TrajectoryRun>(&spec);
    const auto* motion_run = std::get_if<MotionRun>(&spec);
    if (!traj && !motion_run) continue;
    const Record stored = file.read_record(static_cast<std::int64_t>(ref.run));
    auto stored_cell = [&](const std::string& name) -> const Cell* {
      const std::size_t c = column_of(columns, name);
      return c < columns.size() ? &stored.cells[c] : nullptr;
    };
    const Cell* stored_status = stored_cell("status");
    const std::string good(statuses(block.kind()).front());
    const Cell* stored_duration = motion_run ? stored_cell("final_duration") : nullptr;
    const double motion_T = stored_duration ? cell_number(*stored_duration) : kNaN;  // [s]
    for (const Refinement refinement : refinements_of(spec)) {
      const Task* grid[2] = {nullptr, nullptr};
      for (const Task& t : tasks)
        if (t.ref == i && t.refinement == refinement) grid[t.grid] = &t;
      for (const std::string& q : traj ? options.quantities : options.motion_quantities) {
        const MetricDef* def = nullptr;
        for (const MetricDef& m : block.metrics())
          if (m.name == q && m.type == CellType::f64) def = &m;
        if (!def || (traj && q == "opt_objective" && traj->options.method != TrajectoryMethod::global_spline)) continue;
        const Cell* stored_value = stored_cell(q);
        if (!stored_value) continue;
        store::VerificationRow row;
        row.run = static_cast<std::int64_t>(ref.run);
        row.block = block.name();
        row.method = ref.method;
        row.group = ref.group;
        row.quantity = q;
        row.unit = def->unit;
        row.refinement = kRefinementNames[static_cast<int>(refinement)];
        row.ratio = kGridRatio;
        bool all_good = stored_status && text_of(*stored_status) == good;
        for (int g = 0; g < 3; ++g) {
          const int factor = g == 0 ? 4 : g == 1 ? 2 : 1;  // grid 0: r^2, grid 1: r, grid 2 (3): 1
          if (traj) {
            const bool knots = refinement == Refinement::knots;
            const double k = traj->options.method == TrajectoryMethod::global_spline &&
                                     traj->options.global.spline == AlphaSpline::cubic
                                 ? static_cast<double>(traj->options.global.knots)
                                 : kNaN;
            row.dt[g] = knots ? traj->options.dt : traj->options.dt / factor;
            row.knots[g] = knots ? k * factor : k;
          } else {  // dt: the sample step at the stored duration; knots: the controls per joint
            const bool controls = refinement == Refinement::controls;
            const int K = motion_run->controls * (controls ? factor : 1);
            const int N = motion::motion_sample_count(motion_run->samples, K);
            row.dt[g] = motion_T / (controls ? N - 1 : factor * (N - 1));
            row.knots[g] = static_cast<double>(K);
          }
          if (g == 2) {
            row.value[g] = cell_number(*stored_value);
            row.status[g] = stored_status ? text_of(*stored_status) : "";
            continue;
          }
          const Task* t = grid[g];
          if (!t || !t->runnable) {
            row.value[g] = kNaN;
            row.status[g] = "not_run";
            all_good = false;
            continue;
          }
          if (!t->done) {
            row.value[g] = kNaN;
            row.status[g] = "interrupted";
            all_good = false;
            continue;
          }
          row.value[g] = metric_value(block.metrics(), q, t->outcome);
          row.status[g] = std::string(t->outcome.status());
          all_good = all_good && t->outcome.good();
        }
        GciResult r = grid_convergence(row.value[0], row.value[1], row.value[2], kGridRatio, options.gci);
        if (!all_good) r = grid_convergence(kNaN, kNaN, kNaN, kGridRatio, options.gci);  // a failed grid: not_enough
        row.convergence = std::string(to_string(r.convergence));
        row.order = r.order, row.extrapolated = r.extrapolated, row.gci_fine = r.gci_fine, row.gci_coarse = r.gci_coarse;
        table.rows.push_back(std::move(row));
      }
    }
  }
  return table;
}

namespace {
std::string num(double v) {
  char s[32];
  std::snprintf(s, sizeof s, "%.4g", v);
  return s;
}
std::string percent(double v) {
  char s[32];
  if (v == 0.0) return "0 %";
  std::snprintf(s, sizeof s, 100.0 * v < 100.0 ? "%.2g %%" : "%.0f %%", 100.0 * v);
  return s;
}
std::string with_unit(double v, const std::string& unit) { return unit.empty() ? num(v) : num(v) + " " + unit; }
}  // namespace

std::string verification_phrase(const store::VerificationRow& r) {
  Convergence c = Convergence::not_enough;
  parse(r.convergence, c);
  // the grids as knots or controls per joint, else as the step [s]
  const bool knots = r.refinement == "knots" || r.refinement == "controls";
  const std::string grid_unit = r.refinement == "knots" ? " knots" : r.refinement == "controls" ? " controls" : " s";
  auto grids = [&] {
    std::string s;
    for (int g = 2; g >= 0; --g) s += (g == 2 ? "" : ", ") + num(knots ? r.knots[g] : r.dt[g]);
    return s + grid_unit;
  };
  auto values = [&] {
    std::string s;
    for (int g = 2; g >= 0; --g) s += (g == 2 ? "" : ", ") + num(r.value[g]);
    return s + (r.unit.empty() ? "" : " " + r.unit);
  };
  switch (c) {
    case Convergence::monotone:
    case Convergence::unchanged:
      return r.quantity + " = " + with_unit(r.value[2], r.unit) + " (GCI " + percent(r.gci_coarse) +
             (c == Convergence::monotone && std::isfinite(r.order) ? ", order " + num(r.order) : "") + ", converged " +
             with_unit(r.extrapolated, r.unit) + ")";
    case Convergence::oscillatory:
      return r.quantity + " oscillates (" + values() + " at " + grids() + "): no GCI";
    case Convergence::divergent:
      return r.quantity + " diverges (" + values() + " at " + grids() + "): no GCI";
    case Convergence::not_enough:
      break;
  }
  std::string why;
  for (int g = 1; g >= 0; --g)
    if (r.status[g] != "ok") why += (why.empty() ? "" : ", ") + r.status[g] + " at " + num(knots ? r.knots[g] : r.dt[g]) +
                                    grid_unit;
  if (r.status[2] != "ok") why += (why.empty() ? "" : ", ") + r.status[2] + " as stored";
  return r.quantity + ": not verified (" + (why.empty() ? "a value is not finite" : why) + ")";
}

void print_verification(std::ostream& out, const store::VerificationTable& table) {
  if (table.rows.empty()) return;
  out << "best runs against the grid (dt, dt/2, dt/4; global_spline also K, 2K, 4K knots; motions 2 and 4 times "
         "the sample intervals, 2K and 4K controls; GCI of the run as stored, Fs = " << num(table.safety_factor) << "):\n";
  const auto& rows = table.rows;
  for (std::size_t i = 0; i < rows.size();) {
    if (i == 0 || rows[i - 1].run != rows[i].run)
      out << "  run " << rows[i].run << " (block " << rows[i].block << ", " << rows[i].group << ")\n";
    std::string label = rows[i].refinement + ":";
    label.resize(std::max<std::size_t>(label.size() + 1, 7), ' ');
    out << "    " << label << verification_phrase(rows[i]);
    std::size_t j = i + 1;
    for (; j < rows.size() && rows[j].run == rows[i].run && rows[j].refinement == rows[i].refinement; ++j)
      out << "; " << verification_phrase(rows[j]);
    out << '\n';
    i = j;
  }
}

}  // namespace ks
