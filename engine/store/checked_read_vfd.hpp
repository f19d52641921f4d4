#pragma once
// Internal to the store: the HDF5 driver readers open a results file with when no journal overlay is
// needed (checked_read_vfd.cpp): sec2's plain reads, plus a check of each global heap collection (the
// variable-length strings) before HDF5 1.10 parses it, so that a damaged collection fails the read
// instead of crashing the process. Only store/*.cpp include it.
#include <hdf5.h>

#include "store/journal/heap_check.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

namespace ks::store::detail {

/// A file-access property list opening a file read-only through the checked driver (H5Pclose it).
hid_t make_checked_read_fapl();

/// Throws StoreError (naming `what`) when an element of the selection `file_space` (H5S_ALL: every
/// element) of the contiguous variable-length string dataset `dset` of the results file `path` points
/// to no object of its length in the file's global heap: HDF5 1.10 would copy from a null object, or
/// past the buffer it allocated for the string. Nothing for a dataset that is not contiguous, or a file
/// with a journal beside it (its bytes on disk may not be its committed state).
void check_vlen_references(hid_t dset, hid_t file_space, const std::string& path, const std::string& what);

}  // namespace ks::store::detail
