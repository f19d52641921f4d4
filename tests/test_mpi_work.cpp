// The work pool of distributed sweeps (runner/mpi_work.hpp), without MPI calls: every id not done
// is handed out exactly once, each rank's ids come in consecutive runs from regions of its own, and
// only the regions still being drawn when none was left unassigned are shared (so that most /runs
// chunks of a shard are whole and the merge copies them as stored).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <set>
#include <vector>

#include "runner/mpi_work.hpp"

namespace {
using ks::mpi::WorkPool;

struct Drawn {
  std::vector<int> owner;  // per id: the rank it went to, -1 none
  int takes = 0;
};

/// Ranks ask in turn (rank 0 through take, the others through take_chunk) until the pool is empty.
Drawn draw_all(const std::vector<bool>& done, int ranks, std::uint64_t region, std::size_t batch) {
  WorkPool pool(done, ranks, region);
  Drawn d;
  d.owner.assign(done.size(), -1);
  std::vector<bool> finished(static_cast<std::size_t>(ranks), false);
  for (int turn = 0; std::count(finished.begin(), finished.end(), true) < ranks; ++turn) {
    const int r = turn % ranks;
    if (finished[static_cast<std::size_t>(r)]) continue;
    const std::vector<std::uint64_t> ids = r == 0 ? pool.take(2 * batch) : pool.take_chunk(r, 1, batch);
    if (ids.empty()) finished[static_cast<std::size_t>(r)] = true;
    for (std::uint64_t id : ids) {
      EXPECT_FALSE(done[id]) << "id " << id << " was done";
      EXPECT_EQ(d.owner[id], -1) << "id " << id << " handed out twice";
      d.owner[id] = r;
    }
    ++d.takes;
  }
  EXPECT_EQ(pool.remaining(), 0u);
  return d;
}

TEST(WorkPool, EveryIdOnceAndRegionsWholeButTheTail) {
  for (int ranks : {1, 2, 3, 5}) {
    for (std::uint64_t region : {1u, 16u, 100u}) {
      const std::size_t n = 1000;
      std::vector<bool> done(n, false);
      for (std::size_t i = 0; i < n; i += 7) done[i] = true;  // a resumed study
      const Drawn d = draw_all(done, ranks, region, 4);
      std::size_t shared = 0;
      for (std::size_t lo = 0; lo < n; lo += region) {
        std::set<int> owners;
        for (std::size_t id = lo; id < std::min<std::size_t>(n, lo + region); ++id) {
          EXPECT_EQ(d.owner[id] == -1, done[id]) << "id " << id;
          if (!done[id]) owners.insert(d.owner[id]);
        }
        shared += owners.size() > 1;
      }
      // only the regions that were being drawn when the last one was assigned can be split
      EXPECT_LE(shared, static_cast<std::size_t>(ranks)) << ranks << " ranks, region " << region;
    }
  }
}

TEST(WorkPool, TheTailIsShared) {
  // One region of 10000 ids and two ranks: the second rank takes the upper half of the first's
  // range (and halves again as they run out), so neither computes the study alone.
  const Drawn d = draw_all(std::vector<bool>(10000, false), 2, 1u << 20, 8);
  const auto by0 = std::count(d.owner.begin(), d.owner.end(), 0), by1 = std::count(d.owner.begin(), d.owner.end(), 1);
  EXPECT_EQ(by0 + by1, 10000);
  EXPECT_GT(by0, 100);
  EXPECT_GT(by1, 1000);
}

TEST(WorkPool, HaltedPoolHandsOutNothing) {
  WorkPool pool(std::vector<bool>(100, false), 2, 16);
  EXPECT_EQ(pool.take(10).size(), 10u);
  pool.halt();
  EXPECT_TRUE(pool.take(10).empty());
  EXPECT_TRUE(pool.take_chunk(1, 1, 4).empty());
}

}  // namespace
