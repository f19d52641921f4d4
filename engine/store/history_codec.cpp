// encode_history / decode_history (see store.hpp, FORMAT.md: "/histories"): a run's history arrays
// cut into chunks of the history datasets and encoded as HDF5's filter pipeline (shuffle, then
// deflate) stores them. HDF5-free and thread-safe: the sweep runs it in its worker threads.
#include <libdeflate.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>

#include "store/store.hpp"

namespace ks::store {

namespace {
/// HDF5's shuffle filter for 8-byte elements: byte j of element i goes to j * n + i.
void shuffle8(const double* src, std::size_t n, unsigned char* dst) {
  const unsigned char* s = reinterpret_cast<const unsigned char*>(src);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < 8; ++j) dst[j * n + i] = s[i * 8 + j];
}
/// The byte-shuffled array as one zlib stream, the format HDF5's deflate filter reads. The six
/// low-order byte planes of a history's doubles are close to noise (deflate gains ~4 % on them at
/// the price of most of its time), so they go into the stream as stored blocks, copied; only the two
/// high planes (sign, exponent, top of the mantissa: 2.5x and 50x smaller) are deflated, at `level`.
/// The stream: zlib header, stored blocks (BFINAL = 0, each ending on a byte boundary), libdeflate's
/// raw deflate of the high planes (its last block final), Adler-32 of all the bytes. Empty on failure.
std::vector<unsigned char> zlib_stream_high_planes(const unsigned char* shuffled, std::size_t n, int level);

/// One libdeflate compressor per thread and level (allocating one costs more than a small array).
libdeflate_compressor* compressor(int level) {
  struct Cache {
    std::array<libdeflate_compressor*, 10> c{};
    ~Cache() {
      for (auto* p : c)
        if (p) libdeflate_free_compressor(p);
    }
  };
  thread_local Cache cache;
  if (!cache.c[level]) cache.c[level] = libdeflate_alloc_compressor(level);
  return cache.c[level];
}

std::vector<unsigned char> zlib_stream_high_planes(const unsigned char* shuffled, std::size_t n, int level) {
  const std::size_t total = 8 * n, low = 6 * n;  // planes 0..5 stored, 6..7 deflated
  libdeflate_compressor* c = compressor(level);
  if (!c) return {};
  const std::size_t stored_blocks = (low + 65534) / 65535;
  std::vector<unsigned char> out(2 + low + 5 * stored_blocks + libdeflate_deflate_compress_bound(c, total - low) + 4);
  unsigned char* p = out.data();
  *p++ = 0x78;  // CMF: deflate, 32 KiB window
  *p++ = 0x01;  // FLG: no dictionary, (0x78 * 256 + 0x01) % 31 == 0
  for (std::size_t at = 0; at < low;) {
    const std::size_t len = std::min<std::size_t>(65535, low - at);
    *p++ = 0x00;  // BFINAL = 0, BTYPE = 00 (stored), then padding to the byte boundary
    *p++ = static_cast<unsigned char>(len & 0xff);
    *p++ = static_cast<unsigned char>(len >> 8);
    *p++ = static_cast<unsigned char>(~len & 0xff);
    *p++ = static_cast<unsigned char>((~len >> 8) & 0xff);
    std::memcpy(p, shuffled + at, len);
    p += len;
    at += len;
  }
  const std::size_t room = static_cast<std::size_t>(out.data() + out.size() - p) - 4;
  const std::size_t m = libdeflate_deflate_compress(c, shuffled + low, total - low, p, room);
  if (m == 0) return {};
  p += m;
  const std::uint32_t adler = libdeflate_adler32(1, shuffled, total);
  *p++ = static_cast<unsigned char>(adler >> 24);
  *p++ = static_cast<unsigned char>(adler >> 16);
  *p++ = static_cast<unsigned char>(adler >> 8);
  *p++ = static_cast<unsigned char>(adler);
  out.resize(static_cast<std::size_t>(p - out.data()));
  return out;
}

/// One libdeflate decompressor per thread.
libdeflate_decompressor* decompressor() {
  struct Cache {
    libdeflate_decompressor* d = nullptr;
    ~Cache() {
      if (d) libdeflate_free_decompressor(d);
    }
  };
  thread_local Cache cache;
  if (!cache.d) cache.d = libdeflate_alloc_decompressor();
  return cache.d;
}

void unshuffle8(const unsigned char* src, std::size_t n, double* dst) {
  unsigned char* d = reinterpret_cast<unsigned char*>(dst);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < 8; ++j) d[i * 8 + j] = src[j * n + i];
}

/// One chunk of `n` values: raw for level 0; else shuffled, then the fast stream above when the
/// chunk is at least 7/8 data (its NaN padding's low planes cost little stored), or libdeflate's
/// zlib stream of everything when padding dominates (short runs: a few rows in a large chunk).
EncodedChunk encode_chunk(const double* values, std::size_t n, std::size_t data_values, int level,
                          std::vector<unsigned char>& shuffled) {
  EncodedChunk c;
  const std::size_t bytes = n * sizeof(double);
  if (level == 0) {
    c.filter_mask = kRawChunk;
    c.bytes.resize(bytes);
    std::memcpy(c.bytes.data(), values, bytes);
    return c;
  }
  shuffled.resize(bytes);
  shuffle8(values, n, shuffled.data());
  if (8 * data_values >= 7 * n) {
    c.bytes = zlib_stream_high_planes(shuffled.data(), n, level);
  } else if (libdeflate_compressor* z = compressor(level)) {
    c.bytes.resize(libdeflate_zlib_compress_bound(z, bytes));
    const std::size_t m = libdeflate_zlib_compress(z, shuffled.data(), bytes, c.bytes.data(), c.bytes.size());
    c.bytes.resize(m);
  }
  if (c.bytes.empty()) throw StoreError("", "libdeflate failed to compress a history chunk");
  return c;
}
}  // namespace

EncodedHistory encode_history(const RunHistory& history, int level, std::size_t chunk_rows) {
  level = std::clamp(level, 0, 9);
  EncodedHistory out;
  out.arrays.reserve(history.arrays.size());
  std::vector<unsigned char> shuffled;
  std::vector<double> padded;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const auto& a : history.arrays) {
    if (a.data.size() != a.rows * a.cols)
      throw StoreError("", "history array '" + a.name + "' has " + std::to_string(a.data.size()) +
                               " values, expected rows*cols = " + std::to_string(a.rows * a.cols));
    if (a.rows != history.arrays.front().rows)
      throw StoreError("", "history array '" + a.name + "' has " + std::to_string(a.rows) + " rows, array '" +
                               history.arrays.front().name + "' " + std::to_string(history.arrays.front().rows) +
                               ": a run's history arrays share their rows");
    EncodedArray e;
    e.name = a.name; e.unit = a.unit; e.rows = a.rows; e.cols = a.cols; e.level = level;
    e.chunk_rows = a.rows == 0 ? 0 : chunk_rows == 0 ? a.rows : chunk_rows;
    if (a.cols > 0)
      for (std::size_t r0 = 0; r0 < a.rows; r0 += e.chunk_rows) {
        const std::size_t r = std::min(e.chunk_rows, a.rows - r0), n = e.chunk_rows * a.cols;
        const double* v = a.data.data() + r0 * a.cols;
        if (r < e.chunk_rows) {  // the last chunk: the rows left, then NaN
          padded.assign(n, nan);
          std::copy(v, v + r * a.cols, padded.begin());
          v = padded.data();
        }
        e.chunks.push_back(encode_chunk(v, n, r * a.cols, level, shuffled));
      }
    out.arrays.push_back(std::move(e));
  }
  return out;
}

RunHistory decode_history(const EncodedHistory& history) {
  RunHistory out;
  std::vector<unsigned char> plain;
  std::vector<double> chunk;
  for (const auto& e : history.arrays) {
    HistoryArray a{e.name, e.unit, e.rows, e.cols, {}};
    a.data.reserve(e.rows * e.cols);
    const std::size_t n = e.chunk_rows * e.cols, bytes = n * sizeof(double);
    for (std::size_t k = 0; k < e.chunks.size(); ++k) {
      const EncodedChunk& c = e.chunks[k];
      const unsigned char* p = c.bytes.data();
      std::size_t size = c.bytes.size();
      if (!(c.filter_mask & 0x2)) {  // deflate applied
        plain.resize(bytes);
        std::size_t got = 0;
        libdeflate_decompressor* d = decompressor();
        if (!d || libdeflate_zlib_decompress(d, p, size, plain.data(), bytes, &got) != LIBDEFLATE_SUCCESS)
          throw StoreError("", "history array '" + e.name + "': chunk " + std::to_string(k) + " does not inflate");
        p = plain.data();
        size = got;
      }
      if (size != bytes)
        throw StoreError("", "history array '" + e.name + "': chunk " + std::to_string(k) + " holds " +
                                 std::to_string(size) + " bytes, expected " + std::to_string(bytes));
      chunk.resize(n);
      if (!(c.filter_mask & 0x1)) unshuffle8(p, n, chunk.data());  // shuffle applied
      else std::memcpy(chunk.data(), p, bytes);
      const std::size_t r = std::min(e.chunk_rows, e.rows - k * e.chunk_rows);
      a.data.insert(a.data.end(), chunk.begin(), chunk.begin() + static_cast<std::ptrdiff_t>(r * e.cols));
    }
    if (a.data.size() != a.rows * a.cols)
      throw StoreError("", "history array '" + e.name + "' decodes to " + std::to_string(a.data.size()) +
                               " values, expected " + std::to_string(a.rows * a.cols));
    out.arrays.push_back(std::move(a));
  }
  return out;
}

std::size_t encoded_bytes(const EncodedHistory& history) {
  std::size_t b = 0;
  for (const auto& a : history.arrays)
    for (const auto& c : a.chunks) b += c.bytes.size();
  return b;
}

}  // namespace ks::store
