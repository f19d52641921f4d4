#pragma once
// Internal to the store: the on-disk layout of the ksjournal redo journal (FORMAT.md, "Crash safety"),
// the file I/O that reads, resets and replays it, the check that a journal belongs to the file as it
// is, and the writer lock. Shared by the driver (journal_vfd.cpp) and the readers' functions
// (journal_format.cpp, journal_lock.cpp). Only store/*.cpp include it.
#include <sys/types.h>

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace ks::store::detail::journal {

inline constexpr std::uint64_t kPage = 4096;
/// Version 2 header (written now): version 1 fields + the committed state's fingerprint.
inline constexpr char kHeadMagic[8] = {'K', 'S', 'J', 'R', 'N', 'L', '0', '2'};
/// Version 1 header (kinesweep before the fingerprint): still recognised when found after a crash.
inline constexpr char kHeadMagicV1[8] = {'K', 'S', 'J', 'R', 'N', 'L', '0', '1'};
inline constexpr char kTailMagic[8] = {'K', 'S', 'J', 'C', 'M', 'T', '0', '1'};
inline constexpr std::size_t kHeadSizeV1 = 48;  // magic, dev, ino, committed size, commit sequence, session id
inline constexpr std::size_t kHeadSize = 56;    // ... + crc32 of the first and of the last committed page
inline constexpr std::uint64_t kMinCommittedSize = 48;  // bytes of an HDF5 superblock v2: no results file is smaller
inline constexpr std::size_t kTailSize = 32;    // magic, n records, new size, crc32 (+4 pad)

/// Records the driver's last error (journal_last_error() returns it); err: an errno value or 0.
void set_error(const std::string& what, int err);

/// pwrite of all n bytes at off (retries on EINTR). False on error (errno set).
bool write_all(int fd, const void* buf, std::size_t n, std::uint64_t off);
/// Reads n bytes at off; bytes past end of file read as zero.
bool read_all(int fd, void* buf, std::size_t n, std::uint64_t off);
void put64(unsigned char* p, std::uint64_t v);
std::uint64_t get64(const unsigned char* p);

/// What identifies a committed state of the results file: its size and the CRC-32 of its first
/// page [0, min(4096, size)) and of its last page [4096*floor((size-1)/4096), size). Page 0 holds
/// the superblock (its end-of-file address changes whenever the file grows) and the root group's
/// object header, and a change of size moves the last page, so a file changed by another program
/// after its writer stopped (appended to, a copy put over it, page 0 rewritten) no longer matches.
struct Fingerprint {
  std::uint64_t size = 0;
  std::uint32_t crc_first = 0, crc_last = 0;
};
/// The fingerprint of the first `size` bytes of fd. False on I/O error.
bool fingerprint(int fd, std::uint64_t size, Fingerprint* out);
/// The page ranges fingerprint() covers for a file of `size` bytes: {offset, length} x 2.
std::pair<std::uint64_t, std::uint64_t> first_page_range(std::uint64_t size);
std::pair<std::uint64_t, std::uint64_t> last_page_range(std::uint64_t size);

/// Writes a fresh header (identity dev/ino, the fingerprint of fd's first `committed` bytes) and
/// drops the records.
bool reset_journal(int jfd, int fd, std::uint64_t dev, std::uint64_t ino, std::uint64_t committed,
                   std::uint64_t seq, std::uint64_t session);

struct Parsed {
  int version = 0;          // 0: no (valid) header; 1 or 2
  std::uint64_t dev = 0, ino = 0;
  std::uint64_t committed = 0;
  std::uint32_t crc_first = 0, crc_last = 0;  // version 2 only
  bool commit_ok = false;   // a complete trailer with matching checksum
  std::uint64_t new_size = 0;
  std::vector<std::pair<std::uint64_t, std::vector<unsigned char>>> records;
};
/// The journal's header and, when a complete checksummed trailer follows them, its records.
Parsed parse_journal(int jfd);

/// Empty when journal `p` (with a valid header, dev/ino equal to the file's) belongs to the data
/// file fd as it is now: without a commit, the file's first p.committed bytes still have the
/// header's fingerprint (bytes appended after it are the dead writer's); with a complete commit, the
/// file has the commit's new size and each fingerprinted page is either as before the commit or as
/// the commit writes it (the writer may have died while applying). Otherwise a one-line description
/// of the difference. Version 1 journals carry no fingerprint: their sizes alone are checked.
std::string mismatch(const Parsed& p, int fd);

/// What a writer's open does with journal `jfd` of the data file fd (identity dev/ino), decided
/// without writing: nothing (the journal holds nothing of the file as it is: empty, cut within its
/// header, another file's without a commit, or committing the file's present size), recover (replay
/// a commit, or drop the bytes appended after the last one) or refuse (*why says what was found, or
/// is empty after an I/O error). A version 1 journal of this file is refused: without a fingerprint
/// nothing shows that it belongs to the file as it is (its committed size alone may cut a finished
/// file).
enum class Plan { nothing, recover, refuse };
Plan recovery_plan(int fd, int jfd, std::uint64_t dev, std::uint64_t ino, std::string* why);

/// With the journal locked: bring the data file to its last committed state (replay a commit, or
/// drop the bytes appended after the last one) when the journal belongs to it. Returns false on an
/// I/O error or when the journal does not belong to the file (then nothing was written; *why says
/// what was found).
bool recover_locked(int fd, int jfd, std::uint64_t dev, std::uint64_t ino, std::string* why);

/// The writer's open sequence, as steps a test can stop at: KS_STORE_TEST_PAUSE=<step> makes the
/// process stop itself (SIGSTOP) there, so that a test can run readers and other writers at that
/// exact point and then let it continue (SIGCONT). Steps, in order: "data_opened", then either
/// "journal_opened" and "journal_locked" (a journal exists: a crashed writer's, or a live one's) or
/// "journal_created", "journal_created_locked" and "journal_linked" (none exists), then "recovered"
/// and "ready".
void pause_point(const char* step);

/// Takes the writer lock of a results file: the flock of its journal `jp`, taken before the journal
/// is visible under that name (it is created under a temporary name, locked, given a header by
/// `init`, then hard-linked into place) or, for a journal left by a crashed writer, taken on the
/// file the name still points to after locking. Returns the locked journal's fd, or -1 with
/// set_error() (another writer holds it: "is being written by another process").
int acquire_lock(const std::string& jp, const std::function<bool(int jfd)>& init);

/// Removes the temporary files a killed process left beside `name` (a path): `.<base>.tmp-PID-N`
/// (a results file being created) and `<base>.new-PID-N` (a journal being created), where <base> is
/// the file name of `name` and process PID no longer exists on this machine. A live process's
/// temporary files are never touched. Errors are ignored (the files are only clutter).
void remove_orphans(const std::string& name);

}  // namespace ks::store::detail::journal

// What readers and writers ask of a results file's journal, answered from the journal's format
// (format.cpp), without the driver.
namespace ks::store::detail {

/// Path of the journal file that belongs to `results_path`.
std::string journal_path(const std::string& results_path);

/// How a reader opens a results file. Readers never lock, replay, truncate or delete anything.
struct ReadView {
  enum Kind {
    plain,    ///< no journal, or no commit waiting in it: the file's own bytes are its committed state
    overlay,  ///< a complete commit waits in the journal and belongs to this file: make_journal_read_fapl()
    refuse,   ///< a complete commit waits in a journal that does not match the file as it is now (why)
  } kind = plain;
  std::string why;
};
ReadView read_view(const std::string& results_path);

/// True when the journal holds a complete commit for this file, not yet applied (read_view() is not
/// plain): the file must then not be read as it is on disk.
bool journal_has_pending_commit(const std::string& results_path);

/// True when a journal lies beside `results_path` and a writer's open would act on it: recover the
/// file from it, or refuse the file because of it (journal::recovery_plan). False when there is no
/// journal or it holds nothing of the file as it is. Read-only: nothing is locked or written.
bool journal_acts_on_open(const std::string& results_path);

/// A token that changes whenever the committed state of the file may have changed: while a journal
/// exists, its header (commit sequence, writer-session id), its size and its last bytes (records
/// being written or applied change them); else the file's size and mtime. Empty when the file does
/// not exist. Two equal, non-empty stamps taken before and after a read mean the read saw one
/// committed state.
std::string consistency_stamp(const std::string& results_path);

/// Last error text from the driver (open failures), for StoreError messages.
std::string journal_last_error();

}  // namespace ks::store::detail
