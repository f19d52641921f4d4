#pragma once
// The Sobol' indices of a results file's Saltelli designs (/designs): per block, metric and
// combination of the block's other dimensions, from the runs as the file holds them. The one place
// the indices of a file are estimated: `kinesweep run` stores them in /sensitivity, `kinesweep
// sensitivity` prints them (with its own bootstrap settings), kinesweep.sensitivity reads them.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "sensitivity/sobol_indices.hpp"
#include "store/store.hpp"

namespace ks {

/// The indices of one metric at one combination of a design block's other dimensions.
struct DesignIndices {
  std::string block, kind;     ///< the design's block and its run kind
  std::vector<std::string> factors;  ///< the design's factors, in its order (the indices' order)
  std::string metric, unit;    ///< the /runs metric and its unit
  std::int64_t combination = 0;  ///< the combination of the other dimensions, in run order (0 when none)
  std::string at;              ///< those dimensions' values, "method=local_weighted, k=0.5" ("" when none)
  std::string good;            ///< the kind's good status: the indices are conditional on it
  std::map<std::string, std::uint64_t> failed;  ///< status -> runs of the combination with another status (done)
  std::uint64_t not_done = 0;          ///< runs of the combination not done
  std::uint64_t failed_samples = 0;    ///< sample rows left out because a run of theirs failed (all done)
  std::uint64_t not_done_samples = 0;  ///< sample rows left out because a run of theirs is not done
  SobolIndices s;                      ///< sobol_indices of the sample rows (a failed or missing run: NaN)
};

/// The numeric metric columns of `kind`'s runs in `file`, in column order.
std::vector<std::string> design_metrics(const store::ResultsReader& file, const std::string& kind);

/// The indices of `metrics` (numeric /runs columns) for every combination of design `d`'s other
/// dimensions (metric by metric, combinations in run order). `good`: the status of a run whose value
/// counts (the kind's good status); a run not done or with another status is a NaN sample value.
/// The estimates run in parallel (TBB, in the caller's arena); each is the same whatever the threads.
std::vector<DesignIndices> design_indices(const store::ResultsReader& file, const store::DesignMeta& d,
                                          const std::vector<std::string>& metrics, const std::string& good,
                                          const SobolOptions& options);

/// /sensitivity's rows (store::SensitivityTable, FORMAT.md) of `results`: one per factor.
store::SensitivityTable sensitivity_table(const std::vector<DesignIndices>& results, const SobolOptions& options);

}  // namespace ks
