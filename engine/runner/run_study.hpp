#pragma once
// `kinesweep run`: one path for every way a study runs. The sweep's runs come from this process's
// threads or, when an MPI launcher started the process, from all ranks (shards merged by rank 0);
// then the leader (the process, or rank 0) runs the [[optimize]] blocks into the same file and
// prints the report. See runner/sweep_backend.hpp for the two sources.
#include <iosfwd>
#include <string>

#include "runner/sweep.hpp"
#include "schema/history_arrays.hpp"

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

/// Run the study's sweep and optimisation blocks into request.output; print the report to `out`
/// and problems to `err` (under MPI: rank 0 prints). Returns the exit code, the same on every
/// rank: 0 done, 1 results file problem, 130 interrupted.
int run_study(const Study& study, const RunRequest& request, std::ostream& out, std::ostream& err);

/// "" when every trajectory run of `study` keeps a history of at most kMaxHistoryBytesPerRun in
/// memory under `histories`; else why not, naming the block, the run's rows and bytes, and the
/// coarsest policy that fits ("every=N"). Checked before a results file is created or resumed.
std::string history_memory_problem(const Study& study, const HistoryPolicy& histories);

/// The meaning of each run kind the study's blocks use, as its results file records it (/kinds):
/// statuses (enum order), good_statuses, ranking (objective, then tie), key_metrics, objectives,
/// history_arrays (and, trajectory, history_units).
std::vector<store::KindMeta> kind_meta(const Study& study);

/// The StoreMeta of a study's results file (or shard) whose runs are written with `histories`.
store::StoreMeta store_meta(const Study& study, const HistoryPolicy& histories);

/// The history policy a resume of the file `path`, which records `recorded` ("" in files from
/// before it was recorded), writes its runs with: the recorded one when `adopt` (no --histories
/// given) and it parses, else `asked`, which must then equal the recorded one (a file never mixes
/// two policies). Throws store::StoreError naming both policies and the option that resumes.
HistoryPolicy resume_histories(const std::string& path, const std::string& recorded, const HistoryPolicy& asked,
                               bool adopt);

}  // namespace ks
