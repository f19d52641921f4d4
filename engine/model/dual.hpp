#pragma once
// Forward-mode derivative numbers: a value and its partial derivatives with respect to N seeded
// inputs, carried through the arithmetic of the model's templates (model/trig.hpp, kinematics.hpp,
// dynamics.hpp, sym3.hpp take any scalar type). Evaluating a function on DualOf arguments seeded with
// the unit vectors gives its value and its exact gradient (to rounding) in one pass: no step size, no
// truncation error. The value and each derivative are of lane type L (model/lanes.hpp: double, or
// several samples side by side); every lane computes what the double computation would. Values round
// as the same operations on doubles do (the build contracts no multiply-add), so the value part equals
// the plain evaluation bit for bit. Only what those templates and the path-global evaluators use is
// defined.
#include <cmath>
#include <cstring>
#include <type_traits>

#include "model/lanes.hpp"
#include "model/sincos.hpp"

namespace ks {
namespace dual_detail {
/// Four doubles as one vector of GCC's (and clang's) vector extension: the derivatives of a DualOf
/// of doubles in groups of four. Each element rounds as the double operation does (no contraction).
using Four = double __attribute__((vector_size(32)));
inline Four load(const double* p) {
  Four v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store(double* p, Four v) { std::memcpy(p, &v, sizeof v); }
/// Whether a DualOf<L, N>'s derivatives go four at a time.
template <class L, int N>
constexpr bool kFours = std::is_same_v<L, double> && N % 4 == 0;
/// r[k] = f(x[k], y[k]) for the N derivatives: four at a time when kFours<L, N> (f then takes Fours,
/// its doubles spread over the four), else one at a time.
template <class L, int N, class F>
inline void each(L* r, const L* x, const L* y, F f) {
  if constexpr (kFours<L, N>) {
    for (int k = 0; k < N; k += 4) store(r + k, f(load(x + k), load(y + k)));
  } else {
    for (int k = 0; k < N; ++k) r[k] = f(x[k], y[k]);
  }
}
}  // namespace dual_detail

/// A value v and its derivatives d[k] = dv/dx_k with respect to N inputs, in lanes of type L.
template <class L, int N>
struct DualOf {
  L v;
  L d[N];

  DualOf() = default;  // uninitialized, as a double is
  DualOf(double value) : v(value) {  // NOLINT: a constant (zero derivatives), as in `2.0 * x`
    for (int k = 0; k < N; ++k) d[k] = L(0.0);
  }
  template <class U = L, class = std::enable_if_t<!std::is_same_v<U, double>>>
  DualOf(L value) : v(value) {  // NOLINT: a constant in lanes
    for (int k = 0; k < N; ++k) d[k] = L(0.0);
  }
  /// Input k of N: value x, derivative 1 with respect to itself.
  static DualOf input(L x, int k) {
    DualOf r(x);
    r.d[k] = L(1.0);
    return r;
  }
  DualOf& operator+=(const DualOf& b) { return *this = *this + b; }
  DualOf& operator-=(const DualOf& b) { return *this = *this - b; }
  DualOf& operator*=(const DualOf& b) { return *this = *this * b; }

  friend DualOf operator+(const DualOf& a, const DualOf& b) {
    DualOf r;
    r.v = a.v + b.v;
    dual_detail::each<L, N>(r.d, a.d, b.d, [](auto x, auto y) { return x + y; });
    return r;
  }
  friend DualOf operator-(const DualOf& a, const DualOf& b) {
    DualOf r;
    r.v = a.v - b.v;
    dual_detail::each<L, N>(r.d, a.d, b.d, [](auto x, auto y) { return x - y; });
    return r;
  }
  friend DualOf operator-(const DualOf& a) {
    DualOf r;
    r.v = -a.v;
    dual_detail::each<L, N>(r.d, a.d, a.d, [](auto x, auto) { return -x; });
    return r;
  }
  friend DualOf operator*(const DualOf& a, const DualOf& b) {
    DualOf r;
    r.v = a.v * b.v;
    dual_detail::each<L, N>(r.d, a.d, b.d, [&](auto x, auto y) { return x * b.v + a.v * y; });
    return r;
  }
  friend DualOf operator*(double a, const DualOf& b) { return chain(b, L(a * b.v), L(a)); }
  friend DualOf operator*(const DualOf& a, double b) { return b * a; }
  friend DualOf operator/(const DualOf& a, const DualOf& b) {  // the value as a double division rounds it
    DualOf r;
    r.v = a.v / b.v;
    const L inv = L(1.0) / b.v;
    dual_detail::each<L, N>(r.d, a.d, b.d, [&](auto x, auto y) { return (x - r.v * y) * inv; });
    return r;
  }
  friend DualOf operator/(const DualOf& a, double b) {  // (chain, below, is found when instantiated)
    return chain(a, L(a.v / b), L(1.0 / b));
  }
};
template <int N>
using Dual = DualOf<double, N>;

/// The value (lanes) of a lane value or of a DualOf.
template <class L>
inline L value_of(const L& x) {
  return x;
}
template <class L, int N>
inline L value_of(const DualOf<L, N>& x) {
  return x.v;
}

/// a where m, else b, value and derivatives alike (m: the lanes' mask).
template <class L, int N, class M>
inline DualOf<L, N> select(const M& m, const DualOf<L, N>& a, const DualOf<L, N>& b) {
  DualOf<L, N> r;
  r.v = select(m, a.v, b.v);
  for (int k = 0; k < N; ++k) r.d[k] = select(m, a.d[k], b.d[k]);
  return r;
}

/// f(x) with f(x.v) = fv and f'(x.v) = slope.
template <class L, int N>
inline DualOf<L, N> chain(const DualOf<L, N>& x, const L& fv, const L& slope) {
  DualOf<L, N> r;
  r.v = fv;
  dual_detail::each<L, N>(r.d, x.d, x.d, [&](auto d, auto) { return slope * d; });
  return r;
}

/// Square root in lanes; at 0, where it has no derivative, the derivatives are taken as 0.
inline double sqrt_of(double x) { return std::sqrt(x); }
template <class L>
inline L sqrt_of(const L& x) {
  return vsqrt(x);
}
template <class L, int N>
inline DualOf<L, N> sqrt_of(const DualOf<L, N>& x) {
  const L r = sqrt_of(x.v);
  return chain(x, r, select(r > L(0.0), L(0.5) / r, L(0.0)));
}

/// sin and cos of one argument (model/sincos.hpp's in every lane).
template <class L>
inline void sincos_of(const L& x, L& s, L& c) {
  sincos_lanes(x, s, c);
}
template <class L, int N>
inline void sincos_of(const DualOf<L, N>& x, DualOf<L, N>& s, DualOf<L, N>& c) {
  L sv, cv;
  sincos_lanes(x.v, sv, cv);
  s = chain(x, sv, cv);
  c = chain(x, cv, -sv);
}

}  // namespace ks
