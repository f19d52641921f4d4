// The global heap collection check of store/journal/heap_check.hpp.
#include "store/journal/heap_check.hpp"

#include <cstring>
#include <vector>

namespace ks::store::detail {

std::uint64_t le(const unsigned char* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = v << 8 | p[i];
  return v;
}

bool global_heap_collection_is_sound(const unsigned char* bytes, std::size_t size, std::uint64_t addr,
                                     std::uint64_t eof, const ReadBytes& read) {
  // The layout of a collection (HDF5 file format specification, "Global Heap"), with 8-byte lengths
  // (kinesweep's files): "GCOL", version 1, 3 reserved bytes, the collection's size; then objects, each a
  // 16-byte header (index: 2 bytes, reference count: 2, reserved: 4, size: 8) and its data padded to 8
  // bytes; index 0 is the free space, whose size counts its header.
  constexpr std::size_t kHeader = 16, kObjectHeader = 16;
  if (size < kHeader || std::memcmp(bytes, "GCOL\1\0\0\0", 8) != 0) return true;  // not a collection's start
  const std::uint64_t declared = le(bytes + 8, 8);
  if (declared < kHeader || addr > eof || declared > eof - addr) return false;
  std::vector<unsigned char> whole;
  if (declared > size) {  // HDF5's first read (of the minimum size): it reads the rest next, unchecked
    whole.resize(static_cast<std::size_t>(declared));
    if (!read(whole.data(), whole.size(), addr)) return false;
    bytes = whole.data();
  }
  // HDF5's own walk over the objects (H5HG__cache_heap_deserialize), which checks none of these bounds.
  std::uint64_t p = kHeader;
  while (p + kObjectHeader <= declared) {
    const std::uint64_t index = le(bytes + p, 2), object = le(bytes + p + 8, 8);
    const std::uint64_t room = declared - p;
    if (object > room) return false;
    const std::uint64_t need = index == 0 ? object : kObjectHeader + (object + 7) / 8 * 8;
    if (need == 0 || need > room) return false;  // past the collection, or a walk that never ends
    p += need;
  }
  return true;
}

}  // namespace ks::store::detail
