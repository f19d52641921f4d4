// The byte planes and run coder under the history encoding (store/plane_codec.hpp), and the
// encoded chunks of long arrays, checked with zlib's own inflate (an independent decoder).
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "store/plane_codec.hpp"
#include "store/store.hpp"

namespace {
using namespace ks;
using namespace ks::store;

/// src inflated as one raw deflate stream (no zlib header) by zlib; empty on any error.
std::vector<unsigned char> inflate_raw(const unsigned char* src, std::size_t n, std::size_t expected) {
  std::vector<unsigned char> out(expected + 1);
  z_stream z{};
  if (inflateInit2(&z, -15) != Z_OK) return {};
  z.next_in = const_cast<unsigned char*>(src);
  z.avail_in = static_cast<uInt>(n);
  z.next_out = out.data();
  z.avail_out = static_cast<uInt>(out.size());
  const int rc = inflate(&z, Z_FINISH);
  const std::size_t got = out.size() - z.avail_out;
  const bool consumed = z.avail_in == 0;
  inflateEnd(&z);
  if (rc != Z_STREAM_END || !consumed) return {};
  out.resize(got);
  return out;
}

std::vector<double> random_doubles(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  std::vector<double> v(n);
  for (auto& x : v) {
    const std::uint64_t u = g();
    std::memcpy(&x, &u, 8);
  }
  return v;
}

TEST(PlaneCodec, ShuffleMovesByteJOfValueIToPlaneJ) {
  for (std::size_t n : {0, 1, 7, 8, 9, 15, 16, 17, 63, 1001}) {
    const auto v = random_doubles(n, n);
    std::vector<unsigned char> planes(8 * n + 1, 0xAB);
    unsigned char* p[8];
    for (int j = 0; j < 8; ++j) p[j] = planes.data() + j * n;
    detail::shuffle8(v.data(), n, p);
    const auto* b = reinterpret_cast<const unsigned char*>(v.data());
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < 8; ++j) ASSERT_EQ(planes[j * n + i], b[8 * i + j]) << "n " << n << " i " << i << " j " << j;
    EXPECT_EQ(planes[8 * n], 0xAB) << "wrote past the planes";
    std::vector<double> back(n);
    const unsigned char* q[8];
    for (int j = 0; j < 8; ++j) q[j] = p[j];
    detail::unshuffle8(q, n, back.data());
    EXPECT_EQ(0, std::memcmp(back.data(), v.data(), 8 * n)) << n;
  }
}

TEST(PlaneCodec, RunCoderInflatesToItsInput) {
  std::mt19937_64 g(7);
  for (std::size_t distance : {1, 2, 3, 5, 258, 1000, 32768})
    for (std::size_t n : {0, 1, 2, 3, 259, 5000, 70000}) {
      // Three kinds of bytes: noise, runs of one byte, and a period of `distance` bytes with rare changes.
      for (int kind = 0; kind < 3; ++kind) {
        std::vector<unsigned char> src(n);
        for (std::size_t i = 0; i < n; ++i) {
          const auto r = static_cast<unsigned char>(g());
          src[i] = kind == 0 ? r : kind == 1 ? static_cast<unsigned char>(i / 1000) :
                   i >= distance && g() % 97 != 0 ? src[i - distance] : r;
        }
        std::vector<unsigned char> out(detail::deflate_runs_bound(n));
        const std::size_t m = detail::deflate_runs(src.data(), n, distance, out.data());
        ASSERT_LE(m, out.size());
        const auto back = inflate_raw(out.data(), m, n);
        ASSERT_EQ(back.size(), n) << "distance " << distance << " n " << n << " kind " << kind;
        EXPECT_TRUE(back == src) << "distance " << distance << " n " << n << " kind " << kind;
        if (kind == 1 && n >= 5000 && distance <= 5) {
          EXPECT_LT(m, n / 20) << "runs should code to a few bytes per 258";
        }
      }
    }
}

TEST(PlaneCodec, LongChunksDecodeWithZlibAtEveryLevel) {
  // 30000 rows x 3 columns: 90000 values, so each stored plane spans two stored blocks; a smooth
  // signal (the run coder's case) with a NaN-padded tail, and 40000 columns (beyond deflate's
  // longest distance for the run coder).
  HistoryArray smooth{"q", "rad", 30000, 3, {}};
  for (std::size_t r = 0; r < smooth.rows; ++r)
    for (std::size_t c = 0; c < 3; ++c) smooth.data.push_back(std::sin(1e-3 * static_cast<double>(r) + c) * (c + 1));
  HistoryArray wide{"w", "", 2, 40000, {}};
  for (std::size_t i = 0; i < 80000; ++i) wide.data.push_back(std::cos(static_cast<double>(i)));
  for (const HistoryArray& a : {smooth, wide})
    for (int level : {1, 2, 9})
      for (std::size_t chunk_rows : {a.rows, a.rows + 5}) {
        RunHistory h;
        h.arrays.push_back(a);
        const EncodedHistory e = encode_history(h, level, chunk_rows);
        ASSERT_EQ(e.arrays.size(), 1u);
        ASSERT_EQ(e.arrays[0].chunks.size(), 1u);
        const EncodedChunk& c = e.arrays[0].chunks[0];
        EXPECT_EQ(c.filter_mask, 0u);
        const std::size_t n = chunk_rows * a.cols;
        std::vector<unsigned char> shuffled(8 * n + 16);
        uLongf got = static_cast<uLongf>(shuffled.size());
        ASSERT_EQ(uncompress(shuffled.data(), &got, c.bytes.data(), c.bytes.size()), Z_OK) << a.name << " level " << level;
        ASSERT_EQ(got, 8 * n);
        for (std::size_t i = 0; i < n; ++i) {
          unsigned char v[8];
          for (std::size_t j = 0; j < 8; ++j) v[j] = shuffled[j * n + i];
          double x;
          std::memcpy(&x, v, 8);
          if (i < a.data.size()) ASSERT_EQ(0, std::memcmp(&x, &a.data[i], 8)) << a.name << " value " << i;
          else ASSERT_TRUE(std::isnan(x)) << a.name << " padding " << i;
        }
        if (a.name == "q" && chunk_rows == a.rows) {
          EXPECT_LT(c.bytes.size(), 8 * n * 15 / 16) << "level " << level;
        }
        const RunHistory back = decode_history(e);
        ASSERT_EQ(back.arrays.size(), 1u);
        EXPECT_EQ(0, std::memcmp(back.arrays[0].data.data(), a.data.data(), 8 * a.data.size()));
      }
}

}  // namespace
