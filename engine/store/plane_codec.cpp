// Byte planes of doubles and their run coder (plane_codec.hpp).
#include "store/plane_codec.hpp"

#include <libdeflate.h>

#include <array>
#include <bit>
#include <cstring>

namespace ks::store::detail {

namespace {
static_assert(std::endian::native == std::endian::little, "the byte planes assume a little-endian machine");

/// Transposes the 8 x 8 bytes of x: afterwards byte i of x[j] is what byte j of x[i] was.
inline void transpose8x8(std::uint64_t x[8]) {
  for (int i = 0; i < 4; ++i) {  // 4-byte halves
    const std::uint64_t a = x[i], b = x[i + 4];
    x[i] = (a & 0x00000000FFFFFFFFull) | (b << 32);
    x[i + 4] = (a >> 32) | (b & 0xFFFFFFFF00000000ull);
  }
  for (int k = 0; k < 8; k += 4)  // 2-byte quarters
    for (int i = k; i < k + 2; ++i) {
      const std::uint64_t a = x[i], b = x[i + 2];
      x[i] = (a & 0x0000FFFF0000FFFFull) | ((b & 0x0000FFFF0000FFFFull) << 16);
      x[i + 2] = ((a >> 16) & 0x0000FFFF0000FFFFull) | (b & 0xFFFF0000FFFF0000ull);
    }
  for (int i = 0; i < 8; i += 2) {  // bytes
    const std::uint64_t a = x[i], b = x[i + 1];
    x[i] = (a & 0x00FF00FF00FF00FFull) | ((b & 0x00FF00FF00FF00FFull) << 8);
    x[i + 1] = ((a >> 8) & 0x00FF00FF00FF00FFull) | (b & 0xFF00FF00FF00FF00ull);
  }
}

/// Bits in deflate's order: the first bit is the lowest of the first byte.
struct BitWriter {
  unsigned char* p;
  std::uint64_t acc = 0;
  int n = 0;
  void put(std::uint32_t v, int bits) {
    acc |= static_cast<std::uint64_t>(v) << n;
    n += bits;
    if (n >= 32) {
      const auto w = static_cast<std::uint32_t>(acc);
      std::memcpy(p, &w, 4);
      p += 4;
      acc >>= 32;
      n -= 32;
    }
  }
  void finish() {
    for (; n > 0; n -= 8, acc >>= 8) *p++ = static_cast<unsigned char>(acc);
  }
};

constexpr std::uint32_t reverse_bits(std::uint32_t v, int bits) {
  std::uint32_t r = 0;
  for (int i = 0; i < bits; ++i, v >>= 1) r = (r << 1) | (v & 1);
  return r;
}

/// RFC 1951 3.2.6: the fixed literal/length codes (bit-reversed for BitWriter) and the length
/// symbols with their extra bits.
struct FixedCodes {
  std::array<std::uint16_t, 288> code{};
  std::array<std::uint8_t, 288> bits{};
  std::array<std::uint8_t, 259> len_symbol{}, len_extra_bits{};
  std::array<std::uint16_t, 259> len_extra{};
  constexpr FixedCodes() {
    for (int v = 0; v < 288; ++v) {
      const int c = v < 144 ? 0x30 + v : v < 256 ? 0x190 + v - 144 : v < 280 ? v - 256 : 0xC0 + v - 280;
      const int b = v < 144 ? 8 : v < 256 ? 9 : v < 280 ? 7 : 8;
      code[v] = static_cast<std::uint16_t>(reverse_bits(static_cast<std::uint32_t>(c), b));
      bits[v] = static_cast<std::uint8_t>(b);
    }
    constexpr int base[29] = {3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 15, 17, 19, 23, 27,
                              31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
    constexpr int extra[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
    for (int len = 3; len <= 258; ++len) {
      int s = 28;
      while (base[s] > len) --s;
      len_symbol[len] = static_cast<std::uint8_t>(s);
      len_extra_bits[len] = static_cast<std::uint8_t>(extra[s]);
      len_extra[len] = static_cast<std::uint16_t>(len - base[s]);
    }
  }
};
constexpr FixedCodes kFixed;
}  // namespace

void shuffle8(const double* values, std::size_t n, unsigned char* const planes[8]) {
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    std::uint64_t x[8];
    std::memcpy(x, values + i, 64);
    transpose8x8(x);
    for (int j = 0; j < 8; ++j) std::memcpy(planes[j] + i, &x[j], 8);
  }
  const auto* b = reinterpret_cast<const unsigned char*>(values);
  for (; i < n; ++i)
    for (int j = 0; j < 8; ++j) planes[j][i] = b[i * 8 + j];
}

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

void unshuffle8(const unsigned char* const planes[8], std::size_t n, double* values) {
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    std::uint64_t x[8];
    for (int j = 0; j < 8; ++j) std::memcpy(&x[j], planes[j] + i, 8);
    transpose8x8(x);
    std::memcpy(values + i, x, 64);
  }
  auto* b = reinterpret_cast<unsigned char*>(values);
  for (; i < n; ++i)
    for (int j = 0; j < 8; ++j) b[i * 8 + j] = planes[j][i];
}

std::size_t deflate_runs(const unsigned char* src, std::size_t n, std::size_t distance, unsigned char* out) {
  BitWriter w{out};
  w.put(1, 1);  // BFINAL
  w.put(1, 2);  // BTYPE 01: fixed Huffman codes
  // The distance's code (5 bits, fixed) and extra bits (RFC 1951 3.2.5).
  constexpr int dbase[30] = {1, 2, 3, 4, 5, 7, 9, 13, 17, 25, 33, 49, 65, 97, 129,
                             193, 257, 385, 513, 769, 1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
  int ds = 29;
  while (dbase[ds] > static_cast<int>(distance)) --ds;
  const std::uint32_t dcode = reverse_bits(static_cast<std::uint32_t>(ds), 5);
  const int dextra_bits = ds < 4 ? 0 : ds / 2 - 1;
  const auto dextra = static_cast<std::uint32_t>(distance) - static_cast<std::uint32_t>(dbase[ds]);
  const auto literal = [&](unsigned char c) { w.put(kFixed.code[c], kFixed.bits[c]); };
  std::size_t i = 0;
  for (; i < n && i < distance; ++i) literal(src[i]);
  while (i < n) {
    const std::size_t max = n - i < 258 ? n - i : 258;
    std::size_t len = 0;
    for (; len + 8 <= max; len += 8) {  // 8 bytes at a time: the first difference ends the run
      std::uint64_t a, b;
      std::memcpy(&a, src + i + len, 8);
      std::memcpy(&b, src + i + len - distance, 8);
      if (a != b) {
        len += static_cast<std::size_t>(std::countr_zero(a ^ b)) / 8;
        goto measured;
      }
    }
    while (len < max && src[i + len] == src[i + len - distance]) ++len;
  measured:
    if (len >= 3) {
      const int s = 257 + kFixed.len_symbol[len];
      w.put(kFixed.code[s], kFixed.bits[s]);
      if (kFixed.len_extra_bits[len]) w.put(kFixed.len_extra[len], kFixed.len_extra_bits[len]);
      w.put(dcode, 5);
      if (dextra_bits) w.put(dextra, dextra_bits);
      i += len;
    } else {
      literal(src[i++]);
    }
  }
  w.put(kFixed.code[256], kFixed.bits[256]);  // end of block
  w.finish();
  return static_cast<std::size_t>(w.p - out);
}

}  // namespace ks::store::detail
