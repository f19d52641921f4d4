#pragma once
// Where a study's runs are computed and stored (internal to engine/runner): this process's threads
// into the results file, MPI ranks into shards merged by rank 0, or (runner/dry_run.hpp) sample runs
// into a temporary file for the dry run's estimates. run_study drives each through the same steps:
// open, sweep, then (leader only) optimisations and report, then finish.
#include <memory>
#include <optional>
#include <ostream>
#include <string>

#include "runner/mpi_launch.hpp"
#include "runner/run_request.hpp"
#include "schema/history_arrays.hpp"
#include "store/store.hpp"
#include "study/study.hpp"

namespace ks {

struct SweepResult {
  int code = 0;          ///< 0 done, 1 failed, 130 interrupted (the same on every rank)
  SweepReport report;    ///< the leader's report of the whole sweep
  std::unique_ptr<store::ResultsWriter> writer;  ///< leader, done: the final file, still open
};

class SweepBackend {
 public:
  virtual ~SweepBackend() = default;
  /// True on the process that prints and runs the optimisation blocks.
  virtual bool leader() const = 0;
  /// Check the output against --resume / --overwrite and open what the sweep writes into. Returns 0,
  /// or an exit code after printing the problem to `err`. May throw store::StoreError.
  virtual int open(const Study& study, const StudySchema& schema, const RunRequest& request, std::ostream& err) = 0;
  /// Compute the runs not done yet. May throw store::StoreError.
  virtual SweepResult sweep(const Study& study, const StudySchema& schema, const RunRequest& request,
                            std::ostream& out, std::ostream& err) = 0;
  /// Threads for the optimisation blocks on the leader.
  virtual int threads(const RunRequest& request) const { return request.options.threads; }
  /// Where an interrupted sweep keeps its runs, and the command that resumes it.
  virtual std::string kept_in(const RunRequest& request) const = 0;
  /// What an early end keeps, given what is done (`done`: "N of M runs"): "N of M runs are kept in F".
  virtual std::string kept(const RunRequest& request, const std::string& done) const {
    return done + " are kept in " + kept_in(request);
  }
  /// The leader, once the final file is complete and closed: put it in place (a resume of an edited
  /// study builds it beside the file it replaces). May throw store::StoreError.
  virtual void publish(const RunRequest&) {}
  virtual std::string resume_command(const RunRequest& request) const = 0;
  /// The exit code every process returns, given the leader's `code` (MPI: broadcast, finalise).
  virtual int finish(int code) = 0;
};

/// This process's threads, writing the results file directly.
std::unique_ptr<SweepBackend> local_backend();
#ifdef KINESWEEP_HAVE_MPI
/// MPI ranks (MPI_Init here, MPI_Finalize in finish()).
std::unique_ptr<SweepBackend> mpi_backend();
#endif

/// A results file opened for a sweep: its writer, and what it already held (resume).
struct OpenedResults {
  std::unique_ptr<store::ResultsWriter> writer;
  std::optional<PreviousRuns> previous;  ///< set when an existing file was reopened
  HistoryPolicy histories;               ///< the policy to write the runs with
};
/// Reopen `out` when `resume` and it exists (its runs read first), else create it (and its folder)
/// recording `histories`. A reopened file keeps the policy it records: taken when `adopt_recorded`
/// (no --histories given), else it must be `histories`. Throws store::StoreError (another study,
/// another format version, another recorded history policy, unwritable, ...).
OpenedResults open_results(const Study& study, const StudySchema& schema, const std::string& out, bool resume,
                           const store::StoreOptions& options, const HistoryPolicy& histories,
                           bool adopt_recorded);

/// The shards of a distributed run of `output` that exist (`<out>.rank<digits>.h5`), by rank.
/// The history policy a resume of the file `path`, which records `recorded` ("" in files from
/// before it was recorded), writes its runs with: the recorded one when `adopt` (no --histories
/// given) and it parses, else `asked`, which must then equal the recorded one (a file never mixes
/// two policies). Throws store::StoreError naming both policies and the option that resumes.
HistoryPolicy resume_histories(const std::string& path, const std::string& recorded, const HistoryPolicy& asked,
                               bool adopt);

std::vector<std::string> find_shards(const std::string& output);

/// Throws store::StoreError when `files` new results files (a file and its shards) of `runs` rows
/// would not fit, before any run, in the free space of `out`'s directory.
void check_free_space(const std::string& out, const StudySchema& schema, std::uint64_t runs, int files);

/// " --histories X" when the request gave --histories X (so a printed resume command repeats it).
std::string histories_argument(const RunRequest& request);

/// "exists; use --resume ... or --overwrite ..." when `out` (or its `what`) exists and neither was
/// asked for; "" otherwise.
std::string refuse_existing(const std::string& out, bool exists, const std::string& what, const RunRequest& request);

}  // namespace ks
