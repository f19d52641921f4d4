#pragma once
// Internal to the store: an HDF5 virtual file driver ("ksjournal") that makes every H5Fflush an
// atomic commit of the file, so that a kill -9 at any moment leaves the last committed state.
// See FORMAT.md, "Crash safety". Writers open with make_journal_fapl() (and recover a crashed
// writer's file first); readers use make_journal_read_fapl() only for a commit left unapplied.
// Only store/*.cpp include it.
#include <hdf5.h>

#include <cstdint>
#include <string>

namespace ks::store::detail {

/// The driver id (registered on first use). Files opened with it must already exist.
hid_t journal_driver_id();
/// A file-access property list using the driver; `durable` adds fsync()s around each commit
/// (needed only against power loss, not against a killed process).
hid_t make_journal_fapl(bool durable);

/// The writer of the open file `file` gave up: its journal driver commits nothing more (flushes do
/// nothing) and its close succeeds leaving the file in its last committed state, with its journal
/// (the next writer recovers it). Nothing for a file of another driver.
void abandon_journal_file(hid_t file);

/// The open file `file` (of this driver) was renamed to `new_path`, its journal to
/// journal_path(new_path): the driver's messages and its close (which deletes the journal) use them.
void rename_journal_file(hid_t file, const std::string& new_path);

/// Path of the journal file that belongs to `results_path`.
std::string journal_path(const std::string& results_path);

/// A file-access property list for reading the committed state of a file whose stopped writer left
/// a complete commit in the journal, not yet applied (see read_view()): the driver serves the
/// journal's pages over the file's bytes, in memory. It opens read-only and writes nothing, neither
/// to the file nor to the journal.
hid_t make_journal_read_fapl();

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
