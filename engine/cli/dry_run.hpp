#pragma once
// `kinesweep run --dry-run`: the study's runs per block, and its time and file size estimated from
// sample runs of each block executed and written here.
#include <iosfwd>
#include <string>

#include "runner/schema.hpp"
#include "study/study.hpp"

namespace ks::cli {

struct DryRunOptions {
  HistoryPolicy histories;  ///< the policy the run would use
  int threads = 0;          ///< 0: all cores
  int lanes = 0;            ///< runs per SIMD batch as the sweep would use them (0: the widest)
  int compression = 1;      ///< history deflate level
  std::string output;       ///< the results file the run would write
  double seconds_per_block = 0.25;  ///< sampling budget per block (at least 4 runs each, at most 64)
};

/// Print the plan and the estimates to `out`. Writes only a temporary file (removed). Returns 0, or 1
/// when the sample file cannot be written (the message on `err`).
int dry_run(const Study& study, const StudySchema& schema, const DryRunOptions& options, std::ostream& out,
            std::ostream& err);

}  // namespace ks::cli
