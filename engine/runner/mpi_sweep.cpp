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
// MPI threading: rank 0's coordinator thread and the workers' pipeline source stage are the only
// callers of MPI during the sweep, never concurrently within one process (MPI_THREAD_SERIALIZED).
#include "runner/mpi_sweep.hpp"

#include <mpi.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <thread>

namespace ks {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr int kTagRequest = 0x6b73;
constexpr int kTagReply = 0x6b74;
constexpr std::uint64_t kMaxChunk = 1024;  ///< largest chunk of run ids handed out at once

bool env_set(const char* name) {
  const char* v = std::getenv(name);
  return v && *v;
}

/// Shards of `output` that exist, by rank: `<out>.rank<digits>.h5`.
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

void remove_results_file(const std::string& path) {
  std::error_code ec;
  fs::remove(path, ec);
  fs::remove(path + ".journal", ec);
}

/// Wait for a request without spinning a core (Open MPI's blocking waits busy-poll; the cores
/// belong to the TBB workers).
void wait_gently(MPI_Request& request, MPI_Status* status) {
  int flag = 0;
  auto pause = std::chrono::microseconds(10);
  for (;;) {
    MPI_Test(&request, &flag, status);
    if (flag) return;
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::microseconds(200));
  }
}

void bcast_bytes(std::vector<std::uint8_t>& v, MPI_Comm comm) {
  constexpr std::size_t slice = std::size_t(1) << 30;
  for (std::size_t at = 0; at < v.size(); at += slice)
    MPI_Bcast(v.data() + at, static_cast<int>(std::min(slice, v.size() - at)), MPI_UINT8_T, 0, comm);
}

/// The run ids still to do, handed out in ascending order (rank 0).
class WorkPool {
 public:
  WorkPool(std::vector<std::uint64_t> todo, int ranks) : todo_(std::move(todo)), ranks_(ranks) {}
  /// Up to `max` ids for rank 0's own pipeline.
  std::vector<std::uint64_t> take(std::size_t max) { return slice(max); }
  /// A chunk for a remote rank with `threads` threads: guided (remaining / 4 ranks), at least two
  /// rounds of its pipeline, at most kMaxChunk.
  std::vector<std::uint64_t> take_chunk(std::uint64_t threads, std::size_t batch) {
    std::lock_guard<std::mutex> lock(m_);
    const std::uint64_t remaining = todo_.size() - next_;
    const std::uint64_t lo = std::max<std::uint64_t>(1, 2 * threads * batch);
    const std::uint64_t n = std::min(kMaxChunk, std::max(lo, remaining / (4 * static_cast<std::uint64_t>(ranks_))));
    return slice_locked(n);
  }
  void halt() {
    std::lock_guard<std::mutex> lock(m_);
    halted_ = true;
  }

 private:
  std::vector<std::uint64_t> slice(std::size_t n) {
    std::lock_guard<std::mutex> lock(m_);
    return slice_locked(n);
  }
  std::vector<std::uint64_t> slice_locked(std::size_t n) {
    if (halted_) return {};
    n = std::min<std::size_t>(n, todo_.size() - next_);
    std::vector<std::uint64_t> ids(todo_.begin() + next_, todo_.begin() + next_ + n);
    next_ += n;
    return ids;
  }
  std::mutex m_;
  std::vector<std::uint64_t> todo_;
  std::size_t next_ = 0;
  int ranks_;
  bool halted_ = false;
};

/// Rank 0's coordinator thread: answers chunk requests until every other rank has retired (got an
/// empty chunk or said it quits). Request: {quit, runs written so far, threads}.
void coordinate(MPI_Comm comm, int size, std::size_t batch, WorkPool& pool, std::vector<std::atomic<std::uint64_t>>& remote_done,
                const std::atomic<bool>* stop) {
  int active = size - 1;
  std::vector<char> retired(size, 0);
  while (active > 0) {
    std::uint64_t req[3] = {0, 0, 1};
    MPI_Request r;
    MPI_Status st;
    MPI_Irecv(req, 3, MPI_UINT64_T, MPI_ANY_SOURCE, kTagRequest, comm, &r);
    wait_gently(r, &st);
    const int src = st.MPI_SOURCE;
    remote_done[src].store(req[1]);
    if (req[0]) {
      if (!retired[src]) retired[src] = 1, --active;
      continue;
    }
    std::vector<std::uint64_t> ids;
    if (!(stop && stop->load())) ids = pool.take_chunk(req[2], batch);
    MPI_Send(ids.data(), static_cast<int>(ids.size()), MPI_UINT64_T, src, kTagReply, comm);
    if (ids.empty()) retired[src] = 1, --active;
  }
}

/// A worker rank's SweepOptions::source: a local queue refilled from rank 0, one request ahead.
class RemoteSource {
 public:
  RemoteSource(MPI_Comm comm, int threads, std::size_t batch)
      : comm_(comm), threads_(threads), low_water_(2 * static_cast<std::size_t>(threads) * batch), reply_(kMaxChunk) {}

  bool next(std::vector<std::uint64_t>& ids, std::size_t max) {
    if (outstanding_) poll(false);
    if (!finished_ && !outstanding_ && queue_.size() <= low_water_) request();
    while (queue_.empty()) {
      if (finished_) return false;
      if (!outstanding_) request();
      poll(true);
    }
    while (!queue_.empty() && ids.size() < max) {
      ids.push_back(queue_.front());
      queue_.pop_front();
    }
    return true;
  }
  /// After the sweep (finished, interrupted or failed): settle the protocol with rank 0.
  void finish() {
    if (outstanding_) poll(true);
    if (!retired_) {
      std::uint64_t req[3] = {1, written.load(), static_cast<std::uint64_t>(threads_)};
      MPI_Send(req, 3, MPI_UINT64_T, 0, kTagRequest, comm_);
      retired_ = true;
    }
  }
  std::atomic<std::uint64_t> written{0};

 private:
  void request() {
    MPI_Irecv(reply_.data(), static_cast<int>(reply_.size()), MPI_UINT64_T, 0, kTagReply, comm_, &pending_);
    std::uint64_t req[3] = {0, written.load(), static_cast<std::uint64_t>(threads_)};
    MPI_Send(req, 3, MPI_UINT64_T, 0, kTagRequest, comm_);
    outstanding_ = true;
  }
  void poll(bool wait) {
    MPI_Status st;
    int flag = 0;
    if (wait) {
      wait_gently(pending_, &st);
      flag = 1;
    } else {
      MPI_Test(&pending_, &flag, &st);
    }
    if (!flag) return;
    outstanding_ = false;
    int n = 0;
    MPI_Get_count(&st, MPI_UINT64_T, &n);
    if (n == 0) finished_ = retired_ = true;
    queue_.insert(queue_.end(), reply_.begin(), reply_.begin() + n);
  }

  MPI_Comm comm_;
  int threads_;
  std::size_t low_water_;
  std::vector<std::uint64_t> reply_;
  std::deque<std::uint64_t> queue_;
  MPI_Request pending_ = MPI_REQUEST_NULL;
  bool outstanding_ = false, finished_ = false, retired_ = false;
};

store::StoreMeta meta_of(const Study& study) {
  store::StoreMeta meta;
  meta.study_name = study.name;
  meta.study_path = study.file;
  meta.study_text = study.text;
  meta.study_sha256 = study.sha256;
  return meta;
}

/// Rank 0 before the sweep: check what exists, apply --overwrite, collect the done set of --resume.
/// Returns 0, or 1 with `msg`.
int prepare(const Study& study, const DistributedRun& run, std::vector<std::uint8_t>& done, std::string& msg) {
  const std::string& out = run.output;
  const bool exists = fs::exists(out);
  const std::vector<std::string> shards = find_shards(out);
  if (!run.resume && !run.overwrite && (exists || !shards.empty())) {
    msg = out + (exists ? " exists" : " has shards of an unfinished distributed run (" + shards.front() + ")") +
          "; use --resume to complete it or --overwrite to replace it";
    return 1;
  }
  if (run.overwrite) {
    if (exists) remove_results_file(out);
    for (const auto& s : shards) remove_results_file(s);
  } else if (run.resume) {
    std::vector<std::string> files = shards;
    if (exists) files.insert(files.begin(), out);
    for (const auto& f : files) {
      store::ResultsReader r(f);
      if (r.meta().study_sha256 != study.sha256 || r.n_runs() != static_cast<std::int64_t>(done.size())) {
        msg = f + " holds another study (study_sha256 " + r.meta().study_sha256 + ", this study " + study.sha256 + ")";
        return 1;
      }
      const auto mask = r.done_mask();
      for (std::size_t i = 0; i < done.size() && i < mask.size(); ++i) done[i] |= mask[i];
    }
  }
  if (!fs::path(out).parent_path().empty()) fs::create_directories(fs::path(out).parent_path());
  return 0;
}

/// Rank 0 after the sweep: final file (or a new one) + every shard -> the final file, in run-id
/// order; then landscapes via run_sweep (which computes nothing, every run being done); then the
/// shards are deleted. Returns the report.
SweepReport merge(const Study& study, const StudySchema& schema, const DistributedRun& run, int threads) {
  const std::string& out = run.output;
  const std::uint64_t total = study.run_count();
  PreviousRuns all;
  std::unique_ptr<store::ResultsWriter> writer;
  // Commits are the store's main cost (each journals every dirty page of /runs); the merge can be
  // redone from the shards, so it commits rarely (every 30 s) instead of every 64 runs.
  store::StoreOptions so;
  so.flush_every_runs = 0;
  so.flush_every_seconds = 30.0;
  if (fs::exists(out)) {
    all = read_previous(out, schema);
    writer = std::move(store::ResultsWriter::open_for_resume(out, study.sha256, so).writer);
  } else {
    all.done.assign(total, 0);
    for (std::size_t c = 0; c < schema.columns.size(); ++c) all.columns.emplace_back(total, schema.blank.cells[c]);
    writer = store::ResultsWriter::create(out, meta_of(study), schema.columns, static_cast<std::int64_t>(total), so);
  }
  all.done.resize(total, 0);

  const std::vector<std::string> shards = find_shards(out);
  std::vector<std::unique_ptr<store::ResultsReader>> readers;
  std::vector<std::int32_t> owner(total, -1);
  for (std::size_t s = 0; s < shards.size(); ++s) {
    auto r = std::make_unique<store::ResultsReader>(shards[s]);
    if (r->meta().study_sha256 != study.sha256 || r->n_runs() != static_cast<std::int64_t>(total))
      throw store::StoreError(shards[s], "shard of another study");
    const auto mask = r->done_mask();
    std::vector<std::uint64_t> ids;
    for (std::uint64_t id = 0; id < total && id < mask.size(); ++id)
      if (mask[id] && !all.done[id]) ids.push_back(id);
    if (!ids.empty()) {
      for (std::size_t c = 0; c < schema.columns.size(); ++c) {
        std::vector<Cell> col = r->read_column(schema.columns[c].name);
        for (std::uint64_t id : ids) all.columns[c][id] = std::move(col[id]);
      }
      for (std::uint64_t id : ids) all.done[id] = 1, owner[id] = static_cast<std::int32_t>(s);
    }
    readers.push_back(std::move(r));
  }
  const std::uint64_t missing = static_cast<std::uint64_t>(std::count(all.done.begin(), all.done.end(), 0));
  if (missing)
    throw store::StoreError(out, std::to_string(missing) + " runs are in neither the results file nor a shard");

  // Copy the shards' runs in run-id order (the single-process write order): histories are read
  // serially, re-encoded in parallel (shards hold them raw), written serially.
  const int level = run.options.compression;
  tbb::task_arena arena(threads);
  std::vector<std::uint64_t> ids;
  for (std::uint64_t id = 0; id < total; ++id)
    if (owner[id] >= 0) ids.push_back(id);
  const std::size_t chunk = 64 * static_cast<std::size_t>(threads);
  std::vector<RunHistory> raw(chunk);
  std::vector<store::EncodedHistory> enc(chunk);
  for (std::size_t at = 0; at < ids.size(); at += chunk) {
    const std::size_t n = std::min(chunk, ids.size() - at);
    for (std::size_t i = 0; i < n; ++i) {
      const auto& r = *readers[owner[ids[at + i]]];
      const auto id = static_cast<std::int64_t>(ids[at + i]);
      raw[i] = r.has_history(id) ? r.read_history(id) : RunHistory{};
    }
    arena.execute([&] {
      tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
        enc[i] = raw[i].arrays.empty() ? store::EncodedHistory{} : store::encode_history(raw[i], level);
      });
    });
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint64_t id = ids[at + i];
      Record row;
      row.cells.reserve(all.columns.size());
      for (const auto& col : all.columns) row.cells.push_back(col[id]);
      writer->write_run(static_cast<std::int64_t>(id), row, enc[i]);
      raw[i] = {};
      enc[i] = {};
    }
  }
  writer->flush();
  readers.clear();

  SweepOptions o;
  o.threads = threads;
  o.histories = run.options.histories;
  o.compression = level;
  SweepReport report = run_sweep(study, schema, *writer, o, &all);
  writer->close();
  for (const auto& s : shards) remove_results_file(s);
  return report;
}

}  // namespace

bool launched_under_mpi() {
  return env_set("OMPI_COMM_WORLD_SIZE") || env_set("PMIX_RANK") || env_set("PMI_RANK") || env_set("PMI_SIZE") ||
         env_set("MPI_LOCALNRANKS");
}

std::string shard_path(const std::string& output, int rank) { return output + ".rank" + std::to_string(rank) + ".h5"; }

int run_distributed(const Study& study, const StudySchema& schema, const DistributedRun& run, std::ostream& out,
                    std::ostream& err) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_MULTIPLE, &provided);
  MPI_Comm comm;
  MPI_Comm_dup(MPI_COMM_WORLD, &comm);
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  auto finish = [&](int code) {
    MPI_Comm_free(&comm);
    MPI_Finalize();
    return code;
  };
  auto fail = [&](const std::string& what) { err << "kinesweep run [rank " << rank << "]: " << what << '\n' << std::flush; };
  if (provided < MPI_THREAD_SERIALIZED) {
    if (rank == 0) fail("the MPI library does not support MPI_THREAD_SERIALIZED");
    return finish(1);
  }
  const auto start = Clock::now();
  const std::uint64_t total = study.run_count();

  // Threads per rank: as asked; else the cores this rank is bound to, or (unbound) the node's cores
  // shared between the ranks on the node.
  int threads = run.options.threads;
  {
    MPI_Comm node;
    MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &node);
    int node_ranks = 1;
    MPI_Comm_size(node, &node_ranks);
    MPI_Comm_free(&node);
    if (threads <= 0) {
      const int allowed = tbb::info::default_concurrency();
      const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
      threads = allowed < cores ? allowed : std::max(1, cores / node_ranks);
    }
  }

  // 1. Rank 0 checks the files and collects the done set; everybody learns it.
  int code = 0;
  std::vector<std::uint8_t> done(total, 0);
  if (rank == 0) {
    std::string msg;
    try {
      code = prepare(study, run, done, msg);
    } catch (const store::StoreError& e) {
      code = 1, msg = e.what();
    } catch (const fs::filesystem_error& e) {
      code = 1, msg = e.what();
    }
    if (code) fail(msg);
  }
  MPI_Bcast(&code, 1, MPI_INT, 0, comm);
  if (code) return finish(code);
  bcast_bytes(done, comm);

  // 2. Every rank opens its shard (reopens it when resuming).
  std::unique_ptr<store::ResultsWriter> shard;
  int local = 0;
  try {
    // Shards commit every 512 runs or 2 s (single process: 64 runs or 10 s): commits are the
    // writer's main cost, and a killed rank loses at most that much.
    store::StoreOptions so;
    so.flush_every_runs = 512;
    so.flush_every_seconds = 2.0;
    const std::string sp = shard_path(run.output, rank);
    if (fs::exists(sp))
      shard = std::move(store::ResultsWriter::open_for_resume(sp, study.sha256, so).writer);
    else
      shard = store::ResultsWriter::create(sp, meta_of(study), schema.columns, static_cast<std::int64_t>(total), so);
  } catch (const store::StoreError& e) {
    fail(e.what());
    local = 1;
  }
  MPI_Allreduce(MPI_IN_PLACE, &local, 1, MPI_INT, MPI_MAX, comm);
  if (local) return finish(1);

  // 3. The sweep: rank 0 coordinates (a thread) and computes; the others compute what it hands out.
  std::vector<std::uint64_t> todo;
  for (std::uint64_t id = 0; id < total; ++id)
    if (!done[id]) todo.push_back(id);
  const std::uint64_t todo_n = todo.size();
  std::vector<std::uint8_t>().swap(done);
  SweepOptions o = run.options;
  o.threads = threads;
  o.compression = 0;  // shards hold raw histories; the merge compresses them once, in parallel
  o.source_runs = todo_n;
  std::unique_ptr<WorkPool> pool;
  std::unique_ptr<RemoteSource> remote;
  std::vector<std::atomic<std::uint64_t>> remote_done(size);
  std::thread coordinator;
  if (rank == 0) {
    pool = std::make_unique<WorkPool>(std::move(todo), size);
    o.source = [&](std::vector<std::uint64_t>& ids, std::size_t max) {
      ids = pool->take(max);
      return !ids.empty();
    };
    o.on_progress = [&](const SweepProgress& p) {
      std::uint64_t all = p.done;
      for (int r = 1; r < size; ++r) all += remote_done[r].load();
      if (run.options.on_progress && !run.quiet)
        run.options.on_progress({std::min(all, todo_n), todo_n, p.elapsed_s});
    };
    if (size > 1) coordinator = std::thread([&] { coordinate(comm, size, o.batch, *pool, remote_done, o.stop); });
  } else {
    remote = std::make_unique<RemoteSource>(comm, threads, o.batch);
    o.source = [&](std::vector<std::uint64_t>& ids, std::size_t max) { return remote->next(ids, max); };
    o.on_progress = [&](const SweepProgress& p) { remote->written.store(p.done); };
  }
  SweepReport report;
  int status = 0;  // 0 done, 1 failed, 130 interrupted
  try {
    report = run_sweep(study, schema, *shard, o, nullptr);
    if (report.interrupted) status = 130;
    shard->close();
  } catch (const store::StoreError& e) {
    fail(e.what());
    status = 1;
  }
  if (pool && status) pool->halt();
  if (remote) remote->finish();
  if (coordinator.joinable()) coordinator.join();
  shard.reset();
  const double sweep_s = std::chrono::duration<double>(Clock::now() - start).count();

  int failed = status == 1, interrupted = status == 130;
  unsigned long long written = report.written;
  MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPI_INT, MPI_MAX, comm);
  MPI_Allreduce(MPI_IN_PLACE, &interrupted, 1, MPI_INT, MPI_MAX, comm);
  MPI_Allreduce(MPI_IN_PLACE, &written, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, comm);
  if (failed || interrupted) {
    if (rank == 0) {
      out << (failed ? "failed" : "interrupted") << ": " << written << " runs computed now are kept in the shards "
          << shard_path(run.output, 0) << " ...\nresume with: mpirun -np " << size << " kinesweep run " << run.study_arg
          << " -o " << run.output << " --resume\n"
          << std::flush;
    }
    return finish(failed ? 1 : 130);
  }
  if (rank == 0 && run.options.on_progress && !run.quiet) run.options.on_progress({todo_n, todo_n, sweep_s});

  // 4. Rank 0 merges; the others wait for its verdict.
  code = 0;
  if (rank == 0) {
    try {
      const auto t0 = Clock::now();
      SweepReport final_report = merge(study, schema, run, threads);
      const double merge_s = std::chrono::duration<double>(Clock::now() - t0).count();
      final_report.written = written;
      final_report.skipped = total - std::min<std::uint64_t>(total, written);
      final_report.elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
      char line[256];
      std::snprintf(line, sizeof line, "distributed: %d ranks x %d threads; sweep %.2f s, merge %.2f s\n", size,
                    threads, sweep_s, merge_s);
      out << line;
      print_report(out, study, final_report);
      out << "results: " << run.output << '\n' << std::flush;
    } catch (const store::StoreError& e) {
      fail(std::string(e.what()) + " (the shards are kept: run again with --resume)");
      code = 1;
    } catch (const fs::filesystem_error& e) {
      fail(e.what());
      code = 1;
    }
  }
  {  // the other ranks wait for the merge without spinning a core (a blocking MPI_Bcast would)
    MPI_Request r;
    MPI_Ibcast(&code, 1, MPI_INT, 0, comm, &r);
    wait_gently(r, MPI_STATUS_IGNORE);
  }
  return finish(code);
}

}  // namespace ks
