#pragma once
// `kinesweep run --dry-run` as a sweep back end (runner/sweep_backend.hpp): the study's runs per
// block, and its time and file size estimated from sample runs of each block, run by the sweep
// itself (run_sweep: its threads, SIMD lanes, history encoding and writer) into a temporary results
// file opened like any other (open_results), which is removed.
#include <memory>

#include "runner/sweep_backend.hpp"

namespace ks {

struct DryRunOptions {
  /// Sampling budget per block [s]: at least 4 runs each within 10 budgets (at least 1 beyond), at
  /// most 64; past the budget, sampling goes on (up to 10 budgets) while the block's mean run time is
  /// uncertain by more than 10 %.
  double seconds_per_block = 0.25;
  /// Where the temporary files go (empty: the system's temporary directory).
  std::string temp_dir;
};

/// The dry run's back end. Its sweep prints the plan and the estimates to `out` (RunRequest:
/// output, histories, threads, lanes, compression, stop); nothing is written but temporary files,
/// removed before it returns. Exit codes: 0, 1 (a sample file could not be written, or a history
/// policy a run could not keep in memory), 130 (interrupted).
std::unique_ptr<SweepBackend> dry_run_backend(const DryRunOptions& options = {});

}  // namespace ks
