// ResultsWriter's histories and encode_history (see store.hpp, FORMAT.md: "/histories"): the
// compression runs in worker threads, the writer thread only stores.
#include <libdeflate.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <set>

#include "store/h5util.hpp"
#include "store/store.hpp"
#include "store/writer_impl.hpp"

namespace ks::store {
using namespace detail;

std::string history_group_name(std::int64_t run_id, std::int64_t n_runs) {
  std::size_t width = 6;
  std::string last = std::to_string(n_runs > 0 ? n_runs - 1 : 0);
  width = std::max(width, last.size());
  std::string s = std::to_string(run_id);
  if (s.size() < width) s = std::string(width - s.size(), '0') + s;
  return s;
}

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
}  // namespace

EncodedHistory encode_history(const RunHistory& history, int level) {
  level = std::clamp(level, 0, 9);
  EncodedHistory out;
  out.arrays.reserve(history.arrays.size());
  std::vector<unsigned char> shuffled;
  for (const auto& a : history.arrays) {
    if (a.data.size() != a.rows * a.cols)
      throw StoreError("", "history array '" + a.name + "' has " + std::to_string(a.data.size()) +
                               " values, expected rows*cols = " + std::to_string(a.rows * a.cols));
    EncodedArray e;
    e.name = a.name; e.unit = a.unit; e.rows = a.rows; e.cols = a.cols; e.level = level;
    if (!a.data.empty()) {
      const std::size_t src = a.data.size() * sizeof(double);
      if (level == 0) {  // no filter: the chunk is the raw little-endian array
        e.bytes.resize(src);
        std::memcpy(e.bytes.data(), a.data.data(), src);
      } else {  // shuffle, then deflate (zlib format, as HDF5's deflate filter writes it)
        shuffled.resize(src);
        shuffle8(a.data.data(), a.data.size(), shuffled.data());
        e.bytes = zlib_stream_high_planes(shuffled.data(), a.data.size(), level);
        if (e.bytes.empty()) throw StoreError("", "libdeflate failed for history array '" + a.name + "'");
      }
    }
    out.arrays.push_back(std::move(e));
  }
  return out;
}

void ResultsWriter::Impl::write_history(std::int64_t id, const EncodedHistory& h) {
  const std::string gname = history_group_name(id, n_runs);
  if (link_exists(histories, gname) && H5Ldelete(histories, gname.c_str(), H5P_DEFAULT) < 0)
    fail("cannot replace /histories/" + gname);
  Hid g(H5Gcreate2(histories, gname.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (!g.ok()) fail("cannot create /histories/" + gname);
  std::vector<std::string> names;
  for (const auto& a : h.arrays) {
    validate_name(path, a.name, "history array");
    if (std::find(names.begin(), names.end(), a.name) != names.end())
      throw StoreError(path, "duplicate history array '" + a.name + "' in run " + std::to_string(id));
    names.push_back(a.name);
    hsize_t dims[2] = {a.rows, a.cols};
    Hid space(H5Screate_simple(2, dims, nullptr));
    Hid dcpl(H5Pcreate(H5P_DATASET_CREATE));
    const bool empty = a.rows == 0 || a.cols == 0;
    if (!empty) {
      H5Pset_chunk(dcpl, 2, dims);  // one chunk = the whole array
      if (a.level > 0) {            // the pipeline encode_history ran: shuffle, then deflate
        H5Pset_shuffle(dcpl);
        H5Pset_deflate(dcpl, static_cast<unsigned>(a.level));
      }
    }
    Hid d(H5Dcreate2(g, a.name.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT));
    if (!d.ok()) fail("cannot create /histories/" + gname + "/" + a.name);
    if (!empty) {
      hsize_t offset[2] = {0, 0};
      if (H5Dwrite_chunk(d, H5P_DEFAULT, 0, offset, a.bytes.size(), a.bytes.data()) < 0)
        fail("cannot write /histories/" + gname + "/" + a.name);
    }
    write_str_attr(d, "unit", a.unit);
  }
  write_str_list_attr(g, "arrays", names);
}

}  // namespace ks::store
