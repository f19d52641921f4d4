// `kinesweep run --dry-run` (see dry_run.hpp).
//
// Each block's runs are sampled along a golden-ratio sequence of its run indices (any prefix is spread
// over the block), in batches of runs that share SIMD lanes as the sweep's consecutive runs do, and
// handed to run_sweep as its run source: the sweep executes, encodes and writes them as in a real
// run, and reports each run's time and history bytes (SweepOptions::on_written). The samples are then
// read back and written again, repeated, into files of up to 4096 rows: their size beyond a file of
// one empty row gives the bytes per run on disk (rows, history objects, index), and the writer's time
// the serial cost per run. The sweep overlaps computing (all threads) with the single writer, so its
// time is about max((compute + write) / threads, write, the longest run).
#include "runner/dry_run.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <ostream>
#include <sstream>
#include <thread>

#include "common/human_units.hpp"
#include "methods/closed_form/lanes.hpp"
#include "runner/execute.hpp"
#include "runner/landscape.hpp"
#include "runner/study_meta.hpp"
#include "store/store.hpp"

namespace ks {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

/// Run-index sequence over [0, n): the golden-ratio (Weyl) sequence, distinct indices, any prefix spread.
std::vector<std::uint64_t> spread_indices(std::uint64_t n, std::size_t max) {
  std::vector<std::uint64_t> out;
  const double phi = 0.6180339887498949;
  double x = 0.5;
  for (std::size_t tries = 0; out.size() < std::min<std::uint64_t>(n, max) && tries < 16 * max; ++tries) {
    const auto i = std::min<std::uint64_t>(n - 1, static_cast<std::uint64_t>(x * static_cast<double>(n)));
    if (std::find(out.begin(), out.end(), i) == out.end()) out.push_back(i);
    x += phi;
    x -= std::floor(x);
  }
  return out;
}

/// `picks` as batches of up to `lanes` runs that can share SIMD lanes, as the sweep's consecutive
/// runs mostly can: each batch opens with the next pick not taken, in the spread order, and takes the
/// later picks lane-compatible with it (same inertia form and lane options); a run that never shares
/// lanes (execute.hpp lane_run: the sweep's rule) is a batch of its own.
std::vector<std::vector<std::uint64_t>> lane_batches(const Scenario& scenario, const Block& block,
                                                     const std::vector<std::uint64_t>& picks,
                                                     int lanes) {
  std::vector<RunSpec> runs;
  for (std::uint64_t p : picks) runs.push_back(block.run(p));
  std::vector<std::vector<std::uint64_t>> out;
  std::vector<char> used(picks.size(), 0);
  const std::size_t width = static_cast<std::size_t>(std::max(1, lanes));
  for (std::size_t i = 0; i < picks.size(); ++i) {
    if (used[i]) continue;
    const auto* a = lane_run(scenario, runs[i]);
    // a run that never shares lanes (a chain's, a path-global one) is a batch of its own, so that a
    // block of runs of minutes each is not sampled whole before its first one is timed
    const std::size_t cap = a ? width : 1;
    out.emplace_back();
    for (std::size_t j = i; j < picks.size() && out.back().size() < cap; ++j) {
      const auto* b = lane_run(scenario, runs[j]);
      const bool shares = a && b && b->inertia == a->inertia && lane_compatible(a->options, b->options);
      if (used[j] || (j != i && !shares)) continue;
      used[j] = 1;
      out.back().push_back(picks[j]);
    }
  }
  return out;
}

/// Seconds since this process started (Linux: /proc; 0 elsewhere): what a run spends before its sweep
/// (loading, MPI probing, parsing the study), which the dry run spent too.
double seconds_since_process_start() {
  std::ifstream stat("/proc/self/stat"), uptime("/proc/uptime");
  std::string text;
  double up = 0;
  if (!std::getline(stat, text) || !(uptime >> up)) return 0;
  std::istringstream fields(text.substr(text.rfind(')') + 2));  // after "pid (comm) "
  std::string f;
  for (int i = 3; i <= 22 && fields >> f; ++i) {
    if (i == 22) return std::max(0.0, up - std::stod(f) / static_cast<double>(sysconf(_SC_CLK_TCK)));
  }
  return 0;
}

/// One block's sample runs: the batches still to hand out and the statistics of those written.
struct BlockSamples {
  std::vector<std::vector<std::uint64_t>> batches;  // run ids, ascending within a batch
  std::size_t next = 0, handed = 0;
  bool started = false;
  Clock::time_point start;
  std::size_t n = 0;  // written
  double sum = 0, sq = 0, history_bytes = 0;
  /// True when sampling the block may stop: at least 4 runs handed out, the budget spent, and the
  /// mean run time known within 10 %; or 10 budgets spent (then with any number of runs handed out:
  /// a block of runs of minutes each, path-global ones, is estimated from the runs begun).
  bool enough(double budget) const {
    if (handed == 0 || !started) return false;
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    if (elapsed > 10 * budget) return true;
    if (handed < 4 || elapsed <= budget) return false;
    const double k = static_cast<double>(n), mean = k > 0 ? sum / k : 0;
    const double var = k > 1 ? (sq - k * mean * mean) / (k - 1) : 0;
    return k > 1 && std::sqrt(std::max(var, 0.0) / k) <= 0.1 * mean;
  }
};

/// Size in bytes of a results file of `rows` runs (run ids 0..rows-1) whose rows and histories cycle
/// through the samples, the writer's time, and the history bytes written.
struct Written {
  double bytes = 0, seconds = 0, history_bytes = 0;
};
Written write_samples(const std::string& path, const Study& study, const StudySchema& schema,
                      const std::vector<Record>& rows_in, const std::vector<store::EncodedHistory>& histories,
                      std::size_t rows) {
  Written out;
  const auto t0 = Clock::now();
  {
    auto w = store::ResultsWriter::create(path, store_meta(study, study.histories), schema.columns,
                                          static_cast<std::int64_t>(std::max<std::size_t>(rows, 1)),
                                          {.overwrite = true});
    for (std::size_t i = 0; i < rows && !rows_in.empty(); ++i) {
      const std::size_t s = i % rows_in.size();
      Record row = rows_in[s];
      row.cells[schema.run_id] = static_cast<std::int64_t>(i);
      w->write_run(static_cast<std::int64_t>(i), row, histories[s]);
      out.history_bytes += static_cast<double>(store::encoded_bytes(histories[s]));
    }
    w->close();
  }
  out.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  out.bytes = static_cast<double>(fs::file_size(path));
  store::remove_results_file(path);
  return out;
}

class DryRunBackend final : public SweepBackend {
 public:
  explicit DryRunBackend(const DryRunOptions& o) : options_(o) {}
  ~DryRunBackend() override { remove_temp(); }

  /// The dry run prints its estimates itself and runs no optimisation block.
  bool leader() const override { return false; }

  int open(const Study& study, const StudySchema& schema, const RunRequest& r, std::ostream& err) override {
    startup_ = seconds_since_process_start();
    const fs::path dir = options_.temp_dir.empty() ? fs::temp_directory_path() : fs::path(options_.temp_dir);
    temp_ = (dir / ("kinesweep-dry-run-" + std::to_string(getpid()) + ".h5")).string();
    try {
      opened_ = open_results(study, schema, temp_, false, {.overwrite = true}, r.options.histories, false);
    } catch (const store::StoreError& e) {
      err << "kinesweep run: --dry-run: cannot write a sample results file in " << dir.string() << ": " << e.what()
          << '\n';
      return 1;
    }
    return 0;
  }

  SweepResult sweep(const Study& study, const StudySchema& schema, const RunRequest& r, std::ostream& out,
                    std::ostream& err) override {
    SweepResult res;
    out << "study " << study.name << " (" << study.file << "), sha256 " << study.sha256 << '\n';
    out << "output " << r.output
        << (fs::exists(r.output) ? " (exists: --resume completes it, --overwrite replaces it)" : "") << '\n';
    const int lanes = r.options.lanes > 0 ? std::min(r.options.lanes, max_lanes()) : max_lanes();
    std::vector<BlockSamples> blocks(study.blocks.size());
    std::uint64_t total_samples = 0;
    for (std::size_t b = 0; b < study.blocks.size(); ++b) {
      const Block& block = study.blocks[b];
      out << "  block " << block.name() << " (" << to_string(block.kind()) << "): " << block.run_count() << " runs =";
      const auto shape = block.shape();
      if (shape.empty()) out << " 1";
      for (std::size_t d = 0; d < shape.size(); ++d) out << (d ? " x " : " ") << shape[d];
      out << '\n';
      for (auto batch : lane_batches(Scenario::of(study), block, spread_indices(block.run_count(), 64), lanes)) {
        for (std::uint64_t& local : batch) local += study.first_run(b);
        std::sort(batch.begin(), batch.end());
        total_samples += batch.size();
        blocks[b].batches.push_back(std::move(batch));
      }
    }
    // The sample runs, by the sweep: a block's batches are handed out until it has enough.
    std::mutex m;
    std::size_t current = 0;
    std::vector<std::int64_t> sampled;
    double longest = 0;
    SweepOptions o = r.options;
    o.histories = opened_.histories;
    o.on_progress = nullptr;
    o.landscapes = false;
    o.source_runs = total_samples;
    // a batch asked for when one is written, so that each decision knows the time of the runs done
    o.tokens = r.options.threads > 0 ? static_cast<std::size_t>(r.options.threads)
                                     : std::max<std::size_t>(1, std::thread::hardware_concurrency());
    o.source = [&](std::vector<std::uint64_t>& ids, std::size_t) {
      std::lock_guard lock(m);
      while (current < blocks.size()) {
        BlockSamples& s = blocks[current];
        if (s.next < s.batches.size() && !s.enough(options_.seconds_per_block)) {
          if (!s.started) s.started = true, s.start = Clock::now();
          ids = s.batches[s.next++];
          s.handed += ids.size();
          sampled.insert(sampled.end(), ids.begin(), ids.end());
          return true;
        }
        ++current;
      }
      return false;
    };
    o.on_written = [&](std::size_t block, double seconds, std::size_t history_bytes) {
      std::lock_guard lock(m);
      BlockSamples& s = blocks[block];
      ++s.n, s.sum += seconds, s.sq += seconds * seconds, s.history_bytes += static_cast<double>(history_bytes);
      longest = std::max(longest, seconds);
    };
    const SweepReport report = run_sweep(study, schema, *opened_.writer, o);
    opened_.writer->close();
    if (report.interrupted) {
      err << "kinesweep run: --dry-run interrupted; nothing written\n";
      res.code = 130;
      return res;
    }
    try {
      estimate(study, schema, r, blocks, sampled, longest, out);
    } catch (const std::exception& e) {
      err << "kinesweep run: --dry-run: cannot write a sample results file in "
          << fs::path(temp_).parent_path().string() << ": " << e.what() << '\n';
      res.code = 1;
    }
    return res;
  }

  std::string kept_in(const RunRequest&) const override { return "no file (a dry run)"; }
  std::string resume_command(const RunRequest&) const override { return ""; }
  int finish(int code) override {
    remove_temp();
    return code;
  }

 private:
  /// Estimates from the sample runs (in the temporary file) and their statistics.
  void estimate(const Study& study, const StudySchema& schema, const RunRequest& r,
                const std::vector<BlockSamples>& blocks, std::vector<std::int64_t> sampled, double longest,
                std::ostream& out) {
    std::sort(sampled.begin(), sampled.end());
    std::vector<Record> rows;
    std::vector<store::EncodedHistory> histories;
    {
      const store::ResultsReader file(temp_);
      rows = file.read_rows(sampled);
      for (std::int64_t id : sampled) histories.push_back(file.read_history_chunks(id, r.options.compression));
    }
    remove_temp();
    // Bytes and writer time per run, from sample files beyond a file of one empty row. The samples
    // are written repeatedly, up to 4096 rows or 64 MiB of histories, so that the store's per-commit
    // costs are spread over as many runs as in a sweep.
    double total_runs = 0, compute_total = 0, sample_history = 0;
    for (std::size_t b = 0; b < blocks.size(); ++b) {
      const double runs = static_cast<double>(study.blocks[b].run_count());
      total_runs += runs;
      if (blocks[b].n) compute_total += runs * blocks[b].sum / static_cast<double>(blocks[b].n);
    }
    for (const auto& h : histories) sample_history += static_cast<double>(store::encoded_bytes(h));
    const double mean_history = histories.empty() ? 0 : sample_history / static_cast<double>(histories.size());
    std::size_t n_rows = std::min<std::size_t>(static_cast<std::size_t>(total_runs), 4096);
    if (mean_history > 0) n_rows = std::min<std::size_t>(n_rows, static_cast<std::size_t>(64.0 * (1 << 20) / mean_history));
    n_rows = std::max(n_rows, rows.size());
    const Written empty = write_samples(temp_, study, schema, {}, {}, 0);
    const Written half = write_samples(temp_, study, schema, rows, histories, n_rows / 2);
    const Written full = write_samples(temp_, study, schema, rows, histories, n_rows);
    // Per run: its block's history bytes, plus what every run costs beyond its history (row, index,
    // objects).
    const double rows_d = static_cast<double>(std::max<std::size_t>(n_rows, 1));
    const double overhead_per_run = std::max(0.0, full.bytes - empty.bytes - full.history_bytes) / rows_d;
    double bytes = empty.bytes;
    for (std::size_t b = 0; b < blocks.size(); ++b) {
      const double mean = blocks[b].n ? blocks[b].history_bytes / static_cast<double>(blocks[b].n) : 0;
      bytes += static_cast<double>(study.blocks[b].run_count()) * (mean + overhead_per_run);
    }
    // The landscapes (not in the sample files): one f64 per cell and gridded metric, allocated whole.
    for (const Block& block : study.blocks)
      if (const LandscapeGrid grid(block); grid.enabled())
        bytes += static_cast<double>(block.run_count()) * static_cast<double>(grid.spec().metrics.size()) * sizeof(double);
    // The writer's time per run: the slope between the half and the full file (a new file's first
    // rows cost more: its index and chunks are being allocated).
    const double write_per_run = n_rows >= 2 ? std::max(0.0, full.seconds - half.seconds) / (rows_d - n_rows / 2)
                                             : std::max(0.0, full.seconds - empty.seconds) / rows_d;
    const int n = r.options.threads > 0 ? r.options.threads
                                        : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    const double write_total = total_runs * write_per_run;
    const double seconds =
        startup_ + std::max({(compute_total + write_total) / n, write_total, longest}) + 2 * empty.seconds;
    const HistoryPolicy& h = opened_.histories;
    out << "  total: " << static_cast<std::uint64_t>(total_runs) << " runs; histories " << h.str()
        << "\n  estimated size: " << human_bytes(bytes) << " ("
        << human_bytes((bytes - empty.bytes) / std::max(total_runs, 1.0)) << " per run); estimated time: "
        << human_time(seconds) << " on " << n << " thread" << (n == 1 ? "" : "s") << " (from " << rows.size()
        << " sample runs executed and written here)\n";
    for (const OptimizeBlock& ob : study.optimizations) {  // run after the sweep; not part of the estimates
      out << "  optimization " << ob.name << ": minimise " << ob.objective_text << " over";
      for (const auto& v : ob.variables) out << ' ' << v.name;
      if (!ob.polish_block.empty()) out << "; sweep " << ob.polish_block << " (best " << ob.polish_best << ")";
      if (ob.global) out << "; global " << opt::to_string(ob.global->algorithm) << " (max_evals " << ob.global->max_evals << ")";
      if (ob.local) out << "; local " << opt::to_string(ob.local->algorithm) << " (max_evals " << ob.local->max_evals << ")";
      out << '\n';
    }
    if (!study.optimizations.empty())
      out << "  (the estimates cover the sweep; the optimization blocks run after it, up to their max_evals runs)\n";
  }

  void remove_temp() {
    opened_.writer.reset();
    if (!temp_.empty() && fs::exists(temp_)) store::remove_results_file(temp_);
  }

  DryRunOptions options_;
  double startup_ = 0;
  std::string temp_;
  OpenedResults opened_;
};

}  // namespace

std::unique_ptr<SweepBackend> dry_run_backend(const DryRunOptions& options) {
  return std::make_unique<DryRunBackend>(options);
}

}  // namespace ks
