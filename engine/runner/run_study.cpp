// One "run a study" path (see run_study.hpp) and the local backend (this process's threads).
#include "runner/run_study.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <ostream>
#include <stdexcept>

#include <tbb/task_arena.h>

#include "common/shell_word.hpp"
#include "runner/optimize_blocks.hpp"
#include "runner/resume_edited.hpp"
#include "runner/dry_run.hpp"
#include "runner/sweep_backend.hpp"
#include "runner/verify_best.hpp"
#include "schema/params.hpp"
#include "sensitivity/design_indices.hpp"

namespace ks {

namespace fs = std::filesystem;

namespace {

/// A message on one line (HDF5's descriptions may hold line breaks).
std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

class LocalBackend final : public SweepBackend {
 public:
  bool leader() const override { return true; }

  int open(const Study& study, const StudySchema& schema, const RunRequest& r, std::ostream& err) override {
    const std::string& out = r.output;
    if (r.options.stop && r.options.stop->load()) {  // a signal during validation: nothing created
      err << "kinesweep run: interrupted before " << out << " was opened; nothing written\n";
      return 130;
    }
    if (fs::is_directory(out)) {
      err << "kinesweep run: " << out << " is a directory; expected a results file path (NAME.h5)\n";
      return 1;
    }
    const bool exists = fs::exists(out);
    if (const std::string why = refuse_existing(out, exists, "exists", r); !why.empty()) {
      err << "kinesweep run: " << why << '\n';
      return 1;
    }
    // Shards of a distributed run hold runs of `out` that this process would not see: refused
    // before anything is written (an MPI launch of one rank merges them).
    if (const std::vector<std::string> shards = find_shards(out); !shards.empty() && !r.overwrite) {
      std::string names;
      for (const auto& s : shards) names += (names.empty() ? "" : ", ") + s;
      err << "kinesweep run: " << out << " has shards of an unfinished distributed run (" << names
          << "); nothing was written. Resume it with: mpirun -np 1 " << r.program << " run " << shell_word(r.study_arg)
          << " -o " << shell_word(out) << " --resume (the launch merges the shards), or delete the shards to "
          << (exists ? "resume " + out + " alone" : "start afresh") << '\n';
      return 1;
    }
    store::StoreOptions so;  // commits every second (see StoreOptions)
    so.overwrite = r.overwrite;
    if (r.resume && exists && holds_edited_study(out, study)) {  // a new file, replacing `out` when complete
      if (const std::string why = history_memory_problem(study, r.options.histories); !why.empty()) {
        err << "kinesweep run: " << why << "; nothing written\n";
        return 1;
      }
      EditedResumeOptions eo;
      eo.histories = r.options.histories;
      eo.compression = r.options.compression;
      eo.store = so;
      edited_ = begin_edited_resume(study, schema, out, eo);
      writer_ = std::move(edited_->writer);
      previous_ = std::move(edited_->previous);
      return 0;
    }
    OpenedResults o = open_results(study, schema, out, r.resume, so, r.options.histories, !r.histories_given);
    writer_ = std::move(o.writer);
    histories_ = o.histories;
    previous_ = std::move(o.previous);
    return 0;
  }

  SweepResult sweep(const Study& study, const StudySchema& schema, const RunRequest& r, std::ostream& out,
                    std::ostream&) override {
    SweepResult res;
    SweepOptions o = r.options;
    if (!edited_) o.histories = histories_;
    if (r.quiet) o.on_progress = nullptr;
    if (edited_ && !edited_->context_changes.empty()) out << edited_->context_changes << "\n";
    if (edited_)
      out << "the study differs from the one in " << r.output << ": " << edited_->reused << " of its "
          << edited_->old_done << " done runs are runs of this study and are reused; a new file replaces it when "
          << "complete\n" << std::flush;
    res.report = run_sweep(study, schema, *writer_, o, previous_ ? &*previous_ : nullptr);
    previous_.reset();
    res.code = res.report.interrupted ? 130 : 0;
    res.writer = std::move(writer_);
    return res;
  }

  std::string kept_in(const RunRequest& r) const override { return r.output; }
  std::string kept(const RunRequest& r, const std::string& done) const override {
    if (!edited_) return SweepBackend::kept(r, done);
    return r.output + " is unchanged: the new file of the edited study (" + done +
           ") would replace it only once complete, and is deleted";
  }
  std::string resume_command(const RunRequest& r) const override {
    return r.program + " run " + shell_word(r.study_arg) + " -o " + shell_word(r.output) + " --resume" +
           histories_argument(r);
  }
  void publish(const RunRequest& r) override {
    if (!edited_) return;
    store::replace_results_file(edited_->staging, r.output);
    edited_.reset();
  }
  int finish(int code) override {
    if (edited_) {  // ended early: the old file stays as it was
      writer_.reset();
      store::remove_results_file(edited_->staging);
      edited_.reset();
    }
    return code;
  }

 private:
  std::optional<EditedResume> edited_;  // a resume of an edited study: the new file, beside the old one
  HistoryPolicy histories_;  // the policy of a new or plainly resumed file (open_results)
  std::optional<PreviousRuns> previous_;
  std::unique_ptr<store::ResultsWriter> writer_;
};

/// /sensitivity of the file the sweep wrote: every numeric metric of each Saltelli design's block, at
/// the estimator's default bootstrap, on `threads` threads (an empty table when the study has no design).
store::SensitivityTable design_sensitivity(const Study& study, const store::ResultsReader& file, int threads) {
  std::vector<DesignIndices> all;
  const SobolOptions options;
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  for (const store::DesignMeta& d : file.designs())
    for (const Block& block : study.blocks) {
      if (block.name() != d.block) continue;
      const std::string good(statuses(block.kind()).front());
      std::vector<DesignIndices> indices;
      arena.execute([&] { indices = design_indices(file, d, design_metrics(file, d.kind), good, options); });
      for (DesignIndices& r : indices) all.push_back(std::move(r));
    }
  return sensitivity_table(all, options);
}

/// The leader after the sweep: optimisation blocks into the same file, the report, the exit code.
int conclude(const Study& study, const RunRequest& r, SweepBackend& backend, SweepResult& res, std::ostream& out) {
  const SweepReport& report = res.report;
  if (res.code != 0) {
    if (res.writer) res.writer->close();
    if (res.code == 130) print_report(out, study, report);
    out << (res.code == 130 ? "interrupted" : "failed") << ": "
        << backend.kept(r, std::to_string(report.written + report.skipped) + " of " + std::to_string(report.total) + " runs")
        << "\nresume with: " << backend.resume_command(r) << '\n';
    return res.code;
  }
  print_report(out, study, report);
  if (!study.optimizations.empty()) {
    std::optional<store::ResultsReader> cells;  // the landscape cells for polish_from, as just written
    try {
      cells.emplace(res.writer->path());
    } catch (const store::StoreError&) {
    }
    OptimizeRunOptions oo;
    oo.threads = backend.threads(r);
    oo.cells = cells ? &*cells : nullptr;
    oo.stop = r.options.stop;
    const auto done = run_optimizations(study, res.writer.get(), oo, &out);
    const bool partial = !done.empty() && done.back().summary.stopped;
    if (partial || done.size() < study.optimizations.size()) {
      res.writer->close();
      const std::size_t complete = done.size() - (partial ? 1 : 0);
      out << "interrupted: "
          << backend.kept(r, "the sweep's " + std::to_string(report.total) + " runs, " + std::to_string(complete) +
                                 " of " + std::to_string(study.optimizations.size()) + " optimisation blocks" +
                                 (partial ? " and the evaluations of the next" : ""))
          << "\nresume with: " << backend.resume_command(r) << '\n';
      return 130;
    }
  }
  if (r.verify_best) {
    res.writer->flush();
    const store::ResultsReader file(res.writer->path());
    BestRunVerifyOptions vo;
    vo.threads = backend.threads(r);
    vo.stop = r.options.stop;
    const store::VerificationTable table = verify_best_runs(study, file, best_runs_to_verify(study, file), vo);
    if (r.options.stop && r.options.stop->load()) {
      res.writer->close();
      out << "interrupted: " << backend.kept(r, "the sweep's " + std::to_string(report.total) + " runs")
          << "; the best runs were not verified against the grid\nresume with: " << backend.resume_command(r) << '\n';
      return 130;
    }
    if (!table.rows.empty()) res.writer->write_verification(table);
    print_verification(out, table);
  }
  {
    res.writer->flush();
    const store::ResultsReader file(res.writer->path());
    if (!file.designs().empty()) {
      if (r.options.stop && r.options.stop->load()) {  // a resume computes them
        res.writer->close();
        out << "interrupted: " << backend.kept(r, "the sweep's " + std::to_string(report.total) + " runs")
            << "; the Sobol' indices were not computed\nresume with: " << backend.resume_command(r) << '\n';
        return 130;
      }
      const store::SensitivityTable indices = design_sensitivity(study, file, backend.threads(r));
      if (!indices.rows.empty()) res.writer->write_sensitivity(indices);
    }
  }
  res.writer->close();
  backend.publish(r);
  out << "results: " << r.output << '\n' << std::flush;
  return 0;
}

}  // namespace

std::unique_ptr<SweepBackend> local_backend() { return std::make_unique<LocalBackend>(); }

int run_study(const Study& study, const RunRequest& request, std::ostream& out, std::ostream& err) {
  const StudySchema schema = make_schema(study);
#ifdef KINESWEEP_HAVE_MPI
  std::unique_ptr<SweepBackend> backend =
      request.dry_run ? dry_run_backend() : launched_under_mpi() ? mpi_backend() : local_backend();
#else
  std::unique_ptr<SweepBackend> backend = request.dry_run ? dry_run_backend() : local_backend();
#endif
  int code = 0;
  try {
    code = backend->open(study, schema, request, err);
    if (code == 0) {
      SweepResult res = backend->sweep(study, schema, request, out, err);
      code = backend->leader() ? conclude(study, request, *backend, res, out) : res.code;
    }
  } catch (const std::exception& e) {  // store, file system or anything else: every rank ends through finish()
    err << "kinesweep run: " << one_line(e.what()) << '\n';
    code = 1;
  }
  return backend->finish(code);
}

}  // namespace ks
