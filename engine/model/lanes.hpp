#pragma once
// Lanes<N>: N doubles computed at once, each lane exactly as scalar double arithmetic would compute
// it, so that a run's bits do not depend on the lanes it shares or on the lane width.
//   Lanes<1> = double (masks: bool), Lanes<4> = F64x4 (AVX2, __m256d), Lanes<8> = F64x8 (AVX-512F/DQ).
// Every operation is the IEEE operation of each lane: + - * / sqrt (correctly rounded, no FMA: the
// build has -ffp-contract=off and nothing here fuses), comparisons to masks, select, abs, and min /
// max with exactly std::min / std::max semantics (NaN included).
//
// Why a small hand-written wrapper rather than xsimd, Highway or std::experimental::simd: the code
// needs a dozen operations whose exact semantics are the point (min/max operand order for NaN,
// ordered vs unordered comparisons, blend), a 1-lane form that is plain double so the single-run path
// is the same template, and both widths in one binary with run-time dispatch; written out they are
// ~150 lines of intrinsics with nothing to audit behind them and no new build dependency.
//
// F64x4 exists where __AVX2__ is defined, F64x8 where __AVX512F__ and __AVX512DQ__ are: the lane
// kernels are compiled in their own translation units with those flags (methods/closed_form/lanes_x*.cpp).
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <type_traits>

#if defined(__AVX2__) || defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace ks {

// ---- 1 lane: double, masks are bool ----
inline double select(bool m, double a, double b) { return m ? a : b; }
inline bool any(bool m) { return m; }
inline bool all(bool m) { return m; }
/// Both masks (a lane holds in both): a && b for one lane, a & b for vectors' masks.
inline bool both(bool a, bool b) { return a && b; }
inline double vabs(double x) { return std::abs(x); }
inline double vsqrt(double x) { return std::sqrt(x); }
/// std::min(a, b) and std::max(a, b) per lane: b < a ? b : a and a < b ? b : a.
inline double vmin(double a, double b) { return std::min(a, b); }
inline double vmax(double a, double b) { return std::max(a, b); }
inline double lane(double x, int) { return x; }

/// A K-vector of lanes (element access as Eigen's fixed vectors: v[i]).
template <class T, int K>
struct LaneVec {
  T x[K];
  T& operator[](int i) { return x[i]; }
  const T& operator[](int i) const { return x[i]; }
};
/// A 2x3 matrix of lanes (element access as Eigen's: m(r, c)).
template <class T>
struct LaneMat23 {
  T m[2][3];
  T& operator()(int r, int c) { return m[r][c]; }
  const T& operator()(int r, int c) const { return m[r][c]; }
};

#if defined(__AVX2__)
// ---- 4 lanes: AVX2 ----
struct M64x4 {
  __m256d m;  // all ones or all zeros per lane
};
inline M64x4 operator&(M64x4 a, M64x4 b) { return {_mm256_and_pd(a.m, b.m)}; }
inline M64x4 both(M64x4 a, M64x4 b) { return a & b; }
inline M64x4 operator|(M64x4 a, M64x4 b) { return {_mm256_or_pd(a.m, b.m)}; }
inline M64x4 operator!(M64x4 a) { return {_mm256_xor_pd(a.m, _mm256_castsi256_pd(_mm256_set1_epi64x(-1)))}; }
inline bool any(M64x4 a) { return _mm256_movemask_pd(a.m) != 0; }
inline bool all(M64x4 a) { return _mm256_movemask_pd(a.m) == 0xF; }
inline int bits(M64x4 a) { return _mm256_movemask_pd(a.m); }

struct F64x4 {
  __m256d v;
  F64x4() = default;
  F64x4(double x) : v(_mm256_set1_pd(x)) {}  // NOLINT: broadcast, so that 2.0 * x reads as in scalar code
  explicit F64x4(__m256d x) : v(x) {}
  static F64x4 load(const double* p) { return F64x4(_mm256_loadu_pd(p)); }
  void store(double* p) const { _mm256_storeu_pd(p, v); }
  F64x4& operator+=(F64x4 b) { v = _mm256_add_pd(v, b.v); return *this; }
  F64x4& operator-=(F64x4 b) { v = _mm256_sub_pd(v, b.v); return *this; }
  F64x4& operator*=(F64x4 b) { v = _mm256_mul_pd(v, b.v); return *this; }
  F64x4& operator/=(F64x4 b) { v = _mm256_div_pd(v, b.v); return *this; }
};
inline F64x4 operator+(F64x4 a, F64x4 b) { return F64x4(_mm256_add_pd(a.v, b.v)); }
inline F64x4 operator-(F64x4 a, F64x4 b) { return F64x4(_mm256_sub_pd(a.v, b.v)); }
inline F64x4 operator*(F64x4 a, F64x4 b) { return F64x4(_mm256_mul_pd(a.v, b.v)); }
inline F64x4 operator/(F64x4 a, F64x4 b) { return F64x4(_mm256_div_pd(a.v, b.v)); }
inline F64x4 operator-(F64x4 a) { return F64x4(_mm256_xor_pd(a.v, _mm256_set1_pd(-0.0))); }  // sign flip, as scalar -x
inline M64x4 operator<(F64x4 a, F64x4 b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_LT_OQ)}; }
inline M64x4 operator<=(F64x4 a, F64x4 b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_LE_OQ)}; }
inline M64x4 operator>(F64x4 a, F64x4 b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_GT_OQ)}; }
inline M64x4 operator>=(F64x4 a, F64x4 b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_GE_OQ)}; }
inline M64x4 operator==(F64x4 a, F64x4 b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_EQ_OQ)}; }
inline M64x4 operator!=(F64x4 a, F64x4 b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_NEQ_UQ)}; }  // true for NaN, as in C++
inline F64x4 select(M64x4 m, F64x4 a, F64x4 b) { return F64x4(_mm256_blendv_pd(b.v, a.v, m.m)); }
inline F64x4 vabs(F64x4 x) { return F64x4(_mm256_andnot_pd(_mm256_set1_pd(-0.0), x.v)); }
inline F64x4 vsqrt(F64x4 x) { return F64x4(_mm256_sqrt_pd(x.v)); }
// (v)minpd(x, y) is x < y ? x : y and (v)maxpd(x, y) is x > y ? x : y, the second operand when unordered:
// with the operands swapped they are std::min and std::max exactly.
inline F64x4 vmin(F64x4 a, F64x4 b) { return F64x4(_mm256_min_pd(b.v, a.v)); }
inline F64x4 vmax(F64x4 a, F64x4 b) { return F64x4(_mm256_max_pd(b.v, a.v)); }
inline double lane(F64x4 x, int i) {
  alignas(32) double a[4];
  _mm256_store_pd(a, x.v);
  return a[i];
}
/// The masks of bits 0 and 1 of each lane's 64-bit pattern (the quadrant of fast_sincos).
inline void low_bits(F64x4 x, M64x4& bit0, M64x4& bit1) {
  const __m256i q = _mm256_castpd_si256(x.v), one = _mm256_set1_epi64x(1), two = _mm256_set1_epi64x(2);
  bit0.m = _mm256_castsi256_pd(_mm256_cmpeq_epi64(_mm256_and_si256(q, one), one));
  bit1.m = _mm256_castsi256_pd(_mm256_cmpeq_epi64(_mm256_and_si256(q, two), two));
}
#endif

#if defined(__AVX512F__) && defined(__AVX512DQ__)
// ---- 8 lanes: AVX-512F and DQ (the and/xor of doubles) ----
struct M64x8 {
  __mmask8 m;
};
inline M64x8 operator&(M64x8 a, M64x8 b) { return {static_cast<__mmask8>(a.m & b.m)}; }
inline M64x8 both(M64x8 a, M64x8 b) { return a & b; }
inline M64x8 operator|(M64x8 a, M64x8 b) { return {static_cast<__mmask8>(a.m | b.m)}; }
inline M64x8 operator!(M64x8 a) { return {static_cast<__mmask8>(~a.m)}; }
inline bool any(M64x8 a) { return a.m != 0; }
inline bool all(M64x8 a) { return a.m == 0xFF; }
inline int bits(M64x8 a) { return a.m; }

struct F64x8 {
  __m512d v;
  F64x8() = default;
  F64x8(double x) : v(_mm512_set1_pd(x)) {}  // NOLINT: broadcast
  explicit F64x8(__m512d x) : v(x) {}
  static F64x8 load(const double* p) { return F64x8(_mm512_loadu_pd(p)); }
  void store(double* p) const { _mm512_storeu_pd(p, v); }
  F64x8& operator+=(F64x8 b) { v = _mm512_add_pd(v, b.v); return *this; }
  F64x8& operator-=(F64x8 b) { v = _mm512_sub_pd(v, b.v); return *this; }
  F64x8& operator*=(F64x8 b) { v = _mm512_mul_pd(v, b.v); return *this; }
  F64x8& operator/=(F64x8 b) { v = _mm512_div_pd(v, b.v); return *this; }
};
inline F64x8 operator+(F64x8 a, F64x8 b) { return F64x8(_mm512_add_pd(a.v, b.v)); }
inline F64x8 operator-(F64x8 a, F64x8 b) { return F64x8(_mm512_sub_pd(a.v, b.v)); }
inline F64x8 operator*(F64x8 a, F64x8 b) { return F64x8(_mm512_mul_pd(a.v, b.v)); }
inline F64x8 operator/(F64x8 a, F64x8 b) { return F64x8(_mm512_div_pd(a.v, b.v)); }
inline F64x8 operator-(F64x8 a) { return F64x8(_mm512_xor_pd(a.v, _mm512_set1_pd(-0.0))); }
inline M64x8 operator<(F64x8 a, F64x8 b) { return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_LT_OQ)}; }
inline M64x8 operator<=(F64x8 a, F64x8 b) { return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_LE_OQ)}; }
inline M64x8 operator>(F64x8 a, F64x8 b) { return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_GT_OQ)}; }
inline M64x8 operator>=(F64x8 a, F64x8 b) { return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_GE_OQ)}; }
inline M64x8 operator==(F64x8 a, F64x8 b) { return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_EQ_OQ)}; }
inline M64x8 operator!=(F64x8 a, F64x8 b) { return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_NEQ_UQ)}; }
inline F64x8 select(M64x8 m, F64x8 a, F64x8 b) { return F64x8(_mm512_mask_blend_pd(m.m, b.v, a.v)); }
inline F64x8 vabs(F64x8 x) { return F64x8(_mm512_andnot_pd(_mm512_set1_pd(-0.0), x.v)); }
inline F64x8 vsqrt(F64x8 x) { return F64x8(_mm512_sqrt_pd(x.v)); }
inline F64x8 vmin(F64x8 a, F64x8 b) { return F64x8(_mm512_min_pd(b.v, a.v)); }  // see F64x4's
inline F64x8 vmax(F64x8 a, F64x8 b) { return F64x8(_mm512_max_pd(b.v, a.v)); }
inline double lane(F64x8 x, int i) {
  alignas(64) double a[8];
  _mm512_store_pd(a, x.v);
  return a[i];
}
inline void low_bits(F64x8 x, M64x8& bit0, M64x8& bit1) {
  const __m512i q = _mm512_castpd_si512(x.v);
  bit0.m = _mm512_test_epi64_mask(q, _mm512_set1_epi64(1));
  bit1.m = _mm512_test_epi64_mask(q, _mm512_set1_epi64(2));
}
#endif

/// The lane type of N lanes: Lanes<1> = double, Lanes<4> = F64x4 (where __AVX2__), Lanes<8> = F64x8
/// (where __AVX512F__ and __AVX512DQ__).
template <int N>
struct LaneType;
template <>
struct LaneType<1> {
  using type = double;
};
#if defined(__AVX2__)
template <>
struct LaneType<4> {
  using type = F64x4;
};
#endif
#if defined(__AVX512F__) && defined(__AVX512DQ__)
template <>
struct LaneType<8> {
  using type = F64x8;
};
#endif
template <int N>
using Lanes = typename LaneType<N>::type;

/// The number of lanes of lane type T.
template <class T>
inline constexpr int lanes_of = sizeof(T) / sizeof(double);
/// The mask type of lane type T (bool for double).
template <class T>
using MaskOf = decltype(T{} < T{});

/// Eigen's fixed vectors and 2x3 matrix for double (the single-run path's types), lane arrays otherwise.
template <class T, int K>
using VecOf = std::conditional_t<std::is_same_v<T, double>, Eigen::Matrix<double, K, 1>, LaneVec<T, K>>;
template <class T>
using Vec3Of = VecOf<T, 3>;
template <class T>
using Vec2Of = VecOf<T, 2>;
template <class T>
using Mat23Of = std::conditional_t<std::is_same_v<T, double>, Eigen::Matrix<double, 2, 3>, LaneMat23<T>>;

}  // namespace ks
