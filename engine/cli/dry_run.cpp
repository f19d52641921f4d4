// `kinesweep run --dry-run` (see dry_run.hpp).
//
// Each block's runs are sampled along a golden-ratio sequence of its run indices (any prefix is spread
// over the block), executed and encoded as the sweep does (compute time and history bytes per run),
// then all samples are written through the store into a temporary results file (its landscapes, one
// f64 per cell and metric, are added from the blocks' grids): its size beyond a
// file of one empty row gives the bytes per run on disk (rows, history objects, index), and the
// writer's time the serial cost per run. The sweep overlaps computing (all threads) with the single
// writer, so its time is about max((compute + write) / threads, write).
#include "cli/dry_run.hpp"
#include "cli/human_units.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <ostream>
#include <thread>

#include "methods/trajectory_lanes.hpp"
#include "runner/execute.hpp"
#include "runner/landscape.hpp"
#include "runner/run_study.hpp"
#include "store/store.hpp"

namespace ks::cli {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Sample {
  std::size_t block;
  std::uint64_t local;
  Record row;
  store::EncodedHistory history;
};

struct BlockEstimate {
  std::uint64_t runs = 0;
  std::size_t sampled = 0;
  double compute_s = 0;      ///< per run
  double history_bytes = 0;  ///< per run, encoded
};

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

/// Seconds since this process started (Linux: /proc; 0 elsewhere): what a run spends before its sweep
/// (loading, MPI probing, parsing the study), which the dry run spent too.
/// `picks` as batches of up to `lanes` runs that can share SIMD lanes, as the sweep's consecutive
/// runs mostly can: each batch opens with the next pick not taken, in the spread order, and takes the
/// later picks lane-compatible with it (same inertia form and lane options; other runs: one a batch
/// slot as in the sweep, which runs them one at a time).
std::vector<std::vector<std::uint64_t>> lane_batches(const Block& block, const std::vector<std::uint64_t>& picks,
                                                     int lanes) {
  std::vector<RunSpec> runs;
  for (std::uint64_t p : picks) runs.push_back(block.run(p));
  std::vector<std::vector<std::uint64_t>> out;
  std::vector<char> used(picks.size(), 0);
  const std::size_t width = static_cast<std::size_t>(std::max(1, lanes));
  for (std::size_t i = 0; i < picks.size(); ++i) {
    if (used[i]) continue;
    const auto* a = std::get_if<TrajectoryRun>(&runs[i]);
    out.emplace_back();
    for (std::size_t j = i; j < picks.size() && out.back().size() < width; ++j) {
      const auto* b = std::get_if<TrajectoryRun>(&runs[j]);
      const bool shares = a && b && b->inertia == a->inertia && lane_compatible(a->options, b->options);
      if (used[j] || (j != i && a && !shares)) continue;  // (runs without lanes: any, in order)
      used[j] = 1;
      out.back().push_back(picks[j]);
    }
  }
  return out;
}

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

double history_bytes(const store::EncodedHistory& h) {
  double b = 0;
  b += static_cast<double>(store::encoded_bytes(h));
  return b;
}

/// Size in bytes of a results file of `rows` runs (run ids 0..rows-1) whose rows and histories cycle
/// through `samples`, the writer's time, and the history bytes written.
struct Written {
  double bytes = 0, seconds = 0, history_bytes = 0;
};
Written write_samples(const std::string& path, const Study& study, const StudySchema& schema,
                      const std::vector<Sample>& samples, std::size_t rows) {
  Written out;
  const auto t0 = Clock::now();
  {
    auto w = store::ResultsWriter::create(path, store_meta(study, study.histories), schema.columns,
                                          static_cast<std::int64_t>(std::max<std::size_t>(rows, 1)),
                                          {.overwrite = true});
    for (std::size_t i = 0; i < rows && !samples.empty(); ++i) {
      const Sample& sample = samples[i % samples.size()];
      Record row = sample.row;
      row.cells[schema.run_id] = static_cast<std::int64_t>(i);
      w->write_run(static_cast<std::int64_t>(i), row, sample.history);
      out.history_bytes += history_bytes(sample.history);
    }
    w->close();
  }
  out.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  out.bytes = static_cast<double>(fs::file_size(path));
  fs::remove(path);
  return out;
}

}  // namespace

int dry_run(const Study& study, const StudySchema& schema, const DryRunOptions& opt, std::ostream& out,
            std::ostream& err) {
  const double startup = seconds_since_process_start();
  out << "study " << study.name << " (" << study.file << "), sha256 " << study.sha256 << '\n';
  out << "output " << opt.output << (fs::exists(opt.output) ? " (exists: --resume completes it, --overwrite replaces it)" : "")
      << '\n';
  const HistoryPolicy& h = opt.histories;
  if (const std::string why = history_memory_problem(study, h); !why.empty()) {
    err << "kinesweep run: " << why << '\n';
    return 1;
  }
  const int stride = h.mode == HistoryPolicy::Mode::none ? 0 : h.stride;
  const Scenario scenario = Scenario::of(study);
  RunWorkspace ws;
  const int lanes = opt.lanes > 0 ? std::min(opt.lanes, max_lanes()) : max_lanes();
  std::vector<Sample> samples;
  std::vector<BlockEstimate> est(study.blocks.size());
  double longest = 0;  // the longest sample run: no thread count finishes before it
  for (std::size_t b = 0; b < study.blocks.size(); ++b) {
    const Block& block = study.blocks[b];
    out << "  block " << block.name() << " (" << to_string(block.kind()) << "): " << block.run_count() << " runs =";
    const auto shape = block.shape();
    if (shape.empty()) out << " 1";
    for (std::size_t d = 0; d < shape.size(); ++d) out << (d ? " x " : " ") << shape[d];
    out << '\n';
    est[b].runs = block.run_count();
    // The samples run in batches of `lanes`, as the sweep's workers run them (execute_batch).
    const auto start = Clock::now();
    double compute = 0, sq = 0;
    for (const std::vector<std::uint64_t>& picks : lane_batches(block, spread_indices(block.run_count(), 64), lanes)) {
      // past the budget, sampling goes on (up to 10 budgets) while the mean run time is uncertain by
      // more than 10 % (runs of very different cost in one block: global_spline's knot counts)
      const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
      const double n_s = static_cast<double>(est[b].sampled);
      const double mean = n_s > 0 ? compute / n_s : 0, var = n_s > 1 ? (sq - n_s * mean * mean) / (n_s - 1) : 0;
      const bool settled = n_s > 1 && std::sqrt(std::max(var, 0.0) / n_s) <= 0.1 * mean;
      if (est[b].sampled >= 4 && elapsed > opt.seconds_per_block && (settled || elapsed > 10 * opt.seconds_per_block))
        break;
      const std::size_t n = picks.size(), first = 0;
      std::vector<RunSpec> runs;
      for (std::size_t i = 0; i < n; ++i) runs.push_back(block.run(picks[first + i]));
      std::vector<RunOutcome> outcomes(n);
      std::vector<double> wall(n);
      execute_batch(scenario, runs.data(), n, stride, lanes, ws, outcomes.data(), wall.data());
      for (std::size_t i = 0; i < n; ++i) {
        const auto t0 = Clock::now();
        store::EncodedHistory hist;
        if (!outcomes[i].history.arrays.empty()) hist = store::encode_history(outcomes[i].history, opt.compression);
        wall[i] += std::chrono::duration<double>(Clock::now() - t0).count();
        compute += wall[i];
        sq += wall[i] * wall[i];
        longest = std::max(longest, wall[i]);
        est[b].history_bytes += history_bytes(hist);
        samples.push_back({b, picks[first + i],
                           schema.row(study.first_run(b) + picks[first + i], b, block, runs[i], outcomes[i], wall[i]),
                           std::move(hist)});
        ++est[b].sampled;
      }
    }
    est[b].compute_s = est[b].sampled ? compute / static_cast<double>(est[b].sampled) : 0;
    if (est[b].sampled) est[b].history_bytes /= static_cast<double>(est[b].sampled);
  }
  // Bytes and writer time per run, from sample files beyond a file of one empty row. The samples are
  // written repeatedly, up to 4096 rows or 64 MiB of histories, so that the store's per-commit costs
  // are spread over as many runs as in a sweep.
  double total_runs = 0, compute_total = 0, sample_history = 0;
  for (const BlockEstimate& e : est) {
    total_runs += static_cast<double>(e.runs);
    compute_total += static_cast<double>(e.runs) * e.compute_s;
  }
  for (const Sample& smp : samples) sample_history += history_bytes(smp.history);
  const double mean_history = samples.empty() ? 0 : sample_history / static_cast<double>(samples.size());
  std::size_t rows = std::min<std::size_t>(static_cast<std::size_t>(total_runs), 4096);
  if (mean_history > 0) rows = std::min<std::size_t>(rows, static_cast<std::size_t>(64.0 * (1 << 20) / mean_history));
  rows = std::max(rows, samples.size());
  const fs::path tmp = fs::temp_directory_path() / ("kinesweep-dry-run-" + std::to_string(getpid()) + ".h5");
  Written empty, half, full;
  try {
    empty = write_samples(tmp.string(), study, schema, {}, 0);
    half = write_samples(tmp.string(), study, schema, samples, rows / 2);
    full = write_samples(tmp.string(), study, schema, samples, rows);
  } catch (const std::exception& e) {
    std::error_code ec;
    fs::remove(tmp, ec);
    err << "kinesweep run: --dry-run: cannot write a sample results file in " << tmp.parent_path().string() << ": "
        << e.what() << '\n';
    return 1;
  }
  // Per run: its block's history bytes, plus what every run costs beyond its history (row, index, objects).
  const double n_rows = static_cast<double>(std::max<std::size_t>(rows, 1));
  const double overhead_per_run = std::max(0.0, full.bytes - empty.bytes - full.history_bytes) / n_rows;
  double bytes = empty.bytes;
  for (std::size_t b = 0; b < est.size(); ++b) bytes += static_cast<double>(est[b].runs) * (est[b].history_bytes + overhead_per_run);
  // The landscapes (not in the sample files): one f64 per cell and gridded metric, allocated whole.
  for (const Block& block : study.blocks)
    if (const LandscapeGrid grid(block); grid.enabled())
      bytes += static_cast<double>(block.run_count()) * static_cast<double>(grid.spec().metrics.size()) * sizeof(double);
  // The writer's time per run: the slope between the half and the full file (a new file's first
  // rows cost more: its index and chunks are being allocated).
  const double write_per_run = rows >= 2 ? std::max(0.0, full.seconds - half.seconds) / (n_rows - rows / 2)
                                         : std::max(0.0, full.seconds - empty.seconds) / n_rows;
  const int n = opt.threads > 0 ? opt.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const double write_total = total_runs * write_per_run;
  const double seconds =
      startup + std::max({(compute_total + write_total) / n, write_total, longest}) + 2 * empty.seconds;
  out << "  total: " << static_cast<std::uint64_t>(total_runs) << " runs; histories " << h.str()
      << "\n  estimated size: " << human_bytes(bytes) << " (" << human_bytes((bytes - empty.bytes) / std::max(total_runs, 1.0))
      << " per run); estimated time: " << human_time(seconds) << " on " << n
      << " thread" << (n == 1 ? "" : "s") << " (from " << samples.size() << " sample runs executed and written here)\n";
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
  return 0;
}

}  // namespace ks::cli
