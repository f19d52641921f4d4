#pragma once
// One run: a block's parameter cells -> model + method -> metric cells, status and history.
// A run is a pure function of its parameters (no shared state), which is what makes results
// independent of the thread count and resume exact.
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "store/record.hpp"
#include "study/study.hpp"

namespace ks {

/// The metrics a kind writes to /runs (after the parameters), in order.
const std::vector<ColumnSpec>& trajectory_metric_columns();
const std::vector<ColumnSpec>& ik_metric_columns();
const std::vector<ColumnSpec>& metric_columns(BlockKind kind);

/// Outcome of one run, ready for the store.
struct RunOutcome {
  std::vector<Cell> metrics;  ///< metric_columns(kind) order
  std::string status;         ///< the kind's status name (ok, diverged, converged, max_iter, ...)
  RunHistory history;         ///< empty when histories are off
};

/// Per-thread buffers reused from run to run (no allocation per time step or iteration).
class RunWorkspace {
 public:
  RunWorkspace();
  ~RunWorkspace();
  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

/// Execute run `local` of block `block` of the study. `history_stride`: 0 = no history, N = every
/// N-th sample (trajectory) or iteration (ik). Never throws on bad numbers: trouble is a status.
RunOutcome execute_run(const Study& study, std::size_t block, std::span<const Cell> params, int history_stride,
                       RunWorkspace& workspace);

}  // namespace ks
