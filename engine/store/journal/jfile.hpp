#pragma once
// Internal: a file open under the "ksjournal" driver (vfd.cpp) and its commit (commit.cpp). Only
// store/journal/*.cpp.
#include <hdf5.h>

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "store/journal/pages.hpp"

namespace ks::store::detail::journal {

struct JFile {
  H5FD_t pub;  // must be first
  int fd = -1, jfd = -1;
  std::uint64_t dev = 0, ino = 0;
  haddr_t eoa = 0;
  std::uint64_t eof = 0;        // physical size
  std::uint64_t committed = 0;  // physical size at the last commit
  std::uint64_t seq = 0, session = 0;  // commits in this session; random id of this writer session
  bool durable = false;
  bool poisoned = false;        // an I/O error happened: never commit again (the journal stays)
  bool abandoned = false;       // the writer gave up (abandon_journal_file): flushes and close commit nothing
  bool readonly = false;        // a reader's overlay of an unapplied commit (open_overlay): no journal
  std::string path;
  std::map<std::uint64_t, unsigned char*> pages;  // page number -> kPage bytes of page_pool
  PagePool page_pool;
  // Small writes past the committed size (new chunks, mostly) that continue one another, gathered
  // into one pwrite of up to kGather bytes: a sweep with short histories writes several small
  // chunks per run. Writes of kDirect bytes or more go straight to the file (no extra copy).
  static constexpr std::size_t kGather = std::size_t{1} << 20, kDirect = std::size_t{16} << 10;
  std::vector<unsigned char> gathered;
  std::uint64_t gathered_at = 0;
  // Test hook (crash-safety tests only): KS_STORE_TEST_CRASH="<n>:<phase>" makes the process
  // _exit(86) during its n-th commit, phase = journal_half | journal_done | apply_half.
  long crash_commit = -1, commits = 0;
  std::string crash_phase;
};

/// Writes the gathered bytes; false (errno set) on an I/O error.
bool write_gathered(JFile* f);

/// Writes [a, a + n) past the committed size: appended to the gathered bytes when it continues them
/// and fits, else after writing those (directly when n >= kDirect).
bool write_past_committed(JFile* f, const unsigned char* in, std::size_t n, std::uint64_t a);

/// Commits the overlay and the appended bytes: the commit record to the journal, then the pages to
/// the file, then the journal reset (see vfd.cpp's header). False, and the file poisoned (never
/// committed again), on an I/O error.
bool commit(JFile* f);

}  // namespace ks::store::detail::journal
