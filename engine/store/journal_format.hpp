#pragma once
// Internal to the store: the on-disk layout of the ksjournal redo journal (FORMAT.md, "Crash safety")
// and the file I/O that reads, resets and replays it. Shared by the driver (journal_vfd.cpp) and the
// recovery / consistency functions (journal_format.cpp). Only store/*.cpp include it.
#include <sys/types.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace ks::store::detail::journal {

inline constexpr std::uint64_t kPage = 4096;
inline constexpr char kHeadMagic[8] = {'K', 'S', 'J', 'R', 'N', 'L', '0', '1'};
inline constexpr char kTailMagic[8] = {'K', 'S', 'J', 'C', 'M', 'T', '0', '1'};
inline constexpr std::size_t kHeadSize = 48;  // magic, dev, ino, committed size, commit sequence, session id
inline constexpr std::size_t kTailSize = 32;  // magic, n records, new size, crc32 (+4 pad)

/// Records the driver's last error (journal_last_error() returns it); err: an errno value or 0.
void set_error(const std::string& what, int err);

/// pwrite of all n bytes at off (retries on EINTR). False on error (errno set).
bool write_all(int fd, const void* buf, std::size_t n, std::uint64_t off);
/// Reads n bytes at off; bytes past end of file read as zero.
bool read_all(int fd, void* buf, std::size_t n, std::uint64_t off);
void put64(unsigned char* p, std::uint64_t v);
std::uint64_t get64(const unsigned char* p);

std::vector<unsigned char> make_header(std::uint64_t dev, std::uint64_t ino, std::uint64_t committed,
                                       std::uint64_t seq, std::uint64_t session);
/// Writes a fresh header and drops the records.
bool reset_journal(int jfd, std::uint64_t dev, std::uint64_t ino, std::uint64_t committed, std::uint64_t seq,
                   std::uint64_t session);

struct Parsed {
  bool header_ok = false;   // magic and file identity match
  std::uint64_t committed = 0;
  bool commit_ok = false;   // a complete trailer with matching checksum
  std::uint64_t new_size = 0;
  std::vector<std::pair<std::uint64_t, std::vector<unsigned char>>> records;
};
/// The journal's header and, when a complete checksummed trailer follows them, its records.
Parsed parse_journal(int jfd, std::uint64_t dev, std::uint64_t ino);

/// With the journal locked: bring the data file to its last committed state. Returns false on I/O error.
bool recover_locked(int fd, int jfd, std::uint64_t dev, std::uint64_t ino, bool* replayed);

}  // namespace ks::store::detail::journal
