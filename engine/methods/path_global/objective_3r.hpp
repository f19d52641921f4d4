#pragma once
// The per-sample terms of the 3R path-global objective and their exact partials, over a lane type L
// (model/lanes.hpp): samples are independent given the spline's coefficients, so lanes evaluate as
// many side by side. Every lane computes what the single-sample evaluation (L = double) computes, bit
// for bit, so the objective and its gradient do not depend on the lane width. The 4- and 8-lane
// instances live in their own translation units built for their vectors (methods/path_global/
// terms_x4.cpp, terms_x8.cpp); the caller (methods/path_global/closed_form.cpp) sums the terms in
// sample order.
#include <cstddef>

#include "methods/base/path_global_options.hpp"
#include "methods/path_global/sample_3r.hpp"

namespace ks {

/// What the terms read, as arrays over the samples (structure of arrays: lanes load consecutive
/// samples), and the run's constants.
struct Terms3RInput {
  const PlanarArm3* arm = nullptr;
  const DynamicsCoefficients* dyn = nullptr;
  std::size_t n = 0;  ///< samples
  bool self_motion = false;  ///< Extension::self_motion, else Extension::alpha
  int elbow = 1;             ///< alpha: the IK branch (+1, -1)
  double clamp = 1.0;        ///< alpha: |cos theta2| past the reach is taken at this boundary
  double tolerance = 0.0;    ///< alpha: |det J3| [m^2] below which a sample costs the barrier
  GlobalObjective objective = GlobalObjective::E;
  const double *px, *py, *vx, *vy, *ax, *ay;  ///< the path at each sample [m, m/s, m/s^2]
  const double* weight;                       ///< the trapezoid's weight of each sample [s]
  const double *phi[3], *beta[3], *r;         ///< self_motion: the chart (ChartSample) and |tip| [m]
  const double *x, *xd, *xdd;                 ///< the coordinate, its rate and acceleration [rad, /s, /s^2]
};

/// The lanes at p[0 .. lanes).
template <class L>
inline L load_lanes(const double* p) {
  if constexpr (std::is_same_v<L, double>) {
    return *p;
  } else {
    return L::load(p);
  }
}

/// Sample(s) i .. i + lanes of the joint path for the coordinate x (and rates); `alpha` the tip angle.
template <class T, class L = LaneOf<T>>
inline void evaluate_3r(const Terms3RInput& in, std::size_t i, const T& x, const T& xd, const T& xdd,
                        Sample3ROf<T>& s, T& alpha) {
  const Sample3RPointOf<L> pt{load_lanes<L>(in.px + i), load_lanes<L>(in.py + i), load_lanes<L>(in.vx + i),
                              load_lanes<L>(in.vy + i), load_lanes<L>(in.ax + i), load_lanes<L>(in.ay + i)};
  if (!in.self_motion) {
    alpha = x;
    sample_3r(*in.arm, *in.dyn, pt, x, xd, xdd, true, in.elbow, in.clamp, T(0.0), T(0.0), s);
    return;
  }
  ChartLanes<L> c;
  for (int k = 0; k < 3; ++k) c.phi[k] = load_lanes<L>(in.phi[k] + i), c.beta[k] = load_lanes<L>(in.beta[k] + i);
  c.r = load_lanes<L>(in.r + i);
  T ad, add, c2, s2;
  self_motion_point(c, *in.arm, x, xd, xdd, alpha, ad, add, c2, s2);
  sample_3r(*in.arm, *in.dyn, pt, alpha, ad, add, false, 0, 0.0, c2, s2, s);
}

/// The objective's term of sample(s) i (the extension alpha's barrier where |det J3| < tolerance).
template <class T, class L = LaneOf<T>>
inline T term_3r(const Terms3RInput& in, std::size_t i, const Sample3ROf<T>& s) {
  const double n = static_cast<double>(in.n);
  const T tt = s.tau[0] * s.tau[0] + s.tau[1] * s.tau[1] + s.tau[2] * s.tau[2];
  T f(0.0);
  switch (in.objective) {
    case GlobalObjective::E: f = sqrt_of(tt) / n; break;
    case GlobalObjective::E_M: {
      const SymInverse3Of<T> Mi(s.M);
      f = sqrt_of(Mi.P.quadratic_form(s.tau) / Mi.det) / n;
      break;
    }
    case GlobalObjective::torque_sq_integral: f = T(load_lanes<L>(in.weight + i)) * tt; break;
    case GlobalObjective::kinetic_energy: f = T(load_lanes<L>(in.weight + i)) * (0.5 * s.M.quadratic_form(s.qd)); break;
  }
  if (in.self_motion) return f;
  // a barrier the size of a diverged run
  return select(vabs(value_of(s.det)) >= L(in.tolerance), f, T(1e6 / n));
}

/// The terms of samples [first, end) (end - first a multiple of the lanes) into term[i], and, when
/// `partials` is set, their partials with respect to x, xd and xdd into partial[k][i]. Everything it
/// calls is inlined into it (flatten): the samples' values stay in registers across the model's functions.
template <class L>
[[gnu::flatten]] inline void terms_3r(const Terms3RInput& in, std::size_t first, std::size_t end, bool partials, double* term,
                     double* const partial[3]) {
  constexpr int W = lanes_of<L>;
  for (std::size_t i = first; i + W <= end; i += W) {
    const L x = load_lanes<L>(in.x + i), xd = load_lanes<L>(in.xd + i), xdd = load_lanes<L>(in.xdd + i);
    if (!partials) {
      Sample3ROf<L> s;
      L alpha;
      evaluate_3r(in, i, x, xd, xdd, s, alpha);
      const L f = term_3r(in, i, s);
      if constexpr (W == 1) term[i] = f; else f.store(term + i);
      continue;
    }
    using D = DualOf<L, 3>;
    Sample3ROf<D> s;
    D alpha;
    evaluate_3r(in, i, D::input(x, 0), D::input(xd, 1), D::input(xdd, 2), s, alpha);
    const D f = term_3r(in, i, s);
    if constexpr (W == 1) {
      term[i] = f.v;
      for (int k = 0; k < 3; ++k) partial[k][i] = f.d[k];
    } else {
      f.v.store(term + i);
      for (int k = 0; k < 3; ++k) f.d[k].store(partial[k] + i);
    }
  }
}

/// A block of samples as the run's metrics read them (structure of arrays, kSampleBlock samples from
/// the block's first): reach is 1 where the wrist is within reach, else 0; M's upper triangle by
/// rows, J by rows, the tip as end_effector (model/kinematics.hpp) computes it.
inline constexpr std::size_t kSampleBlock = 256;
struct Sample3RBlock {
  alignas(64) double reach[kSampleBlock], det[kSampleBlock], alpha[kSampleBlock], c1[kSampleBlock],
      s1[kSampleBlock], c2[kSampleBlock], s2[kSampleBlock], qd[3][kSampleBlock], qdd[3][kSampleBlock],
      tau[3][kSampleBlock], M[6][kSampleBlock], J[6][kSampleBlock], tip[2][kSampleBlock];
};

/// Samples [first, end) (end - first a multiple of the lanes, at most kSampleBlock) into `out`, row
/// i - first. Everything it calls is inlined into it, as in terms_3r.
template <class L>
[[gnu::flatten]] inline void samples_3r(const Terms3RInput& in, std::size_t first, std::size_t end,
                                        Sample3RBlock& out) {
  constexpr int W = lanes_of<L>;
  const auto put = [](const L& v, double* p) {
    if constexpr (W == 1) *p = v; else v.store(p);
  };
  for (std::size_t i = first; i + W <= end; i += W) {
    const std::size_t j = i % kSampleBlock;
    Sample3ROf<L> s;
    L alpha;
    evaluate_3r(in, i, load_lanes<L>(in.x + i), load_lanes<L>(in.xd + i), load_lanes<L>(in.xdd + i), s, alpha);
    put(select(s.reachable, L(1.0), L(0.0)), out.reach + j);
    put(s.det, out.det + j);
    put(alpha, out.alpha + j);
    put(s.trig.c1, out.c1 + j), put(s.trig.s1, out.s1 + j), put(s.trig.c2, out.c2 + j), put(s.trig.s2, out.s2 + j);
    for (int k = 0; k < 3; ++k) put(s.qd[k], out.qd[k] + j), put(s.qdd[k], out.qdd[k] + j), put(s.tau[k], out.tau[k] + j);
    const L m[6] = {s.M.a00, s.M.a01, s.M.a02, s.M.a11, s.M.a12, s.M.a22};
    for (int k = 0; k < 6; ++k) put(m[k], out.M[k] + j), put(s.J(k / 3, k % 3), out.J[k] + j);
    const JointTrigOf<L>& t = s.trig;
    const double l1 = in.arm->l[0], l2 = in.arm->l[1], l3 = in.arm->l[2];
    put(l1 * t.c1 + l2 * t.c12 + l3 * t.c123, out.tip[0] + j), put(l1 * t.s1 + l2 * t.s12 + l3 * t.s123, out.tip[1] + j);
  }
}

/// terms_3r and samples_3r in 4 lanes (AVX2) and 8 lanes (AVX-512), each compiled for its vectors.
void terms_3r_x4(const Terms3RInput& in, std::size_t first, std::size_t end, bool partials, double* term,
                 double* const partial[3]);
void terms_3r_x8(const Terms3RInput& in, std::size_t first, std::size_t end, bool partials, double* term,
                 double* const partial[3]);
void samples_3r_x4(const Terms3RInput& in, std::size_t first, std::size_t end, Sample3RBlock& out);
void samples_3r_x8(const Terms3RInput& in, std::size_t first, std::size_t end, Sample3RBlock& out);

}  // namespace ks
