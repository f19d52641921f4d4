#include "store/runs_chunks.hpp"

#include <libdeflate.h>

#include <algorithm>
#include <cstring>

namespace ks::store::detail {

namespace {
/// The zlib stream of `data` as stored (uncompressed) deflate blocks: what HDF5's deflate filter
/// inflates with a copy. (Chunks are never written with a filter mask: HDF5 1.10 reads a chunk
/// written with H5Dwrite_chunk and a non-zero mask through every filter until the file is reopened.)
void stored_stream(const unsigned char* data, std::size_t n, ByteBuffer& out) {
  constexpr std::size_t kStored = 65535;  // longest stored block
  const std::size_t blocks = n == 0 ? 1 : (n + kStored - 1) / kStored;
  out.resize(2 + blocks * 5 + n + 4);
  unsigned char* p = out.data();
  *p++ = 0x78;  // CMF: deflate, 32 KiB window
  *p++ = 0x01;  // FLG: no dictionary, (0x78 * 256 + 0x01) % 31 == 0
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::size_t at = b * kStored, len = std::min(kStored, n - at);
    *p++ = b + 1 == blocks ? 0x01 : 0x00;  // BFINAL on the last block, BTYPE = 00 (stored)
    *p++ = static_cast<unsigned char>(len & 0xff);
    *p++ = static_cast<unsigned char>(len >> 8);
    *p++ = static_cast<unsigned char>(~len & 0xff);
    *p++ = static_cast<unsigned char>((~len >> 8) & 0xff);
    if (len) std::memcpy(p, data + at, len);
    p += len;
  }
  const std::uint32_t adler = libdeflate_adler32(1, data, n);
  *p++ = static_cast<unsigned char>(adler >> 24);
  *p++ = static_cast<unsigned char>(adler >> 16);
  *p++ = static_cast<unsigned char>(adler >> 8);
  *p++ = static_cast<unsigned char>(adler);
}
}  // namespace

EncodedChunk encode_column_chunk(const unsigned char* bytes, std::size_t n, std::size_t size, bool compress,
                                 int level) {
  EncodedChunk out;  // filter_mask 0: shuffled, then a zlib stream (deflated or stored)
  const std::size_t raw = n * size;
  ByteBuffer shuffled;
  const unsigned char* src = bytes;
  if (size > 1) {  // byte j of element i to plane j (HDF5's shuffle filter)
    shuffled.resize(raw);
    for (std::size_t j = 0; j < size; ++j) {
      unsigned char* plane = shuffled.data() + j * n;
      for (std::size_t i = 0; i < n; ++i) plane[i] = bytes[i * size + j];
    }
    src = shuffled.data();
  }
  thread_local struct Compressor {
    libdeflate_compressor* c[10] = {};
    ~Compressor() {
      for (auto* p : c)
        if (p) libdeflate_free_compressor(p);
    }
  } z;
  if (level < 1 || level > 9) level = 1;
  if (compress && !z.c[level]) z.c[level] = libdeflate_alloc_compressor(level);
  const std::size_t limit = raw - raw / 10;  // worth storing deflated only below this
  if (compress && z.c[level] && limit > 0) {
    out.bytes.resize(libdeflate_zlib_compress_bound(z.c[level], raw));
    const std::size_t m = libdeflate_zlib_compress(z.c[level], src, raw, out.bytes.data(), out.bytes.size());
    if (m > 0 && m <= limit) {
      out.bytes.resize(m);
      return out;
    }
  }
  stored_stream(src, raw, out.bytes);
  return out;
}

void RunsChunks::open(std::vector<hid_t> dsets, std::vector<std::size_t> sizes, hsize_t chunk_rows, hsize_t n_rows,
                      const std::string& path) {
  dsets_ = std::move(dsets);
  sizes_ = std::move(sizes);
  chunk_rows_ = chunk_rows;
  n_rows_ = n_rows;
  path_ = path;
  chunks_.assign(dsets_.size(), {});
}

RunsChunks::Chunk& RunsChunks::chunk(std::size_t col, hsize_t index) {
  auto [it, inserted] = chunks_[col].try_emplace(index);
  Chunk& c = it->second;
  c.recent = true;
  if (!inserted) return c;
  // Its rows as the file holds them (the fill value where nothing was written): through HDF5's
  // filters, so either encoding reads back.
  c.bytes.resize(chunk_rows_ * sizes_[col]);
  const hsize_t first = index * chunk_rows_, count = std::min(chunk_rows_, n_rows_ - first);
  Hid fs(H5Dget_space(dsets_[col]));
  H5Sselect_hyperslab(fs, H5S_SELECT_SET, &first, nullptr, &count, nullptr);
  Hid ms(H5Screate_simple(1, &count, nullptr));
  Hid ft(H5Dget_type(dsets_[col]));
  Hid mt(H5Tget_native_type(ft, H5T_DIR_ASCEND));
  check(H5Dread(dsets_[col], mt, ms, fs, H5P_DEFAULT, c.bytes.data()), path_, "read back a chunk of /runs");
  if (count < chunk_rows_)  // the last chunk: its padding repeats its last row (compresses to nothing)
    for (hsize_t r = count; r < chunk_rows_; ++r)
      std::memcpy(c.bytes.data() + r * sizes_[col], c.bytes.data() + (count - 1) * sizes_[col], sizes_[col]);
  return c;
}

void RunsChunks::set(std::size_t col, const std::vector<hsize_t>& ids, const unsigned char* values) {
  const std::size_t size = sizes_[col];
  Chunk* c = nullptr;
  hsize_t at = ~hsize_t{0};
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const hsize_t index = ids[i] / chunk_rows_;
    if (index != at) {
      c = &chunk(col, index);
      c->dirty = true;
      at = index;
    }
    std::memcpy(c->bytes.data() + (ids[i] - index * chunk_rows_) * size, values + i * size, size);
  }
}

void RunsChunks::write_chunk(std::size_t col, hsize_t index, const EncodedChunk& e) {
  const hsize_t offset = index * chunk_rows_;
  check(H5Dwrite_chunk(dsets_[col], H5P_DEFAULT, e.filter_mask, &offset, e.bytes.size(), e.bytes.data()), path_,
        "write a chunk of /runs");
}

void RunsChunks::write_complete(const std::vector<hsize_t>& complete) {
  for (std::size_t col = 0; col < chunks_.size(); ++col)
    for (hsize_t index : complete) {
      auto it = chunks_[col].find(index);
      if (it == chunks_[col].end()) continue;
      write_chunk(col, index, encode_column_chunk(it->second.bytes.data(), chunk_rows_, sizes_[col], true));
      chunks_[col].erase(it);
    }
}

void RunsChunks::write_partial() {
  for (std::size_t col = 0; col < chunks_.size(); ++col)
    for (auto it = chunks_[col].begin(); it != chunks_[col].end();) {
      Chunk& c = it->second;
      if (c.dirty) {
        write_chunk(col, it->first, encode_column_chunk(c.bytes.data(), chunk_rows_, sizes_[col], false));
        c.dirty = false;
      }
      if (!c.recent) {
        it = chunks_[col].erase(it);
      } else {
        c.recent = false;
        ++it;
      }
    }
}

}  // namespace ks::store::detail
