#pragma once
// What `kinesweep run` asks of a study's run (runner/run_study.hpp): the results file, resume or
// overwrite, dry run, verification, and the sweep's options.
#include <string>

#include "runner/sweep.hpp"

namespace ks {

struct RunRequest {
  std::string study_arg;   ///< the study path as the user gave it (for the resume hint)
  std::string program = "kinesweep";  ///< the command that runs kinesweep, one shell word (for the hint)
  std::string output;      ///< the results file
  bool resume = false, overwrite = false, quiet = false;
  /// Estimate instead: the runs per block, the file's size and the time, from sample runs of every
  /// block run by the sweep into a temporary file (runner/dry_run.hpp); nothing else is written.
  bool dry_run = false;
  /// options.histories was given on the command line (--histories); otherwise it is the study's,
  /// and a plain resume takes the policy the file records instead.
  bool histories_given = false;
  /// After the sweep and the optimisation blocks: verify each trajectory block's best runs of each
  /// method against its grid (runner/verify_best.hpp) into /verification, and print it.
  bool verify_best = true;
  /// threads (per process or rank; 0: all cores, shared fairly between the ranks on a node),
  /// histories, compression, stop (e.g. set by SIGINT), on_progress (the whole job's progress).
  SweepOptions options;
};

}  // namespace ks
