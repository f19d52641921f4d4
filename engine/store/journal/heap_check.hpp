#pragma once
// The check of an HDF5 global heap collection before HDF5 1.10 parses it (which trusts the object
// sizes in it): both of the store's file drivers run it on each collection they read, the journal's
// (store/journal/vfd.cpp) and the readers' checked reads (store/checked_read_vfd.cpp).
#include <cstddef>
#include <cstdint>
#include <functional>

namespace ks::store::detail {

/// The unsigned little-endian integer of `bytes` bytes at `p` (HDF5's on-disk integers).
std::uint64_t le(const unsigned char* p, int bytes);

/// Reads `n` bytes at file offset `at` into `to`; false on failure.
using ReadBytes = std::function<bool(unsigned char* to, std::size_t n, std::uint64_t at)>;
/// False when `bytes` (`size` bytes read at offset `addr` of a file of `eof` bytes) start a global heap
/// collection (a first read of HDF5's: the rest of the collection is then read with `read`) that runs
/// past the file, or of which an object runs past the collection (or whose walk would not advance);
/// true otherwise (also for bytes that start no collection).
bool global_heap_collection_is_sound(const unsigned char* bytes, std::size_t size, std::uint64_t addr,
                                     std::uint64_t eof, const ReadBytes& read);

}  // namespace ks::store::detail
