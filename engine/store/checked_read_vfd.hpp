#pragma once
// Internal to the store: the HDF5 driver readers open a results file with when no journal overlay is
// needed (checked_read_vfd.cpp): sec2's plain reads, plus a check of each global heap collection (the
// variable-length strings) before HDF5 1.10 parses it, so that a damaged collection fails the read
// instead of crashing the process. Only store/*.cpp include it.
#include <hdf5.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

namespace ks::store::detail {

/// A file-access property list opening a file read-only through the checked driver (H5Pclose it).
hid_t make_checked_read_fapl();

/// Reads `n` bytes at file offset `at` into `to`; false on failure.
using ReadBytes = std::function<bool(unsigned char* to, std::size_t n, std::uint64_t at)>;
/// False when `bytes` (`size` bytes read at offset `addr` of a file of `eof` bytes) start a global heap
/// collection (a first read of HDF5's: the rest of the collection is then read with `read`) that runs
/// past the file, or of which an object runs past the collection (or whose walk would not advance);
/// true otherwise (also for bytes that start no collection).
bool global_heap_collection_is_sound(const unsigned char* bytes, std::size_t size, std::uint64_t addr,
                                     std::uint64_t eof, const ReadBytes& read);

/// Throws StoreError (naming `what`) when an element of the selection `file_space` (H5S_ALL: every
/// element) of the contiguous variable-length string dataset `dset` of the results file `path` points
/// to no object of its length in the file's global heap: HDF5 1.10 would copy from a null object, or
/// past the buffer it allocated for the string. Nothing for a dataset that is not contiguous, or a file
/// with a journal beside it (its bytes on disk may not be its committed state).
void check_vlen_references(hid_t dset, hid_t file_space, const std::string& path, const std::string& what);

}  // namespace ks::store::detail
