#pragma once
// The lane probe: a minimal, independent N-lane implementation of one seed run of case 1a
// (local_weighted, k = 0, the seed 3R arm, the seed square sampled once at dt = 1 ms, 2001 samples,
// semi-implicit Euler), written from the seed's formulas (/work/shared/seeds/NOTES.md, Table 2,
// Table 3, Eq. 51) and the metric definitions of engine/store/FORMAT.md ("Metrics of trajectory
// runs"), not from the engine's kernel. It measures what the per-step arithmetic of that run costs in
// N lanes, with nothing else: no bounds or limit checks, no masks, no statuses, no histories.
//
// Per sample: sin/cos of the three joint angles (tracked by rotating them by each step's dq, whose
// sine and cosine are short Taylor series: |dq| stays below a few 1e-2 rad here), J, J-dot qd, the mass
// matrix, Coriolis and gravity terms, M^-1 (adjugate / det), the inertia-weighted resolution
//   qdd = M^-1 J^T lambda - M^-1 h,  lambda = (J M^-1 J^T)^-1 (xdd - Jdot qd + J M^-1 h),  h = c + k g
// (Eq. 51 rearranged), tau = M qdd + c + g, E += sqrt(tau^T tau), then qd += dt qdd, q += dt qd.
// With the metrics (Metrics::all), also per sample: E_M += sqrt(tau^T M^-1 tau), the per-joint peaks
// of |tau_i|, det(J J^T) (its minimum; the square root once at the end), the sums of tau^T tau and of
// sum (tau_i qd_i)^2 (trapezoidal: the half end samples subtracted at the end), the peak |tau_i qd_i|,
// |tip - path| (its sum, and the largest square), and at the last sample alpha, max |qd_i| and
// qd^T M qd / 2: every metric the engine stores for such a run (FORMAT.md).
// Its results agree with ks::simulate to rounding (tests/test_lane_probe.cpp), not bitwise: the
// formulas are arranged differently.
//
// Widths: 1 (double), 4 (AVX2) and 8 (AVX-512F) lanes, as GCC vector extensions. The lane code is
// instantiated only in lane_probe_x1.cpp / lane_probe_x4.cpp / lane_probe_x8.cpp (each compiled with
// its own flags: tests/bench/CMakeLists.txt) inside an unnamed namespace, so no inline function of a
// wider instruction set can be shared with the rest of the program.
#include <cmath>
#include <cstddef>
#include <vector>

namespace ks_probe {

/// The seed square sampled at t = i dt, i = 0 .. n - 1: the path position and acceleration (x, y)
/// per sample, and the path's first point.
struct ProbePath {
  double dt = 1e-3;
  std::size_t n = 0;
  std::vector<double> pos;  ///< 2 per sample [m]
  std::vector<double> acc;  ///< 2 per sample [m/s^2]
  double p0[2] = {1.5, 1.5};
};
/// Samples the seed square (4 quintic segments of 0.5 s: NOTES.md, Table 3) at dt.
ProbePath seed_square_path(double dt = 1e-3);

/// What a run computes: E alone (the per-step arithmetic), or every metric the engine stores for it.
enum class Metrics { E, all };

/// One run's metrics (FORMAT.md's definitions). With Metrics::E only E is written (the rest stay NaN).
struct ProbeResult {
  double E = NAN;                   ///< mean over samples of sqrt(tau^T tau) [Nm]
  double E_M = NAN;                 ///< mean over samples of sqrt(tau^T M^-1 tau)
  double tau_inf[3] = {NAN, NAN, NAN};  ///< max over samples of |tau_i| [Nm]
  double min_manipulability = NAN;  ///< min over samples of sqrt(det(J J^T)) [m^2]
  double torque_sq_integral = NAN;  ///< trapezoidal integral of sum tau_i^2 [N^2 m^2 s]
  double power_sq_integral = NAN;   ///< trapezoidal integral of sum (tau_i qd_i)^2 [W^2 s]
  double max_tracking_error = NAN;  ///< max over samples of |tip - path| [m]
  double mean_tracking_error = NAN; ///< mean over samples of |tip - path| [m]
  double final_alpha = NAN;         ///< theta1 + theta2 + theta3 at the last sample [rad]
  double peak_joint_power = NAN;    ///< max over samples and joints of |tau_i qd_i| [W]
  double end_qd_max = NAN;          ///< max over joints of |qd_i| at the last sample [rad/s]
  double end_kinetic_energy = NAN;  ///< qd^T M qd / 2 at the last sample [J]
};

/// `lanes` runs (lanes = 1, 4 or 8), one per lane: start at rest from the seed IK at the path's first
/// point for alpha1A[l] (elbow sin(theta2) >= 0), gravity weight k[l]. out[l] is written.
void run_x1(Metrics metrics, const ProbePath& path, const double* alpha1A, const double* k, ProbeResult* out);
void run_x4(Metrics metrics, const ProbePath& path, const double* alpha1A, const double* k, ProbeResult* out);
void run_x8(Metrics metrics, const ProbePath& path, const double* alpha1A, const double* k, ProbeResult* out);
/// Whether this processor runs run_x4 / run_x8.
bool runs_x4();
bool runs_x8();

}  // namespace ks_probe

#ifdef KS_LANE_PROBE_IMPL
// ---- the lane code: only in lane_probe_x*.cpp ----
#include <cmath>
#if defined(__AVX2__) || defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace ks_probe {
namespace {

// Seed arm (NOTES.md, Table 2): l = 1 m, b = 0.1 m, m = (5, 2, 1) kg, centre of mass at l/2,
// I = m (l^2 + b^2) / 12 about the centre of mass, g = 9.81 m/s^2 along -y.
struct Arm {
  double l1 = 1, l2 = 1, l3 = 1;
  double m1 = 5, m2 = 2, m3 = 1;
  double r1 = 0.5, r2 = 0.5, r3 = 0.5;
  double I1 = 5 * (1 + 0.01) / 12, I2 = 2 * (1 + 0.01) / 12, I3 = 1 * (1 + 0.01) / 12;
  double g = 9.81;
};

/// The lane type of width N.
template <int N>
struct LaneType;
template <>
struct LaneType<1> {
  using type = double;
};
template <>
struct LaneType<4> {
  typedef double type __attribute__((vector_size(32)));
};
template <>
struct LaneType<8> {
  typedef double type __attribute__((vector_size(64)));
};

inline double root(double x) { return std::sqrt(x); }
#if defined(__AVX2__)
inline LaneType<4>::type root(LaneType<4>::type x) { return _mm256_sqrt_pd(x); }
#endif
#if defined(__AVX512F__)
inline LaneType<8>::type root(LaneType<8>::type x) { return _mm512_sqrt_pd(x); }
#endif

template <class V>
inline V larger(V a, V b) { return a > b ? a : b; }
template <class V>
inline V smaller(V a, V b) { return a < b ? a : b; }
template <class V>
inline V magnitude(V a) { return a < 0.0 ? -a : a; }

/// (s, c) <- rotated by the angle d (|d| small): sin d and cos d by Taylor series to d^7 and d^8.
template <class V>
inline void rotate(V& s, V& c, V d) {
  const V d2 = d * d;
  const V sd = d * (1.0 - d2 * (1.0 / 6.0) * (1.0 - d2 * (1.0 / 20.0) * (1.0 - d2 * (1.0 / 42.0))));
  const V cd = 1.0 - d2 * 0.5 * (1.0 - d2 * (1.0 / 12.0) * (1.0 - d2 * (1.0 / 30.0) * (1.0 - d2 * (1.0 / 56.0))));
  const V s2 = s * cd + c * sd;
  c = c * cd - s * sd;
  s = s2;
}

template <int N, Metrics kMetrics>
void simulate(const ProbePath& path, const double* alpha1A, const double* kk, ProbeResult* out) {
  constexpr bool all = kMetrics == Metrics::all;
  using V = typename LaneType<N>::type;
  const auto lanes = [](const double* p) {
    V v;
    if constexpr (N == 1) v = p[0];
    else for (int l = 0; l < N; ++l) v[l] = p[l];
    return v;
  };
  const Arm a;
  // constant parts of the dynamics
  const double b12 = (a.m2 * a.r2 + a.m3 * a.l2) * a.l1;  // couplings d_ij of the absolute link angles
  const double b13 = a.m3 * a.r3 * a.l1, b23 = a.m3 * a.r3 * a.l2;
  const double K33 = a.I3 + a.m3 * a.r3 * a.r3;
  const double K22 = a.I2 + a.m2 * a.r2 * a.r2 + a.m3 * a.l2 * a.l2 + K33;
  const double K11 = a.I1 + a.m1 * a.r1 * a.r1 + (a.m2 + a.m3) * a.l1 * a.l1 + K22;
  const double G1 = a.g * (a.m1 * a.r1 + (a.m2 + a.m3) * a.l1), G2 = a.g * (a.m2 * a.r2 + a.m3 * a.l2),
               G3 = a.g * a.m3 * a.r3;
  // start (NOTES.md, Appendix G), per lane in double
  double s0[3][N], c0[3][N], q0[3][N];
  for (int l = 0; l < N; ++l) {
    const double al = alpha1A[l];
    const double wx = path.p0[0] - a.l3 * std::cos(al), wy = path.p0[1] - a.l3 * std::sin(al);
    const double ct2 = (wx * wx + wy * wy - a.l1 * a.l1 - a.l2 * a.l2) / (2 * a.l1 * a.l2);
    const double st2 = std::sqrt(1 - ct2 * ct2);
    const double t2 = std::atan2(st2, ct2);
    const double t1 = std::atan2(wy, wx) - std::atan2(a.l2 * st2, a.l1 + a.l2 * ct2);
    const double t3 = al - t1 - t2;
    s0[0][l] = std::sin(t1), c0[0][l] = std::cos(t1);
    s0[1][l] = std::sin(t2), c0[1][l] = std::cos(t2);
    s0[2][l] = std::sin(t3), c0[2][l] = std::cos(t3);
    q0[0][l] = t1, q0[1][l] = t2, q0[2][l] = t3;
  }
  V s1 = lanes(s0[0]), c1 = lanes(c0[0]), s2 = lanes(s0[1]), c2 = lanes(c0[1]), s3 = lanes(s0[2]), c3 = lanes(c0[2]);
  const V k = lanes(kk);
  V w1 = s1 * 0.0, w2 = w1, w3 = w1;  // joint velocities
  V sum = w1;
  // the metrics (all): the joint angles, sums, peaks and the first and last samples' values
  V q1 = lanes(q0[0]), q2 = lanes(q0[1]), q3 = lanes(q0[2]);
  V sum_m = w1, sum_tt = w1, sum_pp = w1, sum_err = w1, tt_first = w1, pp_first = w1, tt_last = w1, pp_last = w1;
  V peak1 = w1, peak2 = w1, peak3 = w1, peak_p = w1, max_err2 = w1, min_w2 = w1 + 1e300, ke = w1;
  const double dt = path.dt;
  const std::size_t n = path.n;
  const double* acc = path.acc.data();
  const double* pos = path.pos.data();
  for (std::size_t i = 0;; ++i) {
    // kinematics: absolute angles 1, 12, 123 and the relative 23
    const V c12 = c1 * c2 - s1 * s2, s12 = s1 * c2 + c1 * s2;
    const V c23 = c2 * c3 - s2 * s3, s23 = s2 * c3 + c2 * s3;
    const V c123 = c12 * c3 - s12 * s3, s123 = s12 * c3 + c12 * s3;
    const V J02 = -a.l3 * s123, J12 = a.l3 * c123;
    const V J01 = J02 - a.l2 * s12, J11 = J12 + a.l2 * c12;
    const V J00 = J01 - a.l1 * s1, J10 = J11 + a.l1 * c1;
    const V o1 = w1, o2 = w1 + w2, o3 = o2 + w3;  // absolute angular velocities
    const V o11 = o1 * o1, o22 = o2 * o2, o33 = o3 * o3;
    const V jdx = -(a.l1 * c1 * o11 + a.l2 * c12 * o22 + a.l3 * c123 * o33);
    const V jdy = -(a.l1 * s1 * o11 + a.l2 * s12 * o22 + a.l3 * s123 * o33);
    // mass matrix (relative joint angles)
    const V e12 = b12 * c2, e13 = b13 * c23, e23 = b23 * c3;
    const V M33 = V{} + K33, M23 = K33 + e23, M13 = M23 + e13;
    const V M22 = K22 + 2.0 * e23, M12 = M22 + e12 + e13, M11 = K11 + 2.0 * (e12 + e13 + e23);
    // Coriolis: sum_j d_ij sin(phi_i - phi_j) o_j^2 on the absolute angles phi, summed from the tip
    const V f12 = b12 * s2, f13 = b13 * s23, f23 = b23 * s3;
    const V cc3 = f13 * o11 + f23 * o22;
    const V cc2 = cc3 + f12 * o11 - f23 * o33;
    const V cc1 = cc2 - f12 * o22 - f13 * o33;
    // gravity
    const V g3 = G3 * c123, g2 = g3 + G2 * c12, g1 = g2 + G1 * c1;
    const V h1 = cc1 + k * g1, h2 = cc2 + k * g2, h3 = cc3 + k * g3;
    // M^-1 = adj(M) / det(M)
    const V A11 = M22 * M33 - M23 * M23, A12 = M13 * M23 - M12 * M33, A13 = M12 * M23 - M13 * M22;
    const V A22 = M11 * M33 - M13 * M13, A23 = M12 * M13 - M11 * M23, A33 = M11 * M22 - M12 * M12;
    const V inv = 1.0 / (M11 * A11 + M12 * A12 + M13 * A13);
    const V P11 = A11 * inv, P12 = A12 * inv, P13 = A13 * inv, P22 = A22 * inv, P23 = A23 * inv, P33 = A33 * inv;
    // B = J M^-1 (2x3), u = M^-1 h, S = J M^-1 J^T
    const V B00 = J00 * P11 + J01 * P12 + J02 * P13, B01 = J00 * P12 + J01 * P22 + J02 * P23,
            B02 = J00 * P13 + J01 * P23 + J02 * P33;
    const V B10 = J10 * P11 + J11 * P12 + J12 * P13, B11 = J10 * P12 + J11 * P22 + J12 * P23,
            B12 = J10 * P13 + J11 * P23 + J12 * P33;
    const V u1 = P11 * h1 + P12 * h2 + P13 * h3, u2 = P12 * h1 + P22 * h2 + P23 * h3,
            u3 = P13 * h1 + P23 * h2 + P33 * h3;
    const V S00 = B00 * J00 + B01 * J01 + B02 * J02, S01 = B00 * J10 + B01 * J11 + B02 * J12,
            S11 = B10 * J10 + B11 * J11 + B12 * J12;
    const V r0 = (acc[2 * i] - jdx) + (J00 * u1 + J01 * u2 + J02 * u3);
    const V r1 = (acc[2 * i + 1] - jdy) + (J10 * u1 + J11 * u2 + J12 * u3);
    const V id = 1.0 / (S00 * S11 - S01 * S01);
    const V L0 = (S11 * r0 - S01 * r1) * id, L1 = (S00 * r1 - S01 * r0) * id;
    const V a1 = B00 * L0 + B10 * L1 - u1, a2 = B01 * L0 + B11 * L1 - u2, a3 = B02 * L0 + B12 * L1 - u3;
    // torques and E
    const V t1 = M11 * a1 + M12 * a2 + M13 * a3 + cc1 + g1;
    const V t2 = M12 * a1 + M22 * a2 + M23 * a3 + cc2 + g2;
    const V t3 = M13 * a1 + M23 * a2 + M33 * a3 + cc3 + g3;
    const V tt = t1 * t1 + t2 * t2 + t3 * t3;
    sum += root(tt);
    if constexpr (all) {
      // tau^T M^-1 tau, the torque peaks, J J^T's determinant, the powers and the tip's error
      sum_m += root(P11 * t1 * t1 + P22 * t2 * t2 + P33 * t3 * t3 + 2.0 * (P12 * t1 * t2 + P13 * t1 * t3 + P23 * t2 * t3));
      peak1 = larger(peak1, magnitude(t1)), peak2 = larger(peak2, magnitude(t2)), peak3 = larger(peak3, magnitude(t3));
      const V jj00 = J00 * J00 + J01 * J01 + J02 * J02, jj01 = J00 * J10 + J01 * J11 + J02 * J12,
              jj11 = J10 * J10 + J11 * J11 + J12 * J12;
      min_w2 = smaller(min_w2, jj00 * jj11 - jj01 * jj01);
      const V p1 = t1 * w1, p2 = t2 * w2, p3 = t3 * w3;
      const V pp = p1 * p1 + p2 * p2 + p3 * p3;
      peak_p = larger(peak_p, larger(magnitude(p1), larger(magnitude(p2), magnitude(p3))));
      sum_tt += tt, sum_pp += pp;
      if (i == 0) tt_first = tt, pp_first = pp;
      const V ex = J10 - pos[2 * i], ey = -J00 - pos[2 * i + 1];  // tip = (J10, -J00)
      const V err2 = ex * ex + ey * ey;
      max_err2 = larger(max_err2, err2);
      sum_err += root(err2);
      if (i + 1 == n) {
        tt_last = tt, pp_last = pp;
        ke = 0.5 * (w1 * (M11 * w1 + M12 * w2 + M13 * w3) + w2 * (M12 * w1 + M22 * w2 + M23 * w3) +
                    w3 * (M13 * w1 + M23 * w2 + M33 * w3));
      }
    }
    if (i + 1 == n) break;
    // semi-implicit Euler
    w1 += dt * a1, w2 += dt * a2, w3 += dt * a3;
    const V d1 = dt * w1, d2 = dt * w2, d3 = dt * w3;
    rotate(s1, c1, d1);
    rotate(s2, c2, d2);
    rotate(s3, c3, d3);
    if constexpr (all) q1 += d1, q2 += d2, q3 += d3;
  }
  const double nn = static_cast<double>(n);
  const V E = sum / nn;
  V E_M = E, min_w = E, torque_sq = E, power_sq = E, max_err = E, mean_err = E, alpha = E, qd_max = E;
  if constexpr (all) {
    E_M = sum_m / nn;
    min_w = root(min_w2);
    torque_sq = dt * (sum_tt - 0.5 * (tt_first + tt_last));
    power_sq = dt * (sum_pp - 0.5 * (pp_first + pp_last));
    max_err = root(max_err2);
    mean_err = sum_err / nn;
    alpha = q1 + q2 + q3;
    qd_max = larger(magnitude(w1), larger(magnitude(w2), magnitude(w3)));
  }
  const auto lane = [](const V& v, int l) {
    if constexpr (N == 1) return v;
    else return static_cast<double>(v[l]);
  };
  for (int l = 0; l < N; ++l) {
    ProbeResult& r = out[l];
    r = ProbeResult{};
    r.E = lane(E, l);
    if constexpr (all) {
      r.E_M = lane(E_M, l);
      r.tau_inf[0] = lane(peak1, l), r.tau_inf[1] = lane(peak2, l), r.tau_inf[2] = lane(peak3, l);
      r.min_manipulability = lane(min_w, l);
      r.torque_sq_integral = lane(torque_sq, l), r.power_sq_integral = lane(power_sq, l);
      r.max_tracking_error = lane(max_err, l), r.mean_tracking_error = lane(mean_err, l);
      r.final_alpha = lane(alpha, l);
      r.peak_joint_power = lane(peak_p, l);
      r.end_qd_max = lane(qd_max, l);
      r.end_kinetic_energy = lane(ke, l);
    }
  }
}

/// The run at width N with the metrics asked for.
template <int N>
void run(Metrics metrics, const ProbePath& path, const double* alpha1A, const double* k, ProbeResult* out) {
  if (metrics == Metrics::all) simulate<N, Metrics::all>(path, alpha1A, k, out);
  else simulate<N, Metrics::E>(path, alpha1A, k, out);
}

}  // namespace
}  // namespace ks_probe
#endif
