#pragma once
// The run ids of a distributed sweep (internal to engine/runner): rank 0 holds the ids still to do
// and hands them out in chunks that shrink as the work runs out (guided scheduling), answering
// requests from a coordinator thread; every other rank fills its pipeline from a RemoteSource that
// asks one chunk ahead. MPI threading: the coordinator thread and the workers' pipeline source stage
// are the only callers of MPI during the sweep, never concurrently within one process.
#include <mpi.h>

#include <atomic>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

namespace ks::mpi {

inline constexpr int kTagRequest = 0x6b73;
inline constexpr int kTagReply = 0x6b74;
inline constexpr std::uint64_t kMaxChunk = 1024;  ///< largest chunk of run ids handed out at once

/// Wait for a request without spinning a core (Open MPI's blocking waits busy-poll; the cores
/// belong to the TBB workers).
void wait_gently(MPI_Request& request, MPI_Status* status);
/// MPI_Bcast of a byte vector of any size (in slices of 1 GiB) from rank 0.
void bcast_bytes(std::vector<std::uint8_t>& v, MPI_Comm comm);
/// MPI_Bcast from rank 0 of a bit vector (its size included), packed 8 bits per byte.
void bcast_bits(std::vector<bool>& v, MPI_Comm comm);
/// MPI_Bcast from rank 0 of a string (its size included).
void bcast_string(std::string& s, MPI_Comm comm);

/// The run ids not done yet (rank 0), handed out by regions: each rank draws consecutive ids from a
/// region of `region` ids of its own (the /runs chunk of the results file, so that most chunks of a
/// shard are whole and the merge copies them without decoding); a rank whose region is spent gets
/// the next unassigned one, and once none is left it takes the upper half of the largest remaining
/// range of another rank (the tail stays balanced). Holds one bit per run.
class WorkPool {
 public:
  WorkPool(std::vector<bool> done, int ranks, std::uint64_t region);
  /// The number of ids not handed out yet.
  std::uint64_t remaining() const { return remaining_; }
  /// Up to `max` ids for rank 0's own pipeline.
  std::vector<std::uint64_t> take(std::size_t max) {
    std::lock_guard<std::mutex> lock(m_);
    return slice_locked(0, max);
  }
  /// A chunk for remote rank `rank` with `threads` threads: guided (remaining / 4 ranks), at least
  /// two rounds of its pipeline, at most kMaxChunk.
  std::vector<std::uint64_t> take_chunk(int rank, std::uint64_t threads, std::size_t batch) {
    std::lock_guard<std::mutex> lock(m_);
    const std::uint64_t lo = std::max<std::uint64_t>(1, 2 * threads * batch);
    const std::uint64_t n = std::min(kMaxChunk, std::max(lo, remaining_ / (4 * static_cast<std::uint64_t>(ranks_))));
    return slice_locked(rank, n);
  }
  void halt() {
    std::lock_guard<std::mutex> lock(m_);
    halted_ = true;
  }

 private:
  struct Range {
    std::uint64_t next = 0, end = 0;  ///< ids [next, end) not handed out yet
  };
  std::vector<std::uint64_t> slice_locked(int rank, std::size_t n);
  bool refill_locked(int rank);  ///< a new range for `rank`; false when no id is left anywhere
  std::mutex m_;
  std::vector<bool> done_;
  std::vector<Range> ranges_;  ///< per rank
  std::uint64_t region_, next_region_ = 0, remaining_ = 0;
  int ranks_;
  bool halted_ = false;
};

/// Rank 0's coordinator thread: answers chunk requests until every other rank has retired (got an
/// empty chunk or said it quits). Request: {quit, runs written so far, threads}.
void coordinate(MPI_Comm comm, int size, std::size_t batch, WorkPool& pool,
                std::vector<std::atomic<std::uint64_t>>& remote_done, const std::atomic<bool>* stop);

/// A worker rank's SweepOptions::source: a local queue refilled from rank 0, one request ahead.
class RemoteSource {
 public:
  RemoteSource(MPI_Comm comm, int threads, std::size_t batch)
      : comm_(comm), threads_(threads), low_water_(2 * static_cast<std::size_t>(threads) * batch), reply_(kMaxChunk) {}
  /// Up to `max` ids; false when the work is finished.
  bool next(std::vector<std::uint64_t>& ids, std::size_t max);
  /// After the sweep (finished, interrupted or failed): settle the protocol with rank 0.
  void finish();
  std::atomic<std::uint64_t> written{0};

 private:
  void request();
  void poll(bool wait);

  MPI_Comm comm_;
  int threads_;
  std::size_t low_water_;
  std::vector<std::uint64_t> reply_;
  std::deque<std::uint64_t> queue_;
  MPI_Request pending_ = MPI_REQUEST_NULL;
  bool outstanding_ = false, finished_ = false, retired_ = false;
};

}  // namespace ks::mpi
