#include "runner/sweep.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/info.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <ostream>

#include "methods/path_global/slsqp.hpp"
#include "methods/closed_form/seed_cases.hpp"
#include "methods/closed_form/lanes.hpp"
#include "runner/landscape.hpp"

namespace ks {

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Job {
  std::uint64_t id = 0;
  RunRef ref;
  Record row;
  store::EncodedHistory history;
  double seconds = 0;  // executing the run and encoding its history
  bool interrupted = false;  // stopped by a signal before its end: not written
};
struct Batch {
  std::vector<Job> jobs;
};

const std::string& as_str(const Cell& c) {
  static const std::string empty;
  const std::string* s = std::get_if<std::string>(&c);
  return s ? *s : empty;
}

/// The writer-side bookkeeping: landscape cells, status counts, best rows, seed rows.
class Accumulator {
 public:
  /// `fill` (SweepOptions::fill_landscape, may be empty) is given each landscape once begun.
  /// `landscapes` false: no grid is written (SweepOptions::landscapes). `all_done`: every run was
  /// done before the sweep, so add_previous writes every cell before the writer's next commit.
  Accumulator(const Study& study, const StudySchema& schema, store::ResultsWriter& writer,
              const std::function<bool(std::size_t, std::size_t)>& fill, bool landscapes, bool all_done)
      : study_(study), schema_(schema), writer_(writer) {
    for (std::size_t b = 0; b < study.blocks.size(); ++b) {
      grids_.emplace_back(study.blocks[b], landscapes);
      grids_.back().begin(writer, all_done);
      filled_.push_back(grids_.back().enabled() && fill && fill(b, grids_.back().handle()));
      BlockReport r;
      r.name = study.blocks[b].name();
      r.kind = study.blocks[b].kind();
      r.runs = study.blocks[b].run_count();
      report_.blocks.push_back(std::move(r));
    }
    auto metric = [&](std::size_t b, std::string_view name) {
      const auto& ms = study.blocks[b].metrics();
      for (std::size_t j = 0; j < ms.size(); ++j)
        if (ms[j].name == name) return schema.metric_column[b][j];
      return std::size_t(0);
    };
    for (std::size_t b = 0; b < study.blocks.size(); ++b) {  // column indices, looked up once
      const Block& block = study.blocks[b];
      Columns c;
      const Ranking rank = ranking(block.kind());
      c.value = metric(b, rank.objective);
      if (!rank.tie.empty()) c.tie = metric(b, rank.tie);
      if (block.kind() == BlockKind::trajectory) {
        for (int j = 0; j < 3; ++j) c.tau[j] = metric(b, "tau" + std::to_string(j + 1) + "_inf");
        c.preset = schema.param_column[b][block.column_index("preset")];
        const std::size_t inertia = block.column_index("inertia");  // the seed's closed-form 3R only
        c.inertia = inertia == Block::npos ? Columns::npos : schema.param_column[b][inertia];
        c.seed_arm = block.context().robot.joints == 3 && block.context().robot.planar;
      }
      columns_.push_back(c);
    }
    candidates_.assign(study.blocks.size(), {});
  }

  void add(std::uint64_t id, const RunRef& ref, const Record& row) {
    const Block& block = study_.blocks[ref.block];
    BlockReport& br = report_.blocks[ref.block];
    const std::string& status = as_str(row.cells[schema_.status]);
    ++br.by_status[status];
    grids_[ref.block].add(ref.local, row, schema_, ref.block, writer_);
    const bool traj = block.kind() == BlockKind::trajectory;
    const bool good = status == statuses(block.kind()).front();
    const Columns& c = columns_[ref.block];
    if (good)
      consider_best(br, rank_key(cell_number(row.cells[c.value]), c.tie == Columns::npos ? 0.0 : cell_number(row.cells[c.tie]), id),
                    row, ref.block);
    if (traj && c.seed_arm && is_seed_preset(as_str(row.cells[c.preset]))) add_seed(id, row, ref.block);
  }

  /// Whether the columns a done run is counted by (status, and a seed arm's preset) are labelled in
  /// the file, so that add_columns can read them as codes (format 4 files; the file's columns are
  /// the schema's, in its order).
  bool columnar() const {
    const auto& file = writer_.columns();
    if (file.size() != schema_.columns.size()) return false;
    const auto labelled = [&](std::size_t col) { return !file[col].labels.empty(); };
    if (!labelled(schema_.status)) return false;
    for (std::size_t b = 0; b < columns_.size(); ++b)
      if (study_.blocks[b].kind() == BlockKind::trajectory && columns_[b].seed_arm && !labelled(columns_[b].preset))
        return false;
    return true;
  }

  /// What add() does for the done runs among [first, first + n) (done[id]), from typed column reads
  /// instead of Records: status counts and landscape cells at once; the best-run candidates' keys
  /// and the seed runs' ids kept for finish_columns(), which reads those few rows whole.
  void add_columns(std::uint64_t first, std::uint64_t n, const std::vector<bool>& done) {
    const auto& labels = writer_.columns()[schema_.status].labels;
    const std::vector<std::uint16_t> codes = writer_.read_codes(schema_.columns[schema_.status].name,
                                                                static_cast<std::int64_t>(first), static_cast<std::int64_t>(n));
    std::map<std::size_t, std::vector<double>> numbers;  // schema column -> this piece's values
    const auto column = [&](std::size_t col) -> const std::vector<double>& {
      auto it = numbers.find(col);
      if (it == numbers.end())
        it = numbers.emplace(col, writer_.read_numbers(schema_.columns[col].name, static_cast<std::int64_t>(first),
                                                       static_cast<std::int64_t>(n))).first;
      return it->second;
    };
    for (std::size_t b = 0; b < study_.blocks.size(); ++b) {
      const Block& block = study_.blocks[b];
      const std::uint64_t lo = std::max(first, study_.first_run(b)), hi = std::min(first + n, study_.first_run(b) + block.run_count());
      if (lo >= hi) continue;
      BlockReport& br = report_.blocks[b];
      const Columns& c = columns_[b];
      const auto names = statuses(block.kind());
      std::vector<double> kind_code(labels.size() + 1, kNaN);  // label code -> index in statuses(kind)
      for (std::size_t l = 0; l < labels.size(); ++l)
        for (std::size_t s = 0; s < names.size(); ++s)
          if (names[s] == labels[l]) kind_code[l] = static_cast<double>(s);
      std::vector<std::uint64_t> count(labels.size() + 1, 0);
      const std::vector<double>& value = column(c.value);
      const std::vector<double>* tie = c.tie == Columns::npos ? nullptr : &column(c.tie);
      std::vector<const double*> grid_columns;  // the grid's metric columns, in its order
      const bool gridded = grids_[b].enabled() && !filled_[b];
      if (gridded)
        for (std::size_t col : grids_[b].columns(schema_, b)) grid_columns.push_back(column(col).data());
      std::vector<double> values(grid_columns.size());
      const bool seeds = block.kind() == BlockKind::trajectory && c.seed_arm;
      const std::vector<std::uint16_t> presets =
          seeds ? writer_.read_codes(schema_.columns[c.preset].name, static_cast<std::int64_t>(first), static_cast<std::int64_t>(n))
                : std::vector<std::uint16_t>{};
      auto& keys = candidates_[b];
      // Every run of the range done (a merge, a finished file): its cells in one write per metric.
      const bool whole = gridded && std::all_of(done.begin() + lo, done.begin() + hi, [](bool d) { return d; });
      if (whole) {
        std::vector<double> range_codes(hi - lo);
        for (std::uint64_t id = lo; id < hi; ++id)
          range_codes[id - lo] = kind_code[std::min<std::size_t>(codes[id - first], labels.size())];
        std::vector<const double*> at(grid_columns.size());
        for (std::size_t j = 0; j < at.size(); ++j) at[j] = grid_columns[j] + (lo - first);
        grids_[b].add_range(lo - study_.first_run(b), hi - lo, range_codes.data(), at, schema_, b, writer_);
      }
      for (std::uint64_t id = lo; id < hi; ++id) {
        if (!done[id]) continue;
        const std::size_t i = id - first;
        const std::size_t code = std::min<std::size_t>(codes[i], labels.size());
        ++count[code];
        if (gridded && !whole) {
          for (std::size_t j = 0; j < grid_columns.size(); ++j) values[j] = grid_columns[j][i];
          grids_[b].add_cell(id - study_.first_run(b), kind_code[code], values.data(), schema_, b, writer_);
        }
        if (kind_code[code] == 0.0) {  // the good status: a best-run candidate by the ranking rule
          const RankKey k = rank_key(value[i], tie ? (*tie)[i] : 0.0, id);
          if (std::isfinite(k.objective) && (keys.size() < 3 || k < keys.back())) {
            keys.insert(std::upper_bound(keys.begin(), keys.end(), k), k);
            if (keys.size() > 3) keys.pop_back();
          }
        }
        if (seeds && presets[i] < writer_.columns()[c.preset].labels.size() &&
            is_seed_preset(writer_.columns()[c.preset].labels[presets[i]]))
          seed_ids_.push_back(id);
      }
      for (std::size_t l = 0; l < count.size(); ++l)
        if (count[l]) br.by_status[l < labels.size() ? labels[l] : std::string()] += count[l];
    }
  }

  /// The rows add_columns set aside, read whole: the best-run candidates (in rank order, so the
  /// block's best rows are those add() would have kept) and the seed runs.
  void finish_columns() {
    for (std::size_t b = 0; b < candidates_.size(); ++b)
      for (const RankKey& k : candidates_[b])
        consider_best(report_.blocks[b], k, writer_.read_rows(static_cast<std::int64_t>(k.run), 1).front(), b);
    candidates_.assign(candidates_.size(), {});
    for (std::uint64_t id : seed_ids_)
      if (seed_.size() < 1000) add_seed(id, writer_.read_rows(static_cast<std::int64_t>(id), 1).front(), study_.locate(id).block);
    seed_ids_.clear();
  }

  SweepReport finish() {
    for (auto& [id, s] : seed_) {
      report_.seed_rows.push_back(s);
      report_.seed_rows.back().run_id = id;
    }
    return std::move(report_);
  }

  SweepReport& report() { return report_; }
  /// True when fill_landscape set the cells of every landscape (none left to grid from rows).
  bool all_filled() const {
    for (std::size_t b = 0; b < grids_.size(); ++b)
      if (grids_[b].enabled() && !filled_[b]) return false;
    return true;
  }

 private:
  bool is_seed_preset(const std::string& preset) const {
    return !preset.empty() && seed_.size() + seed_ids_.size() < 1000 && find_seed_case(preset);
  }
  /// A run of a seed-arm block whose preset names a Table 4 row (the thesis comparison).
  void add_seed(std::uint64_t id, const Record& row, std::size_t b) {
    const Columns& c = columns_[b];
    SeedRow s;
    s.preset = as_str(row.cells[c.preset]);
    s.inertia = c.inertia == Columns::npos ? "chain" : as_str(row.cells[c.inertia]);
    s.status = as_str(row.cells[schema_.status]);
    s.E = cell_number(row.cells[c.value]);
    for (int j = 0; j < 3; ++j) s.tau[j] = cell_number(row.cells[c.tau[j]]);
    seed_[id] = std::move(s);
  }
  /// The run keyed `k` among the block's best three (ranking(kind): NaN objectives never are).
  void consider_best(BlockReport& br, const RankKey& k, const Record& row, std::size_t b) {
    if (!std::isfinite(k.objective)) return;
    auto& keys = best_keys_[b];
    if (keys.size() == 3 && !(k < keys.back())) return;
    const auto at = std::upper_bound(keys.begin(), keys.end(), k) - keys.begin();
    keys.insert(keys.begin() + at, k);
    br.best.insert(br.best.begin() + at, BestRun{k.run, k.objective, k.tie, label(row, b)});
    if (keys.size() > 3) keys.pop_back(), br.best.pop_back();
  }
  /// The swept parameters of the run, in file units (angles in degrees).
  std::string label(const Record& row, std::size_t b) const {
    const Block& block = study_.blocks[b];
    std::string out;
    for (const Axis& a : block.axes()) {
      const Cell& c = row.cells[schema_.param_column[b][block.column_index(a.name)]];
      char buf[64];
      if (const double* d = std::get_if<double>(&c))
        std::snprintf(buf, sizeof buf, "%.6g", a.unit == "rad" ? *d * 180.0 / M_PI : *d);
      else if (const std::int64_t* i = std::get_if<std::int64_t>(&c))
        std::snprintf(buf, sizeof buf, "%lld", static_cast<long long>(*i));
      else
        std::snprintf(buf, sizeof buf, "%s", std::get<std::string>(c).c_str());
      out += (out.empty() ? "" : ", ") + a.name + (a.unit == "rad" ? "[deg]=" : "=") + buf;
    }
    return out;
  }

  const Study& study_;
  const StudySchema& schema_;
  store::ResultsWriter& writer_;  // the landscapes' cells go there with their rows
  std::vector<LandscapeGrid> grids_;
  std::vector<bool> filled_;  // per block: the previous runs' cells set by SweepOptions::fill_landscape
  SweepReport report_;
  std::map<std::uint64_t, SeedRow> seed_;
  struct Columns {  // schema columns a block's rows are read at
    static constexpr std::size_t npos = std::size_t(-1);
    std::size_t value = 0, tie = npos, preset = 0, inertia = 0, tau[3] = {0, 0, 0};
    bool seed_arm = true;  ///< a planar 3-joint arm: its preset rows are compared with the thesis' Table 4
  };
  std::vector<Columns> columns_;
  std::map<std::size_t, std::vector<RankKey>> best_keys_;  // per block: the keys of report_'s best rows
  std::vector<std::vector<RankKey>> candidates_;  // per block: add_columns' best keys, rows not read yet
  std::vector<std::uint64_t> seed_ids_;           // add_columns' seed runs, rows not read yet
};

}  // namespace

PreviousRuns previous_runs(const store::ResultsWriter& writer) {
  PreviousRuns p;
  p.done.resize(static_cast<std::size_t>(std::max<std::int64_t>(0, writer.n_runs())), false);
  for (std::size_t id = 0; id < p.done.size(); ++id) p.done[id] = writer.is_done(static_cast<std::int64_t>(id));
  return p;
}

namespace {
/// Feeds the runs done in `previous` to `acc`, read from `writer` in pieces (memory bounded whatever
/// the run count): by typed column reads of four /runs chunks at a time where the file's columns
/// allow (Accumulator::columnar), else as Records of 8192 rows. Returns their number.
std::uint64_t add_previous(const Study& study, const PreviousRuns& previous, store::ResultsWriter& writer,
                           Accumulator& acc) {
  const bool columnar = acc.columnar();
  const std::uint64_t kPiece = columnar ? 4 * store::kRunsChunkRows : 8192;
  const std::uint64_t total = std::min<std::uint64_t>(study.run_count(), previous.done.size());
  std::uint64_t added = 0;
  for (std::uint64_t first = 0; first < total; first += kPiece) {
    const std::uint64_t n = std::min(kPiece, total - first);
    if (std::none_of(previous.done.begin() + first, previous.done.begin() + first + n, [](bool d) { return d; }))
      continue;
    if (columnar) {
      acc.add_columns(first, n, previous.done);
      added += static_cast<std::uint64_t>(std::count(previous.done.begin() + first, previous.done.begin() + first + n, true));
      continue;
    }
    const std::vector<Record> rows = writer.read_rows(static_cast<std::int64_t>(first), static_cast<std::int64_t>(n));
    for (std::uint64_t i = 0; i < n; ++i)
      if (previous.done[first + i]) acc.add(first + i, study.locate(first + i), rows[i]), ++added;
  }
  if (columnar) acc.finish_columns();
  return added;
}
}  // namespace

SweepReport run_sweep(const Study& study, const StudySchema& schema, store::ResultsWriter& writer,
                      const SweepOptions& options, const PreviousRuns* previous) {
  const std::uint64_t total = study.run_count();
  const bool all_done = previous && previous->done.size() >= total &&
                        std::all_of(previous->done.begin(), previous->done.begin() + static_cast<std::ptrdiff_t>(total),
                                    [](bool d) { return d; });
  Accumulator acc(study, schema, writer, options.fill_landscape, options.landscapes, all_done);
  const std::uint64_t skipped =
      !previous ? 0
      : options.report_previous || !acc.all_filled()
          ? add_previous(study, *previous, writer, acc)
          : static_cast<std::uint64_t>(std::count(previous->done.begin(), previous->done.end(), true));
  const int threads = options.threads > 0 ? options.threads : tbb::info::default_concurrency();
  const int stride = options.histories.mode == HistoryPolicy::Mode::none ? 0
                     : options.histories.mode == HistoryPolicy::Mode::every ? options.histories.stride
                                                                              : 1;
  tbb::enumerable_thread_specific<RunWorkspace> workspaces;
  // Lanes: runs per SIMD batch (results do not depend on it); a pipeline token holds enough runs to
  // fill two batches of the widest lanes.
  const int lanes = options.lanes > 0 ? std::min(options.lanes, max_lanes()) : max_lanes();
  const auto start = Clock::now();
  auto last_progress = start;
  std::uint64_t next = 0, written = 0;
  const std::uint64_t todo = options.source ? options.source_runs : total - skipped;
  // A small sweep is cut into at least four batches per thread, so that a few long runs (global_spline)
  // spread over the threads; a large one fills two batches of the widest lanes per token.
  const std::size_t full_batch = std::max<std::size_t>(options.batch, 2 * static_cast<std::size_t>(lanes));
  const std::size_t batch = std::clamp<std::size_t>((todo + 4 * threads - 1) / (4 * threads), 1, full_batch);
  bool interrupted = false;
  std::atomic<bool> dropped{false};  // a run stopped by the signal was left out
  // the optimiser of path-global runs ends a run in flight when the stop flag is set
  struct StopFlagInOptimiser {
    explicit StopFlagInOptimiser(const std::atomic<bool>* flag) { set_optimiser_stop_flag(flag); }
    ~StopFlagInOptimiser() { set_optimiser_stop_flag(nullptr); }
  } stop_flag_in_optimiser(options.stop);
  auto is_done = [&](std::uint64_t id) { return previous && id < previous->done.size() && previous->done[id]; };

  tbb::task_arena arena(threads);
  arena.execute([&] {
    tbb::parallel_pipeline(
        options.tokens > 0 ? options.tokens : static_cast<std::size_t>(4 * threads),
        tbb::make_filter<void, std::shared_ptr<Batch>>(
            tbb::filter_mode::serial_in_order,
            [&](tbb::flow_control& fc) -> std::shared_ptr<Batch> {
              if (options.stop && options.stop->load()) interrupted = true;
              auto b = std::make_shared<Batch>();
              if (options.source) {
                std::vector<std::uint64_t> ids;
                if (!interrupted && options.source(ids, batch))
                  for (std::uint64_t id : ids) b->jobs.push_back(Job{id, study.locate(id), {}, {}});
              } else {
                while (!interrupted && next < total && b->jobs.size() < batch) {
                  const std::uint64_t id = next++;
                  if (!is_done(id)) b->jobs.push_back(Job{id, study.locate(id), {}, {}});
                }
              }
              if (b->jobs.empty()) {
                fc.stop();
                return nullptr;
              }
              return b;
            }) &
            tbb::make_filter<std::shared_ptr<Batch>, std::shared_ptr<Batch>>(
                tbb::filter_mode::parallel,
                [&](std::shared_ptr<Batch> b) {
                  RunWorkspace& ws = workspaces.local();
                  const Scenario scenario = Scenario::of(study);
                  const std::size_t n = b->jobs.size();
                  std::vector<RunSpec> runs;
                  runs.reserve(n);
                  for (const Job& j : b->jobs) runs.push_back(study.blocks[j.ref.block].run(j.ref.local));
                  std::vector<RunOutcome> outcomes(n);
                  std::vector<double> wall(n);
                  execute_batch(scenario, runs.data(), n, stride, lanes, ws, outcomes.data(), wall.data());
                  for (std::size_t i = 0; i < n; ++i) {
                    Job& j = b->jobs[i];
                    const RunOutcome& o = outcomes[i];
                    const TrajectoryMetrics* tm = std::get_if<TrajectoryMetrics>(&o.result);
                    if (tm && tm->status == RunStatus::interrupted) {
                      j.interrupted = true;
                      continue;
                    }
                    const auto t0 = Clock::now();
                    if (!o.history.arrays.empty()) j.history = store::encode_history(o.history, options.compression, writer.history_chunk_rows());
                    j.seconds = wall[i] + std::chrono::duration<double>(Clock::now() - t0).count();
                    j.row = schema.row(j.id, j.ref.block, study.blocks[j.ref.block], runs[i], o, wall[i]);
                  }
                  return b;
                }) &
            tbb::make_filter<std::shared_ptr<Batch>, void>(
                tbb::filter_mode::serial_in_order, [&](std::shared_ptr<Batch> b) {
                  for (Job& j : b->jobs) {
                    if (j.interrupted) {  // left undone: a resume computes it
                      dropped.store(true);
                      continue;
                    }
                    // the landscape cell before the row: a commit that holds a run done holds its
                    // cell (a distributed merge copies the cells of the shards' done runs)
                    acc.add(j.id, j.ref, j.row);
                    writer.write_run(static_cast<std::int64_t>(j.id), j.row, j.history);
                    ++written;
                    if (options.on_written) options.on_written(j.ref.block, j.seconds, store::encoded_bytes(j.history));
                  }
                  const auto now = Clock::now();
                  if (options.on_progress &&
                      std::chrono::duration<double>(now - last_progress).count() >= options.progress_interval_s) {
                    last_progress = now;
                    options.on_progress({written, todo, std::chrono::duration<double>(now - start).count()});
                  }
                }));
  });
  if (dropped.load()) interrupted = true;
  writer.flush();
  if (options.on_progress) options.on_progress({written, todo, std::chrono::duration<double>(Clock::now() - start).count()});
  SweepReport report;
  if (!interrupted) {
    report = acc.finish();
  } else {
    report = std::move(acc.report());
  }
  report.total = total;
  report.written = written;
  report.skipped = skipped;
  report.interrupted = interrupted;
  report.elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

void print_report(std::ostream& os, const Study& study, const SweepReport& r) {
  char line[512];
  std::snprintf(line, sizeof line, "%llu runs (%llu computed now, %llu already in the file) in %.2f s\n",
                static_cast<unsigned long long>(r.total), static_cast<unsigned long long>(r.written),
                static_cast<unsigned long long>(r.skipped), r.elapsed_s);
  os << line;
  for (const BlockReport& b : r.blocks) {
    os << "block " << b.name << " (" << to_string(b.kind) << ", " << b.runs << " runs):";
    for (const auto& [status, n] : b.by_status) os << ' ' << status << '=' << n;
    os << '\n';
    // the ranking objective with its unit, as the kind's metric table gives it
    std::string objective(ranking(b.kind).objective);
    for (const MetricDef& m : metrics(b.kind))
      if (m.name == objective && !m.unit.empty()) objective += " [" + m.unit + "]";
    for (const BestRun& best : b.best) {
      std::snprintf(line, sizeof line, "  best: run %llu  %s = %.6g  (%s)\n", static_cast<unsigned long long>(best.run_id),
                    objective.c_str(), best.value, best.label.c_str());
      os << line;
    }
  }
  if (!r.seed_rows.empty()) {
    os << "\nSeed 000, Table 4: thesis vs kinesweep (E = mean |tau|, t1..t3 = max |tau_i|, in Nm; dev = worst "
          "relative deviation)\n";
    std::snprintf(line, sizeof line, "%-5s %-11s | %8s %8s %8s %7s | %8s %8s %8s %7s %7s | %s\n", "case", "inertia",
                  "E", "t1", "t2", "t3", "E", "t1", "t2", "t3", "dev", "status");
    os << "                  | thesis                              | kinesweep\n" << line;
    for (const SeedRow& s : r.seed_rows) {
      const SeedCase& c = *find_seed_case(s.preset);
      const double dev = c.worst_deviation(s.E, s.tau);
      std::snprintf(line, sizeof line, "%-5s %-11s | %8.2f %8.2f %8.2f %7.2f | %8.2f %8.2f %8.2f %7.2f %6.1f%% | %s\n",
                    s.preset.c_str(), s.inertia.c_str(), c.E, c.tau_inf[0], c.tau_inf[1], c.tau_inf[2], s.E, s.tau[0],
                    s.tau[1], s.tau[2], 100 * dev, s.status.c_str());
      os << line;
    }
  }
  (void)study;
}

}  // namespace ks
