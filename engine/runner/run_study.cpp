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

#include "common/shell_word.hpp"
#include "runner/optimize_blocks.hpp"
#include "runner/resume_edited.hpp"
#include "runner/dry_run.hpp"
#include "runner/sweep_backend.hpp"
#include "runner/verify_best.hpp"

namespace ks {

namespace fs = std::filesystem;

std::vector<store::KindMeta> kind_meta(const Study& study) {
  std::vector<store::KindMeta> out;
  auto strings = [](auto&& range) {
    std::vector<std::string> v;
    for (const auto& x : range) v.emplace_back(x);
    return v;
  };
  for (const BlockKind kind : block_kinds()) {
    const Block* block = nullptr;
    for (const Block& b : study.blocks)
      if (!block && b.kind() == kind) block = &b;
    for (const OptimizeBlock& o : study.optimizations)
      if (!block && o.block().kind() == kind) block = &o.block();
    if (!block) continue;
    store::KindMeta k;
    k.name = std::string(to_string(kind));
    const auto st = statuses(kind);
    const Ranking rank = ranking(kind);
    std::vector<std::string> ranked{std::string(rank.objective)};
    if (!rank.tie.empty()) ranked.emplace_back(rank.tie);
    const auto arrays = kind == BlockKind::trajectory ? trajectory_history_arrays(study.robot_shape())
                                                      : ik_history_arrays(IkProblem::scara, study.robot_shape());
    std::vector<std::string> names, units;
    for (const auto& a : arrays) names.push_back(a.name), units.push_back(a.unit);
    k.lists = {{"statuses", strings(st)},
               {"good_statuses", {std::string(st.front())}},
               {"ranking", ranked},
               {"key_metrics", strings(key_metrics(kind))},
               {"objectives", objective_names(block->metrics())},
               {"history_arrays", names},
               {"resume_context", strings(context_parts(kind))}};
    if (kind == BlockKind::trajectory) k.lists.emplace_back("history_units", units);
    out.push_back(std::move(k));
  }
  return out;
}

/// The study's blocks whose design dimension is a Saltelli design (its axes written { saltelli = ... }).
std::vector<store::DesignMeta> design_meta(const Study& study) {
  std::vector<store::DesignMeta> out;
  for (std::size_t b = 0; b < study.blocks.size(); ++b) {
    const Block& block = study.blocks[b];
    store::DesignMeta d;
    for (std::size_t k = 0; k < block.dims().size(); ++k) {
      const Dim& dim = block.dims()[k];
      std::string name;
      for (std::size_t a : dim.axes) name += (name.empty() ? "" : "+") + block.axes()[a].name;
      d.dims.push_back(name);
      d.sizes.push_back(static_cast<std::int64_t>(dim.size));
      if (block.axes()[dim.axes.front()].form != "saltelli") continue;
      d.dim = static_cast<std::int64_t>(k);
      for (std::size_t a : dim.axes) d.factors.push_back(block.axes()[a].name);
    }
    if (d.factors.empty()) continue;
    d.block = block.name();
    d.kind = std::string(to_string(block.kind()));
    d.design = "saltelli";
    d.base_samples = d.sizes[static_cast<std::size_t>(d.dim)] / static_cast<std::int64_t>(d.factors.size() + 2);
    d.first_run = static_cast<std::int64_t>(study.first_run(b));
    out.push_back(std::move(d));
  }
  return out;
}

store::StoreMeta store_meta(const Study& study, const HistoryPolicy& histories) {
  store::StoreMeta meta;
  meta.histories = histories.str();
  meta.kinds = kind_meta(study);
  meta.designs = design_meta(study);
  meta.command_line = process_command_line();
  meta.study_name = study.name;
  meta.study_path = study.file;
  meta.study_text = study.text;
  meta.study_sha256 = study.sha256;
  meta.robot_path = study.robot_file;
  meta.robot_text = study.robot_text;
  return meta;
}

namespace {
/// The smallest dt of a trajectory block's runs [s] (its dt axis, else its dt).
double smallest_dt(const Block& b) {
  double dt = std::numeric_limits<double>::infinity();
  bool swept = false;
  for (const Axis& a : b.axes())
    if (a.name == "dt")
      for (const Cell& c : a.values) swept = true, dt = std::min(dt, std::get<double>(c));
  return swept ? dt : std::get<double>(b.value(0, "dt"));
}

std::string number(double v) {
  char s[32];
  std::snprintf(s, sizeof s, "%g", v);
  return s;
}

std::string megabytes(double bytes) {
  char s[32];
  std::snprintf(s, sizeof s, "%.0f MB", bytes / 1e6);
  return s;
}
}  // namespace

std::string history_memory_problem(const Study& study, const HistoryPolicy& histories) {
  if (histories.mode == HistoryPolicy::Mode::none) return "";
  double duration = 0;
  for (double d : study.task.durations) duration += d;
  const std::size_t values = values_per_row(trajectory_history_arrays(study.robot_shape()));
  for (const Block& b : study.blocks) {
    if (b.kind() != BlockKind::trajectory || b.run_count() == 0) continue;
    const double dt = smallest_dt(b);
    if (!(dt > 0)) continue;  // refused by the parser
    const double rows = history_rows(duration, dt, histories.stride);
    const double bytes = history_bytes_in_memory(rows, values);
    if (bytes <= kMaxHistoryBytesPerRun) continue;
    int stride = std::max(1, histories.stride);
    while (history_bytes_in_memory(history_rows(duration, dt, stride), values) > kMaxHistoryBytesPerRun) stride *= 2;
    int lo = stride / 2 + 1;  // the smallest stride that fits, between the last two powers of 2
    while (lo < stride) {
      const int mid = lo + (stride - lo) / 2;
      if (history_bytes_in_memory(history_rows(duration, dt, mid), values) > kMaxHistoryBytesPerRun) lo = mid + 1;
      else stride = mid;
    }
    return "block '" + b.name() + "': with histories = " + histories.str() + " a run on the " +
           number(duration) + " s path at dt = " + number(dt) + " s keeps " + std::to_string(static_cast<std::uint64_t>(rows)) + " history rows of " +
           std::to_string(values) + " values, " + megabytes(bytes) + " in memory while it runs; expected at most " +
           megabytes(kMaxHistoryBytesPerRun) + " per run: use histories = \"every=" + std::to_string(stride) +
           "\" or coarser, or \"none\" ([study] histories or --histories)";
  }
  return "";
}

std::string refuse_existing(const std::string& out, bool exists, const std::string& what, const RunRequest& r) {
  if (!exists || r.resume || r.overwrite) return "";
  return out + " " + what + "; use --resume to complete it or --overwrite to replace it";
}

namespace {
/// The bytes a new results file takes before any run: every /runs row is allocated at creation (8
/// bytes per number, 16 per string reference, 1 for the done flag), plus 1 MiB for the rest.
std::uint64_t skeleton_bytes(const StudySchema& schema, std::uint64_t runs) {
  std::uint64_t row = 1;
  for (const auto& c : schema.columns) row += c.type == CellType::str ? 16 : 8;
  return runs * row + (1u << 20);
}

}  // namespace

std::vector<std::string> find_shards(const std::string& output) {
  const fs::path p(output);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  const std::string prefix = p.filename().string() + ".rank";
  std::vector<std::pair<long, std::string>> found;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() <= prefix.size() + 3 || name.rfind(prefix, 0) != 0 || !name.ends_with(".h5")) continue;
    const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - 3);
    if (digits.empty() || !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
      continue;
    found.emplace_back(std::stol(digits), (p.parent_path() / name).string());
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> out;
  for (auto& [r, path] : found) out.push_back(std::move(path));
  return out;
}

void check_free_space(const std::string& out, const StudySchema& schema, std::uint64_t runs, int files) {
  const fs::path dir = fs::path(out).parent_path().empty() ? fs::path(".") : fs::path(out).parent_path();
  {  // a folder no file can be created in (read-only, no permission) is no free-space problem
    const std::string probe = (dir / ("." + fs::path(out).filename().string() + ".probe-" + std::to_string(::getpid()))).string();
    const int fd = ::open(probe.c_str(), O_CREAT | O_EXCL | O_WRONLY | O_CLOEXEC, 0600);
    if (fd < 0 && errno != EEXIST)
      throw store::StoreError(out, "cannot create a file in directory '" + dir.string() + "': " + std::strerror(errno) +
                                       "; expected a folder this user can write to");
    if (fd >= 0) ::close(fd), ::unlink(probe.c_str());
  }
  std::error_code ec;
  const fs::space_info sp = fs::space(dir, ec);
  if (ec) return;  // unknown: the writer reports a full disk as it happens
  const std::uint64_t need = skeleton_bytes(schema, runs) * static_cast<std::uint64_t>(files);
  if (need > sp.available)
    throw store::StoreError(out, (files == 1 ? "the file needs " : "the file and its shards need ") +
                                     std::to_string(need) + " bytes for their " + std::to_string(runs) +
                                     " run rows each before any run, but " + dir.string() + " has " +
                                     std::to_string(sp.available) + " bytes free; expected more free space "
                                     "(or fewer runs)");
}

namespace {
/// Refuses (StoreError) to resume a file whose /runs columns are not the study's (the same study
/// text under a kinesweep whose tables differ): its rows could not be read as this schema's.
void require_same_columns(const std::string& out, const std::vector<ColumnSpec>& file, const StudySchema& schema) {
  for (std::size_t c = 0; c < std::max(file.size(), schema.columns.size()); ++c) {
    const ColumnSpec* f = c < file.size() ? &file[c] : nullptr;
    const ColumnSpec* s = c < schema.columns.size() ? &schema.columns[c] : nullptr;
    if (f && s && f->name == s->name && f->type == s->type) continue;
    throw store::StoreError(out, "column " + std::to_string(c) + " of /runs is " + (f ? "'" + f->name + "'" : "absent") +
                                     ", the study's schema has " + (s ? "'" + s->name + "'" : "none") +
                                     " (refusing to resume: rerun with --overwrite)");
  }
}
}  // namespace

HistoryPolicy resume_histories(const std::string& path, const std::string& recorded, const HistoryPolicy& asked,
                               bool adopt) {
  HistoryPolicy p = asked;
  if (adopt && HistoryPolicy::parse(recorded, p)) return p;
  if (!recorded.empty() && recorded != asked.str())
    throw store::StoreError(path, "its runs were written with histories = " + recorded + ", this run asks for " +
                                      asked.str() + " ([study] histories or --histories): resume with --histories " +
                                      recorded + " (refusing to resume: rerun with --overwrite to replace the file)");
  return asked;
}

std::string histories_argument(const RunRequest& request) {
  return request.histories_given ? " --histories " + request.options.histories.str() : "";
}

OpenedResults open_results(const Study& study, const StudySchema& schema, const std::string& out, bool resume,
                           const store::StoreOptions& so, const HistoryPolicy& histories, bool adopt_recorded) {
  OpenedResults r;
  r.histories = histories;
  if (resume && fs::exists(out)) {
    // a file of other columns is refused before the writer opens it (which writes to it); a file the
    // reader cannot open (one a journal must recover first) is checked once the writer has it
    std::optional<std::vector<ColumnSpec>> readable;
    try {
      readable = store::ResultsReader(out).columns();
    } catch (const std::exception&) {
    }
    if (readable) require_same_columns(out, *readable, schema);
    r.writer = std::move(store::ResultsWriter::open_for_resume(out, study.sha256, so).writer);
    r.histories = resume_histories(out, r.writer->recorded_histories(), histories, adopt_recorded);
    if (const std::string why = history_memory_problem(study, r.histories); !why.empty())
      throw std::runtime_error(why);
    require_same_columns(out, r.writer->columns(), schema);
    r.previous = previous_runs(*r.writer);
    return r;
  }
  if (const std::string why = history_memory_problem(study, histories); !why.empty()) throw std::runtime_error(why);
  if (!fs::path(out).parent_path().empty()) fs::create_directories(fs::path(out).parent_path());
  check_free_space(out, schema, study.run_count(), 1);
  r.writer = store::ResultsWriter::create(out, store_meta(study, histories), schema.columns,
                                         static_cast<std::int64_t>(study.run_count()), so);
  return r;
}

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
