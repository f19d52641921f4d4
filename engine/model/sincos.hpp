#pragma once
// sincos for the hot loop: Cody-Waite reduction by pi/2 and fdlibm's minimax kernels on
// [-pi/4, pi/4], inline, branch-light, and the same on every x86-64 machine (glibc picks an FMA or a
// non-FMA variant at run time, so its last bit depends on the processor; this does not).
// Accuracy: within 2 ulp of the correctly rounded value for |x| < 1e5 (tested against libm); larger
// or non-finite arguments go to libm.
#include <math.h>

#include <cmath>
#include <type_traits>

#include "model/lanes.hpp"

namespace ks {

namespace detail {
// The kernels are templates over the lane type (model/lanes.hpp): the same operations for one double
// and for every lane of a vector.
template <class T>
inline T kernel_sin(T x) {  // fdlibm __kernel_sin, tail y = 0
  constexpr double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                   S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                   S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
  const T z = x * x, v = z * x, z2 = z * z;  // Estrin's scheme: shorter dependency chain
  const T r = (S2 + z * S3) + z2 * ((S4 + z * S5) + z2 * S6);
  return x + v * (S1 + z * r);
}
template <class T>
inline T kernel_cos(T x) {  // fdlibm __kernel_cos, tail y = 0
  constexpr double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                   C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                   C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
  const T z = x * x, z2 = z * z;
  const T r = z * ((C1 + z * C2) + z2 * ((C3 + z * C4) + z2 * (C5 + z * C6)));
  const T hz = 0.5 * z, w = 1.0 - hz;
  return w + (((1.0 - w) - hz) + z * r);
}
constexpr double inv_pio2 = 6.36619772367581382433e-01;
constexpr double pio2_1 = 1.57079632673412561417e+00;   // first 33 bits of pi/2
constexpr double pio2_1t = 6.07710050650619224932e-11;  // pi/2 - pio2_1
constexpr double shifter = 0x1.8p52;
}  // namespace detail

/// s = sin(x), c = cos(x).
inline void fast_sincos(double x, double& s, double& c) {
  if (!(std::abs(x) < 1.0e5)) {  // also catches NaN and infinities
    ::sincos(x, &s, &c);
    return;
  }
  using namespace detail;
  const double fn = (x * inv_pio2 + shifter) - shifter;  // round to nearest integer
  const long n = static_cast<long>(fn);
  const double r = (x - fn * pio2_1) - fn * pio2_1t;
  const double ks = detail::kernel_sin(r), kc = detail::kernel_cos(r);
  switch (n & 3) {
    case 0: s = ks; c = kc; break;
    case 1: s = kc; c = -ks; break;
    case 2: s = -ks; c = -kc; break;
    default: s = -kc; c = ks; break;
  }
}

/// sin and cos of three angles at once: the same arithmetic as fast_sincos, written as loops over
/// the three lanes so the compiler can run two of them in one SSE2 register.
inline void fast_sincos3(const double* x, double* s, double* c) {
  if (!(std::abs(x[0]) < 1.0e5 && std::abs(x[1]) < 1.0e5 && std::abs(x[2]) < 1.0e5)) {
    for (int k = 0; k < 3; ++k) fast_sincos(x[k], s[k], c[k]);
    return;
  }
  using namespace detail;
  alignas(16) double fn[4], r[4], ks[4], kc[4];
  for (int k = 0; k < 3; ++k) fn[k] = (x[k] * inv_pio2 + shifter) - shifter;
  for (int k = 0; k < 3; ++k) r[k] = (x[k] - fn[k] * pio2_1) - fn[k] * pio2_1t;
  for (int k = 0; k < 3; ++k) ks[k] = detail::kernel_sin(r[k]);
  for (int k = 0; k < 3; ++k) kc[k] = detail::kernel_cos(r[k]);
  for (int k = 0; k < 3; ++k) {
    const long n = static_cast<long>(fn[k]);
    const double a = (n & 1) ? kc[k] : ks[k], b = (n & 1) ? ks[k] : kc[k];
    s[k] = (n & 2) ? -a : a;
    c[k] = ((n + 1) & 2) ? -b : b;
  }
}

/// fast_sincos in every lane of T (model/lanes.hpp; T = double is fast_sincos itself): the same
/// reduction and kernels, the quadrant read off the rounding sum's low bits (x / (pi/2) + 1.5 2^52
/// holds the nearest integer n in its low mantissa bits, two's complement), and libm for the lanes
/// outside |x| < 1e5.
template <class T>
inline void sincos_lanes(T x, T& s, T& c) {
  if constexpr (std::is_same_v<T, double>) {
    fast_sincos(x, s, c);
  } else {
    using namespace detail;
    const T sum = x * inv_pio2 + shifter;
    const T fn = sum - shifter;
    const T r = (x - fn * pio2_1) - fn * pio2_1t;
    const T ks = kernel_sin(r), kc = kernel_cos(r);
    MaskOf<T> bit0, bit1;
    low_bits(sum, bit0, bit1);
    // n & 3 = 0: (ks, kc); 1: (kc, -ks); 2: (-ks, -kc); 3: (-kc, ks)
    const T a = select(bit0, kc, ks), b = select(bit0, ks, kc);
    s = select(bit1, -a, a);
    c = select((bit0 & !bit1) | (bit1 & !bit0), -b, b);
    const auto small = vabs(x) < 1.0e5;  // false for NaN and infinities
    if (!all(small)) {
      constexpr int N = lanes_of<T>;
      alignas(64) double xs[N], ss[N], cs[N];
      x.store(xs);
      s.store(ss);
      c.store(cs);
      const int fast = bits(small);
      for (int i = 0; i < N; ++i)
        if (!(fast >> i & 1)) ::sincos(xs[i], &ss[i], &cs[i]);
      s = T::load(ss);
      c = T::load(cs);
    }
  }
}

}  // namespace ks
