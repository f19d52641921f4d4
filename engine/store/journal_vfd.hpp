#pragma once
// Internal to the store: an HDF5 virtual file driver ("ksjournal") that makes every H5Fflush an
// atomic commit of the file, so that a kill -9 at any moment leaves the last committed state.
// See FORMAT.md, "Crash safety". Only the writer thread uses it; only store/*.cpp include it.
#include <hdf5.h>

#include <cstdint>
#include <string>

namespace ks::store::detail {

/// The driver id (registered on first use). Files opened with it must already exist (H5Fopen RDWR).
hid_t journal_driver_id();
/// A file-access property list using the driver; `durable` adds fsync()s around each commit
/// (needed only against power loss, not against a killed process).
hid_t make_journal_fapl(bool durable);

/// Path of the journal file that belongs to `results_path`.
std::string journal_path(const std::string& results_path);

enum class RecoverOutcome {
  no_journal,        ///< nothing to do
  writer_alive,      ///< another process holds the journal lock: a live writer; nothing touched
  clean,             ///< journal present but had nothing to replay (stale or uncommitted epoch discarded)
  replayed,          ///< a committed-but-unapplied journal was replayed into the file
  not_permitted,     ///< the data file or journal could not be opened for writing
};
/// Bring a results file to its last committed state after a crash (kill -9 of a writer):
/// replays a committed journal, or drops bytes appended after the last commit. Safe to call at any
/// time; it does nothing while a writer is alive. Removes the journal when done.
RecoverOutcome recover(const std::string& results_path);

/// True when the journal holds a complete, not-yet-applied commit (the only state in which the
/// results file itself must not be read without recover() first). Test/diagnostic helper.
bool journal_has_pending_commit(const std::string& results_path);

/// A token that changes whenever the committed state of the file may have changed: the journal
/// header (which carries a commit sequence number and a writer-session id) while a writer lives,
/// else the file's size and mtime. Empty while a commit is being applied. Two equal, non-empty
/// stamps taken before and after a read mean the read saw one committed state.
std::string consistency_stamp(const std::string& results_path);

/// Last error text from the driver (open failures), for StoreError messages.
std::string journal_last_error();

}  // namespace ks::store::detail
