#pragma once
// `kinesweep run STUDY.toml [-o FILE] [--threads N] [--resume] [--overwrite] [--dry-run]
//  [--histories full|every=N|none] [--compression 0..9] [--max-runs N] [-q] [--verbose] [--no-verify-best]`
#include <cstdint>
#include <string>

namespace CLI {
class App;
}

namespace ks::cli {

struct RunArgs {
  std::string study;
  std::string output;      ///< empty: the study's output
  int threads = 0;         ///< 0: all cores
  int lanes = 0;           ///< runs per SIMD batch: 1, 4 or 8 (0: the widest the processor runs)
  bool resume = false, overwrite = false, dry_run = false;
  std::string histories;   ///< empty: the study's policy
  bool quiet = false;      ///< no progress display
  bool no_verify_best = false;  ///< --no-verify-best: skip the best runs' grid verification
  int compression = 1;     ///< history deflate level (0: raw chunks, no filter)
  std::uint64_t max_runs = 50'000'000;  ///< the run-count limit (a study's max_runs may only lower it)
  bool verbose = false;    ///< HDF5's own error stack with a results-file error
  std::string program = "kinesweep";  ///< how the user invoked kinesweep (argv[0]), for printed commands
};

/// Register the subcommand; returns the argument struct it fills.
RunArgs& add_run_command(CLI::App& app);
/// Exit codes: 0 done, 1 store or I/O failure, 2 bad study file or arguments, 130 interrupted.
int run_command(const RunArgs& args);

}  // namespace ks::cli
