#pragma once
// Internal to the store: an HDF5 virtual file driver ("ksjournal") that makes every H5Fflush an
// atomic commit of the file, so that a kill -9 at any moment leaves the last committed state.
// See FORMAT.md, "Crash safety". Writers open with make_journal_fapl() (and recover a crashed
// writer's file first); readers use make_journal_read_fapl() only for a commit left unapplied.
// Only store/*.cpp include it.
#include <hdf5.h>

#include <cstdint>
#include <string>

#include "store/journal/format.hpp"

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


/// A file-access property list for reading the committed state of a file whose stopped writer left
/// a complete commit in the journal, not yet applied (see read_view()): the driver serves the
/// journal's pages over the file's bytes, in memory. It opens read-only and writes nothing, neither
/// to the file nor to the journal.
hid_t make_journal_read_fapl();

}  // namespace ks::store::detail
