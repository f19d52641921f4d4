// Distributed sweeps over MPI: per-rank shard files, a dynamic coordinator on rank 0, a merge on
// rank 0 at the end. Why shards and not parallel HDF5:
// - each shard is a normal ResultsWriter file, so the crash safety of the store (journal, atomic
//   commits, done mask) holds per rank unchanged: a rank killed with SIGKILL loses only its runs since
//   its last commit, and the next launch redoes exactly those;
// - parallel HDF5 (MPI-IO) needs collective calls for every metadata change (creating a history
//   group, extending...), i.e. all ranks in lock step, which is at odds with dynamic load balancing
//   and with the store's journaled file driver (a custom VFD, not MPI-IO);
// - the merged file is written by the ordinary single writer in run-id order, so it is the same file
//   (every /runs column but wall_time, every history, every landscape) as a single-process run's.
#include "runner/mpi_sweep.hpp"

#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <thread>

#include "common/shell_word.hpp"
#include "runner/mpi_work.hpp"
#include "runner/study_meta.hpp"
#include "runner/sweep_backend.hpp"

namespace ks {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using namespace ks::mpi;


/// Rank 0 after the sweep: final file (or a new one) + every shard -> the final file, in run-id
/// order; then landscapes via run_sweep (which computes nothing, every run being done); then the
/// shards are deleted. Returns the report and the final file, still open.
SweepResult merge(const Study& study, const StudySchema& schema, const RunRequest& run, const HistoryPolicy& histories,
                  int threads, const SweepReport* ranks) {
  const std::string& out = run.output;
  const std::uint64_t total = study.run_count();
  // Commits are the store's main cost (each journals every dirty page of /runs); the merge can be
  // redone from the shards, so it commits rarely (every 30 s) instead of every 64 runs.
  store::StoreOptions so;
  so.flush_every_runs = 0;
  so.flush_every_seconds = 30.0;
  so.overwrite = run.overwrite;  // written aside: the previous file is replaced at the first commit
  OpenedResults opened = open_results(study, schema, out, !run.overwrite, so, histories, false);
  std::unique_ptr<store::ResultsWriter> writer = std::move(opened.writer);
  PreviousRuns all;
  if (opened.previous) all = std::move(*opened.previous);
  all.done.resize(total, false);
  const bool fresh = std::none_of(all.done.begin(), all.done.end(), [](bool d) { return d; });

  const std::vector<std::string> shards = find_shards(out);
  std::vector<std::unique_ptr<store::ResultsReader>> readers;
  std::vector<std::int32_t> owner(total, -1);
  for (std::size_t s = 0; s < shards.size(); ++s) {
    auto r = std::make_unique<store::ResultsReader>(shards[s]);
    if (r->meta().study_sha256 != study.sha256 || r->n_runs() != static_cast<std::int64_t>(total))
      throw store::StoreError(shards[s], "shard of another study");
    const auto mask = r->done_mask();
    for (std::uint64_t id = 0; id < total && id < mask.size(); ++id)
      if (mask[id] && !all.done[id]) all.done[id] = true, owner[id] = static_cast<std::int32_t>(s);
    readers.push_back(std::move(r));
  }
  const std::uint64_t missing = static_cast<std::uint64_t>(std::count(all.done.begin(), all.done.end(), false));
  if (missing)
    throw store::StoreError(out, std::to_string(missing) + " runs are in neither the results file nor a shard");

  // The runs, column by column (histories as the shards store them; /runs chunks a shard holds
  // whole copied as stored). A results file of format 3 (a resumed one) takes them run by run.
  const int level = run.options.compression;
  std::vector<const store::ResultsReader*> sources;
  for (const auto& r : readers) sources.push_back(r.get());
  const bool copied = writer->copy_runs(sources, owner, level);
  if (!copied) {
    constexpr std::size_t kPiece = 4096;  // each shard's rows of a piece in one range read per column
    std::vector<std::uint64_t> ids;
    for (std::uint64_t id = 0; id < total; ++id)
      if (owner[id] >= 0) ids.push_back(id);
    for (std::size_t at = 0; at < ids.size(); at += kPiece) {
      const std::size_t n = std::min(kPiece, ids.size() - at);
      std::vector<Record> rows(n);
      for (std::size_t s = 0; s < readers.size(); ++s) {
        std::size_t first = n, last = 0;
        for (std::size_t i = 0; i < n; ++i)
          if (owner[ids[at + i]] == static_cast<std::int32_t>(s)) first = std::min(first, i), last = i;
        if (first == n) continue;
        const auto from = static_cast<std::int64_t>(ids[at + first]);
        std::vector<Record> got = readers[s]->read_rows(from, static_cast<std::int64_t>(ids[at + last]) - from + 1);
        for (std::size_t i = first; i <= last; ++i)
          if (owner[ids[at + i]] == static_cast<std::int32_t>(s))
            rows[i] = std::move(got[static_cast<std::size_t>(static_cast<std::int64_t>(ids[at + i]) - from)]);
      }
      for (std::size_t i = 0; i < n; ++i) {
        const std::uint64_t id = ids[at + i];
        writer->write_run(static_cast<std::int64_t>(id), rows[i], readers[owner[id]]->read_history_chunks(static_cast<std::int64_t>(id), level));
      }
    }
  }
  writer->flush();

  // Landscapes and the summary: each shard holds the landscape cells of its runs, as this file
  // would compute them from the same rows; when every run came from a shard as stored, the cells
  // are copied from their shard and the summary reads only the columns it ranks and counts by.
  SweepOptions o;
  o.threads = threads;
  o.histories = histories;
  o.compression = level;
  bool all_copied = true;
  if (copied && fresh)
    o.fill_landscape = [&](std::size_t b, std::size_t landscape) {
      const bool ok = writer->copy_landscape(landscape, sources, owner.data() + study.first_run(b));
      all_copied = all_copied && ok;
      return ok;
    };
  // The ranks' reports cover every run when none was done before this job: then the summary needs
  // no /runs column of the merged file (run_sweep reads none when every landscape was copied).
  o.report_previous = !(ranks && copied && fresh);
  SweepResult res;
  res.report = run_sweep(study, schema, *writer, o, &all);
  if (!o.report_previous && all_copied) {
    res.report.blocks = ranks->blocks;
    res.report.seed_rows = ranks->seed_rows;
  }
  readers.clear();
  writer->flush();
  for (const auto& s : shards) store::remove_results_file(s);
  res.writer = std::move(writer);
  return res;
}


class MpiBackend final : public SweepBackend {
 public:
  MpiBackend() {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_MULTIPLE, &provided);
    MPI_Comm_dup(MPI_COMM_WORLD, &comm_);
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &size_);
    serialized_ = provided >= MPI_THREAD_SERIALIZED;
  }

  bool leader() const override { return rank_ == 0; }
  int threads(const RunRequest&) const override { return threads_; }
  std::string kept_in(const RunRequest& r) const override {
    return "the results file and the shards " + shard_path(r.output, 0) + " ...";
  }
  std::string resume_command(const RunRequest& r) const override {
    return "mpirun -np " + std::to_string(size_) + " " + r.program + " run " + shell_word(r.study_arg) + " -o " +
           shell_word(r.output) + " --resume" + histories_argument(r);
  }

  int open(const Study& study, const StudySchema& schema, const RunRequest& r, std::ostream& err) override {
    auto fail = [&](const std::string& what) { err << "kinesweep run [rank " << rank_ << "]: " << what << '\n' << std::flush; };
    if (!serialized_) {
      if (rank_ == 0) fail("the MPI library does not support MPI_THREAD_SERIALIZED");
      return 1;
    }
    start_ = Clock::now();
    threads_ = rank_threads(r.options.threads);
    // A signal to any rank during validation: every rank stops before a file is created.
    int stop = r.options.stop && r.options.stop->load() ? 1 : 0;
    MPI_Allreduce(MPI_IN_PLACE, &stop, 1, MPI_INT, MPI_MAX, comm_);
    if (stop) {
      if (rank_ == 0) err << "kinesweep run: interrupted before " << r.output << " was opened; nothing written\n";
      return 130;
    }
    // 1. Rank 0 checks the files and collects the done set; everybody learns it.
    const std::uint64_t total = study.run_count();
    int code = 0;
    done_.assign(total, false);
    histories_ = r.options.histories;
    if (rank_ == 0) {
      std::string msg;
      try {
        code = prepare(study, schema, r, msg);
      } catch (const std::exception& e) {  // every rank must reach the Bcast
        code = 1, msg = e.what();
      }
      if (code) fail(msg);
    }
    MPI_Bcast(&code, 1, MPI_INT, 0, comm_);
    if (code) return code;
    bcast_bits(done_, comm_);
    std::string policy = histories_.str();
    bcast_string(policy, comm_);
    HistoryPolicy::parse(policy, histories_);
    // 2. Every rank opens its shard (reopens it when resuming). Shards commit every 512 runs or 2 s:
    // commits are the writer's main cost, and a killed rank loses at most that much.
    int local = 0;
    try {
      store::StoreOptions so;
      so.flush_every_runs = 512;
      so.flush_every_seconds = 2.0;
      const std::string sp = shard_path(r.output, rank_);
      if (fs::exists(sp)) {
        shard_ = std::move(store::ResultsWriter::open_for_resume(sp, study.sha256, so).writer);
        resume_histories(sp, shard_->recorded_histories(), histories_, false);
      } else {
        shard_ = store::ResultsWriter::create(sp, store_meta(study, histories_), schema.columns,
                                              static_cast<std::int64_t>(total), so);
      }
    } catch (const std::exception& e) {  // every rank must reach the Allreduce
      fail(e.what());
      local = 1;
    }
    MPI_Allreduce(MPI_IN_PLACE, &local, 1, MPI_INT, MPI_MAX, comm_);
    return local;
  }

  SweepResult sweep(const Study& study, const StudySchema& schema, const RunRequest& r, std::ostream& out,
                    std::ostream& err) override;

  int finish(int code) override {
    // The other ranks wait for the leader's verdict without spinning a core (a blocking MPI_Bcast would).
    MPI_Request req;
    MPI_Ibcast(&code, 1, MPI_INT, 0, comm_, &req);
    wait_gently(req, MPI_STATUS_IGNORE);
    MPI_Comm_free(&comm_);
    MPI_Finalize();
    return code;
  }

 private:
  /// Threads per rank: as asked; else the cores this rank is bound to, or (unbound) the node's cores
  /// shared between the ranks on the node.
  int rank_threads(int asked) {
    MPI_Comm node;
    MPI_Comm_split_type(comm_, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &node);
    int node_ranks = 1;
    MPI_Comm_size(node, &node_ranks);
    MPI_Comm_free(&node);
    if (asked > 0) return asked;
    const int allowed = tbb::info::default_concurrency();
    const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
    return allowed < cores ? allowed : std::max(1, cores / node_ranks);
  }

  /// Rank 0 before the sweep: check what exists, apply --overwrite, collect the done set of --resume
  /// and the history policy the files record (every file must record the same one).
  int prepare(const Study& study, const StudySchema& schema, const RunRequest& run, std::string& msg) {
    const std::string& out = run.output;
    const bool exists = fs::exists(out);
    const std::vector<std::string> shards = find_shards(out);
    msg = refuse_existing(out, exists, "exists", run);
    if (msg.empty() && !shards.empty())
      msg = refuse_existing(out, true, "has shards of an unfinished distributed run (" + shards.front() + ")", run);
    if (!msg.empty()) return 1;
    if (run.overwrite) {  // the previous file stays until the merge's first commit replaces it
      for (const auto& s : shards) store::remove_results_file(s);
    } else if (run.resume) {
      std::vector<std::string> files = shards;
      if (exists) files.insert(files.begin(), out);
      for (const auto& f : files) {
        store::ResultsReader rd(f);
        store::require_resumable(f, rd.meta());
        if (rd.meta().study_sha256 != study.sha256 || rd.n_runs() != static_cast<std::int64_t>(done_.size())) {
          msg = f + " holds another study (study_sha256 " + rd.meta().study_sha256 + ", this study " + study.sha256 + ")";
          return 1;
        }
        histories_ = resume_histories(f, rd.meta().histories, histories_, !run.histories_given && f == files.front());
        const auto mask = rd.done_mask();
        for (std::size_t i = 0; i < done_.size() && i < mask.size(); ++i)
          if (mask[i]) done_[i] = true;
      }
    }
    msg = history_memory_problem(study, histories_);
    if (!msg.empty()) return 1;
    if (!fs::path(out).parent_path().empty()) fs::create_directories(fs::path(out).parent_path());
    if (!run.resume || (!exists && shards.empty())) check_free_space(out, schema, done_.size(), size_ + 1);
    return 0;
  }

  MPI_Comm comm_;
  int rank_ = 0, size_ = 1, threads_ = 1;
  bool serialized_ = false;
  Clock::time_point start_;
  std::vector<bool> done_;  // one bit per run: done in the results file or a shard
  HistoryPolicy histories_;  // the policy of the files resumed, else the request's
  std::unique_ptr<store::ResultsWriter> shard_;
};

SweepResult MpiBackend::sweep(const Study& study, const StudySchema& schema, const RunRequest& r, std::ostream& out,
                              std::ostream& err) {
  // 3. The sweep: rank 0 coordinates (a thread) and computes; the others compute what it hands out.
  const std::uint64_t total = study.run_count();
  const auto todo_n = static_cast<std::uint64_t>(std::count(done_.begin(), done_.end(), false));
  SweepOptions o = r.options;
  o.threads = threads_;
  o.histories = histories_;
  // shards compress as the results file does: the merge copies their chunks without decoding them
  o.source_runs = todo_n;
  std::unique_ptr<WorkPool> pool;
  std::unique_ptr<RemoteSource> remote;
  std::vector<std::atomic<std::uint64_t>> remote_done(size_);
  std::thread coordinator;
  if (rank_ == 0) {
    pool = std::make_unique<WorkPool>(std::move(done_), size_, store::kRunsChunkRows);
    o.source = [&](std::vector<std::uint64_t>& ids, std::size_t max) {
      ids = pool->take(max);
      return !ids.empty();
    };
    o.on_progress = [&](const SweepProgress& p) {
      std::uint64_t all = p.done;
      for (int k = 1; k < size_; ++k) all += remote_done[k].load();
      if (r.options.on_progress && !r.quiet) r.options.on_progress({std::min(all, todo_n), todo_n, p.elapsed_s});
    };
    if (size_ > 1) coordinator = std::thread([&] { coordinate(comm_, size_, o.batch, *pool, remote_done, o.stop); });
  } else {
    std::vector<bool>().swap(done_);
    remote = std::make_unique<RemoteSource>(comm_, threads_, o.batch);
    o.source = [&](std::vector<std::uint64_t>& ids, std::size_t max) { return remote->next(ids, max); };
    o.on_progress = [&](const SweepProgress& p) { remote->written.store(p.done); };
  }
  SweepResult res;
  int status = 0;  // 0 done, 1 failed, 130 interrupted
  try {
    res.report = run_sweep(study, schema, *shard_, o, nullptr);
    if (res.report.interrupted) status = 130;
    shard_->close();
  } catch (const std::exception& e) {  // the coordinator is joined and the ranks settle below
    err << "kinesweep run [rank " << rank_ << "]: " << e.what() << '\n' << std::flush;
    status = 1;
  }
  if (pool && status) pool->halt();
  if (remote) remote->finish();
  if (coordinator.joinable()) coordinator.join();
  shard_.reset();
  const double sweep_s = std::chrono::duration<double>(Clock::now() - start_).count();

  int failed = status == 1, interrupted = status == 130;
  unsigned long long written = res.report.written;
  MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPI_INT, MPI_MAX, comm_);
  MPI_Allreduce(MPI_IN_PLACE, &interrupted, 1, MPI_INT, MPI_MAX, comm_);
  MPI_Allreduce(MPI_IN_PLACE, &written, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, comm_);
  res.report.total = total;
  res.report.written = written;
  res.report.skipped = total - todo_n;
  if (failed || interrupted) {
    res.code = failed ? 1 : 130;
    res.report.blocks.clear();  // rank 0's own counts would read as the job's: the totals only
    res.report.seed_rows.clear();
    return res;
  }
  // Every rank's report of the runs it computed, to rank 0: all the job's runs when none was done
  // before it (each report a few kilobytes).
  std::optional<SweepReport> ranks;
  if (todo_n == total) {
    const std::string mine = encode_report(res.report);
    int n = static_cast<int>(mine.size());
    std::vector<int> sizes(static_cast<std::size_t>(size_)), at(static_cast<std::size_t>(size_));
    MPI_Gather(&n, 1, MPI_INT, sizes.data(), 1, MPI_INT, 0, comm_);
    std::string all;
    if (rank_ == 0) {
      for (int k = 0, t = 0; k < size_; t += sizes[static_cast<std::size_t>(k)], ++k) at[static_cast<std::size_t>(k)] = t;
      all.resize(static_cast<std::size_t>(at.back() + sizes.back()));
    }
    MPI_Gatherv(mine.data(), n, MPI_CHAR, all.data(), sizes.data(), at.data(), MPI_CHAR, 0, comm_);
    if (rank_ == 0) {
      ranks = decode_report(all.substr(0, static_cast<std::size_t>(sizes[0])));
      for (int k = 1; k < size_; ++k)
        merge_reports(*ranks, decode_report(all.substr(static_cast<std::size_t>(at[static_cast<std::size_t>(k)]),
                                                       static_cast<std::size_t>(sizes[static_cast<std::size_t>(k)]))));
    }
  }
  if (rank_ != 0) return res;
  if (r.options.on_progress && !r.quiet) r.options.on_progress({todo_n, todo_n, sweep_s});
  // 4. Rank 0 merges (the others wait in finish()).
  const auto t0 = Clock::now();
  try {
    res = merge(study, schema, r, histories_, threads_, ranks ? &*ranks : nullptr);
  } catch (const store::StoreError& e) {
    throw store::StoreError(r.output, std::string(e.what()) + " (the shards are kept: run again with --resume)");
  }
  const double merge_s = std::chrono::duration<double>(Clock::now() - t0).count();
  res.report.written = written;
  res.report.skipped = total - std::min<std::uint64_t>(total, written);
  res.report.elapsed_s = std::chrono::duration<double>(Clock::now() - start_).count();
  char line[256];
  std::snprintf(line, sizeof line, "distributed: %d ranks x %d threads; sweep %.2f s, merge %.2f s\n", size_,
                threads_, sweep_s, merge_s);
  out << line;
  return res;
}

}  // namespace

std::string shard_path(const std::string& output, int rank) { return output + ".rank" + std::to_string(rank) + ".h5"; }

std::unique_ptr<SweepBackend> mpi_backend() { return std::make_unique<MpiBackend>(); }

}  // namespace ks
