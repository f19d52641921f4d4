#pragma once
// The sweep: TBB tasks over run ids, one writer, bounded memory, landscapes and a summary.
//
// Data flow: a serial stage hands out batches of run ids (skipping the done ones when resuming);
// parallel stages decode parameters, execute the runs and compress their histories (so the
// single-threaded HDF5 filter pipeline never runs on the writer); a serial in-order stage writes
// rows and histories, fills the landscape grids and reports progress. At most `4 x threads`
// batches are in flight, whatever the number of runs.
#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "runner/schema.hpp"
#include "store/store.hpp"
#include "study/study.hpp"

namespace ks {

struct SweepProgress {
  std::uint64_t done = 0;      ///< runs written in this sweep
  std::uint64_t todo = 0;      ///< runs this sweep has to write
  double elapsed_s = 0.0;
};

struct SweepOptions {
  int threads = 0;                   ///< worker threads (0: all cores)
  HistoryPolicy histories;           ///< what to keep of each run's history
  int compression = 1;               ///< deflate level of the histories (1..9; 0: raw, no filter)
  std::size_t batch = 8;             ///< runs per pipeline token (at least twice `lanes`)
  /// Runs computed side by side in SIMD lanes (1: one at a time; 0: the widest this processor runs,
  /// max_lanes()). Results are the same bit for bit whatever the value.
  int lanes = 0;
  const std::atomic<bool>* stop = nullptr;  ///< set (e.g. by SIGINT): finish the runs in flight and return
  std::function<void(const SweepProgress&)> on_progress;  ///< called by the writer after each batch
  /// Where run ids come from: fill `ids` with up to `max` ids to run next (ascending within a call)
  /// and return false when there are none left. Empty: every run id in order, skipping the done ones.
  /// (A distributed runner hands out ids from a coordinator here.)
  std::function<bool(std::vector<std::uint64_t>& ids, std::size_t max)> source;
  /// The number of runs `source` will hand out (for progress); 0: all runs not done.
  std::uint64_t source_runs = 0;
  /// Batches in flight at most (0: four per thread). With `threads`, `source` is asked for the next
  /// batch only when one is written (a dry run deciding from the runs it timed).
  std::size_t tokens = 0;
  double progress_interval_s = 0.25;  ///< minimum time between on_progress calls
  /// Sets a block's landscape cells from elsewhere (a distributed sweep's shards): called once per
  /// block with a landscape, with the block's index and its begun landscape (the writer's handle);
  /// true when it set the cells of every previous run (run_sweep's `previous`), which are then not
  /// gridded from their rows (the runs computed in the sweep are). Empty: every cell from its row.
  std::function<bool(std::size_t block, std::size_t landscape)> fill_landscape;
  /// Write the blocks' landscapes (false: none; a dry run's sample sweep, whose file is thrown away).
  bool landscapes = true;
  /// Count the runs done before the sweep (run_sweep's `previous`) in its report (false: the report
  /// covers the runs computed now only, and when fill_landscape sets every landscape's cells the
  /// previous runs' rows are not read at all: a distributed merge whose ranks' reports cover them).
  bool report_previous = true;
  /// Called by the writer for each run it writes, in run order: the run's block, the time the run
  /// took to execute and encode its history [s], and its encoded history [bytes] (a dry run's
  /// statistics). Empty: nothing.
  std::function<void(std::size_t block, double seconds, std::size_t history_bytes)> on_written;
};

/// One notable row for the summary.
struct BestRun {
  std::uint64_t run_id = 0;
  double value = 0.0;    ///< the kind's ranking objective (ranking(kind): E, iterations)
  double tie = 0.0;      ///< its tie metric (ranking(kind).tie; 0 when the kind has none)
  std::string label;     ///< "method=..., alpha1A=..., k=..." or "method=..., lambda=..."
};

struct BlockReport {
  std::string name;
  BlockKind kind = BlockKind::trajectory;
  std::uint64_t runs = 0;
  std::map<std::string, std::uint64_t> by_status;  ///< over the whole block (resumed runs included)
  std::vector<BestRun> best;                       ///< up to 3: lowest E among ok / fewest iterations among converged
};

/// A run whose preset names a row of seed 000's Table 4 (for the thesis-vs-kinesweep table).
struct SeedRow {
  std::uint64_t run_id = 0;
  std::string preset, inertia, status;
  double E = 0, tau[3] = {0, 0, 0};
};

struct SweepReport {
  std::uint64_t total = 0, written = 0, skipped = 0;
  bool interrupted = false;
  double elapsed_s = 0.0;
  std::vector<BlockReport> blocks;
  std::vector<SeedRow> seed_rows;  ///< in run-id order (sweeps that ran the seed presets)
};

/// Which runs a results file already holds (resume). Their rows are read back from the writer in
/// pieces, so a resume needs memory for this mask only (one bit per run), whatever the number of runs.
/// A copy, not the writer's own flags: the sweep reads it while the writer sets its flags.
struct PreviousRuns {
  std::vector<bool> done;  ///< per run id
};
/// The done mask of `writer`'s file (its committed and pending runs).
PreviousRuns previous_runs(const store::ResultsWriter& writer);

/// Run the runs of a study not done in `previous` (all when null) into `writer`, then write its
/// landscapes. The rows of the runs done in `previous` are read back from `writer` (their landscape
/// cells and the report count them). Throws store::StoreError when the store fails.
SweepReport run_sweep(const Study& study, const StudySchema& schema, store::ResultsWriter& writer,
                      const SweepOptions& options, const PreviousRuns* previous = nullptr);

/// Adds `part`, the report of other runs of the same study (another rank's), to `into`: status counts
/// summed, the best runs per block by the ranking rule (objective, tie, run id; up to 3), seed rows
/// in run-id order (up to 1000), written counts summed.
void merge_reports(SweepReport& into, const SweepReport& part);
/// A report as bytes and back (to send it between processes); decode_report throws
/// std::runtime_error on bytes encode_report did not make.
std::string encode_report(const SweepReport& report);
SweepReport decode_report(const std::string& bytes);
/// Print the summary (runs by status, best rows per block, the thesis comparison when present).
void print_report(std::ostream& os, const Study& study, const SweepReport& report);

}  // namespace ks
