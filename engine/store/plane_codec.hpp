#pragma once
// Internal: the two pieces of a history chunk's encoding that libdeflate does not provide (see
// history_codec.cpp): HDF5's byte shuffle of doubles, done 8 values at a time, and a deflate coder
// for byte planes made of runs. Only store/*.cpp.
#include <cstddef>
#include <cstdint>

struct libdeflate_decompressor;

namespace ks::store::detail {

/// This thread's libdeflate decompressor (freed at thread exit), or nullptr when none can be made.
libdeflate_decompressor* decompressor();

/// HDF5's shuffle filter for 8-byte elements, into eight planes: byte j of value i goes to
/// planes[j][i], for i in [0, n).
void shuffle8(const double* values, std::size_t n, unsigned char* const planes[8]);
/// The inverse: value i is byte i of planes[0], ..., planes[7] (little-endian).
void unshuffle8(const unsigned char* const planes[8], std::size_t n, double* values);

/// Upper bound of deflate_runs' output for `n` bytes.
constexpr std::size_t deflate_runs_bound(std::size_t n) { return n / 8 * 9 + n % 8 * 2 + 16; }

/// One final deflate block (RFC 1951, fixed Huffman codes) holding `src[0, n)`: greedy matches of
/// 3..258 bytes at the one distance `distance` (1 .. 32768), literals elsewhere. Fast on byte planes
/// of smooth data, where a value's high byte usually repeats the one `distance` values before (a
/// chunk's previous row). Writes at most deflate_runs_bound(n) bytes to `out`, returns how many.
std::size_t deflate_runs(const unsigned char* src, std::size_t n, std::size_t distance, unsigned char* out);

}  // namespace ks::store::detail
