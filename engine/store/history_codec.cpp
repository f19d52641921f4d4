// encode_history / decode_history (see store.hpp, FORMAT.md: "/histories"): a run's history arrays
// cut into chunks of the history datasets and encoded as HDF5's filter pipeline (shuffle, then
// deflate) stores them. HDF5-free and thread-safe: the sweep runs it in its worker threads.
#include <libdeflate.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>

#include "store/plane_codec.hpp"
#include "store/store.hpp"

namespace ks::store {

namespace {
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

/// The zlib stream of one chunk of `n` values of `cols` columns, as HDF5's shuffle then deflate
/// filters store it: zlib header; the byte planes 0 .. first_coded-1 as stored blocks (BFINAL = 0,
/// byte-aligned), shuffled straight into place; the planes first_coded .. 7 coded together as the
/// final block(s), by deflate_runs (level 1: matches at distance `cols`, a value's previous row) or
/// by libdeflate at `level`; Adler-32 of all the planes. Empty on failure.
ByteBuffer planes_stream(const double* values, std::size_t n, std::size_t cols, int first_coded,
                                         int level, ByteBuffer& coded_planes) {
  constexpr std::size_t kStored = 65535;  // longest stored block
  const std::size_t segments = (n + kStored - 1) / kStored, coded = static_cast<std::size_t>(8 - first_coded) * n;
  libdeflate_compressor* z = level > 1 ? compressor(level) : nullptr;
  if (level > 1 && !z) return {};
  const std::size_t bound = level > 1 ? libdeflate_deflate_compress_bound(z, coded) : detail::deflate_runs_bound(coded);
  ByteBuffer out(2 + static_cast<std::size_t>(first_coded) * (n + 5 * segments) + bound + 4);
  out[0] = 0x78;  // CMF: deflate, 32 KiB window
  out[1] = 0x01;  // FLG: no dictionary, (0x78 * 256 + 0x01) % 31 == 0
  coded_planes.resize(coded);
  // Plane j's segment s: a stored block of the values [s * kStored, ...) of plane j.
  const auto block = [&](int j, std::size_t s) {
    return out.data() + 2 + (static_cast<std::size_t>(j) * segments + s) * 5 + static_cast<std::size_t>(j) * n + s * kStored;
  };
  std::uint32_t adler = 1;
  for (std::size_t s = 0; s < segments; ++s) {
    const std::size_t at = s * kStored, len = std::min(kStored, n - at);
    unsigned char* planes[8];
    for (int j = 0; j < 8; ++j) {
      if (j < first_coded) {
        unsigned char* h = block(j, s);
        h[0] = 0x00;  // BFINAL = 0, BTYPE = 00 (stored), then padding to the byte boundary
        h[1] = static_cast<unsigned char>(len & 0xff);
        h[2] = static_cast<unsigned char>(len >> 8);
        h[3] = static_cast<unsigned char>(~len & 0xff);
        h[4] = static_cast<unsigned char>((~len >> 8) & 0xff);
        planes[j] = h + 5;
      } else {
        planes[j] = coded_planes.data() + static_cast<std::size_t>(j - first_coded) * n + at;
      }
    }
    detail::shuffle8(values + at, len, planes);
  }
  for (int j = 0; j < first_coded; ++j)
    for (std::size_t s = 0; s < segments; ++s)
      adler = libdeflate_adler32(adler, block(j, s) + 5, std::min(kStored, n - s * kStored));
  adler = libdeflate_adler32(adler, coded_planes.data(), coded);
  unsigned char* p = block(first_coded, 0);
  const std::size_t m = level > 1 ? libdeflate_deflate_compress(z, coded_planes.data(), coded, p, bound)
                                  : detail::deflate_runs(coded_planes.data(), coded, cols, p);
  if (m == 0) return {};
  p += m;
  *p++ = static_cast<unsigned char>(adler >> 24);
  *p++ = static_cast<unsigned char>(adler >> 16);
  *p++ = static_cast<unsigned char>(adler >> 8);
  *p++ = static_cast<unsigned char>(adler);
  out.resize(static_cast<std::size_t>(p - out.data()));
  return out;
}

/// One chunk of `n` values (`data_values` of them data, the rest NaN padding) of `cols` columns: raw
/// for level 0; else a zlib stream of its byte planes (planes_stream). A chunk mostly of data keeps
/// its six (level >= 2) or seven (level 1) low planes stored: close to noise in a history's doubles,
/// deflate gains ~4 % on them at the price of most of its time. The high planes (sign, exponent,
/// top of the mantissa) are coded. A chunk mostly of padding (short runs: a few rows in a large
/// chunk) has all its planes coded.
EncodedChunk encode_chunk(const double* values, std::size_t n, std::size_t cols, std::size_t data_values, int level,
                          ByteBuffer& scratch) {
  EncodedChunk c;
  const std::size_t bytes = n * sizeof(double);
  if (level == 0) {
    c.filter_mask = kRawChunk;
    c.bytes.resize(bytes);
    std::memcpy(c.bytes.data(), values, bytes);
    return c;
  }
  if (level == 1 && cols > 32768) level = 2;  // beyond deflate's longest distance: libdeflate's fastest
  const bool mostly_data = 8 * data_values >= 7 * n;
  c.bytes = planes_stream(values, n, cols, mostly_data ? (level == 1 ? 7 : 6) : 0, level, scratch);
  if (c.bytes.empty()) throw StoreError("", "libdeflate failed to compress a history chunk");
  return c;
}
}  // namespace

EncodedHistory encode_history(const RunHistory& history, int level, std::size_t chunk_rows) {
  level = std::clamp(level, 0, 9);
  EncodedHistory out;
  out.arrays.reserve(history.arrays.size());
  thread_local ByteBuffer coded_planes;  // the planes to code, kept from run to run: no allocation per run
  thread_local std::vector<double> padded;
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
        e.chunks.push_back(encode_chunk(v, n, a.cols, r * a.cols, level, coded_planes));
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
        libdeflate_decompressor* d = detail::decompressor();
        if (!d || libdeflate_zlib_decompress(d, p, size, plain.data(), bytes, &got) != LIBDEFLATE_SUCCESS)
          throw StoreError("", "history array '" + e.name + "': chunk " + std::to_string(k) + " does not inflate");
        p = plain.data();
        size = got;
      }
      if (size != bytes)
        throw StoreError("", "history array '" + e.name + "': chunk " + std::to_string(k) + " holds " +
                                 std::to_string(size) + " bytes, expected " + std::to_string(bytes));
      chunk.resize(n);
      const unsigned char* planes[8];
      for (int j = 0; j < 8; ++j) planes[j] = p + static_cast<std::size_t>(j) * n;
      if (!(c.filter_mask & 0x1)) detail::unshuffle8(planes, n, chunk.data());  // shuffle applied
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
