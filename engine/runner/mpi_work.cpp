// The run-id source of distributed sweeps (see mpi_work.hpp).
#include "runner/mpi_work.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

namespace ks::mpi {

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

void bcast_bits(std::vector<bool>& v, MPI_Comm comm) {
  std::uint64_t n = v.size();
  MPI_Bcast(&n, 1, MPI_UINT64_T, 0, comm);
  std::vector<std::uint8_t> packed((n + 7) / 8, 0);
  for (std::uint64_t i = 0; i < v.size(); ++i)
    if (v[i]) packed[i / 8] |= static_cast<std::uint8_t>(1u << (i % 8));
  bcast_bytes(packed, comm);
  v.assign(n, false);
  for (std::uint64_t i = 0; i < n; ++i) v[i] = (packed[i / 8] >> (i % 8)) & 1u;
}

void bcast_string(std::string& s, MPI_Comm comm) {
  std::uint64_t n = s.size();
  MPI_Bcast(&n, 1, MPI_UINT64_T, 0, comm);
  std::vector<std::uint8_t> bytes(s.begin(), s.end());
  bytes.resize(n);
  bcast_bytes(bytes, comm);
  s.assign(bytes.begin(), bytes.end());
}

WorkPool::WorkPool(std::vector<bool> done, int ranks, std::uint64_t region)
    : done_(std::move(done)), ranges_(static_cast<std::size_t>(std::max(1, ranks))),
      region_(std::max<std::uint64_t>(1, region)), ranks_(std::max(1, ranks)) {
  for (bool d : done_) remaining_ += d ? 0 : 1;
}

bool WorkPool::refill_locked(int rank) {
  Range& mine = ranges_[static_cast<std::size_t>(rank)];
  const std::uint64_t total = done_.size();
  if (next_region_ < total) {
    mine = {next_region_, std::min(total, next_region_ + region_)};
    next_region_ = mine.end;
    return true;
  }
  // No region left: the upper half of the largest range another rank has not drawn yet.
  Range* victim = nullptr;
  for (Range& r : ranges_)
    if (&r != &mine && r.end > r.next && (!victim || r.end - r.next > victim->end - victim->next)) victim = &r;
  if (!victim) return false;
  const std::uint64_t mid = victim->next + (victim->end - victim->next) / 2;
  mine = {mid, victim->end};
  victim->end = mid;
  return true;
}

std::vector<std::uint64_t> WorkPool::slice_locked(int rank, std::size_t n) {
  std::vector<std::uint64_t> ids;
  if (halted_) return ids;
  n = static_cast<std::size_t>(std::min<std::uint64_t>(n, remaining_));
  ids.reserve(n);
  Range& mine = ranges_[static_cast<std::size_t>(rank)];
  while (ids.size() < n) {
    if (mine.next == mine.end && !refill_locked(rank)) break;
    for (; mine.next < mine.end && ids.size() < n; ++mine.next)
      if (!done_[mine.next]) ids.push_back(mine.next);
  }
  remaining_ -= ids.size();
  return ids;
}

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
    if (!(stop && stop->load())) ids = pool.take_chunk(src, req[2], batch);
    MPI_Send(ids.data(), static_cast<int>(ids.size()), MPI_UINT64_T, src, kTagReply, comm);
    if (ids.empty()) retired[src] = 1, --active;
  }
}

// RemoteSource
bool RemoteSource::next(std::vector<std::uint64_t>& ids, std::size_t max) {
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

void RemoteSource::finish() {
  if (outstanding_) poll(true);
  if (!retired_) {
    std::uint64_t req[3] = {1, written.load(), static_cast<std::uint64_t>(threads_)};
    MPI_Send(req, 3, MPI_UINT64_T, 0, kTagRequest, comm_);
    retired_ = true;
  }
}

void RemoteSource::request() {
  MPI_Irecv(reply_.data(), static_cast<int>(reply_.size()), MPI_UINT64_T, 0, kTagReply, comm_, &pending_);
  std::uint64_t req[3] = {0, written.load(), static_cast<std::uint64_t>(threads_)};
  MPI_Send(req, 3, MPI_UINT64_T, 0, kTagRequest, comm_);
  outstanding_ = true;
}

void RemoteSource::poll(bool wait) {
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

}  // namespace ks::mpi
