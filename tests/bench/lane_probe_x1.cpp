// The lane probe (lane_probe.hpp): the path, the one-lane run and the processor checks; compiled
// with the flags of the rest of the binary.
#define KS_LANE_PROBE_IMPL
#include "lane_probe.hpp"

namespace ks_probe {

ProbePath seed_square_path(double dt) {
  // vertices 1 (1.5, 1.5) -> 2 (1.5, 2.0) -> 3 (2.0, 2.0) -> 4 (2.0, 1.5) -> 1, 0.5 s each; each
  // segment p0 + D (10 s^3 - 15 s^4 + 6 s^5), s = tau / T; t <= 0.5 is segment A, 0.5 < t <= 1 B, ...
  const double vx[5] = {1.5, 1.5, 2.0, 2.0, 1.5}, vy[5] = {1.5, 2.0, 2.0, 1.5, 1.5};
  const double T = 0.5, total = 2.0;
  ProbePath p;
  p.dt = dt;
  p.n = static_cast<std::size_t>(std::floor(total / dt + 1e-9)) + 1;
  p.pos.resize(2 * p.n);
  p.acc.resize(2 * p.n);
  for (std::size_t i = 0; i < p.n; ++i) {
    const double t = static_cast<double>(i) * dt;
    int seg = 0;
    while (seg < 3 && t > T * (seg + 1)) ++seg;
    const double s = (t - T * seg) / T;
    const double f = (60 * s - 180 * s * s + 120 * s * s * s) / (T * T);
    const double b = s * s * s * (10 - 15 * s + 6 * s * s);
    p.pos[2 * i] = vx[seg] + (vx[seg + 1] - vx[seg]) * b;
    p.pos[2 * i + 1] = vy[seg] + (vy[seg + 1] - vy[seg]) * b;
    p.acc[2 * i] = (vx[seg + 1] - vx[seg]) * f;
    p.acc[2 * i + 1] = (vy[seg + 1] - vy[seg]) * f;
  }
  return p;
}

void run_x1(Metrics metrics, const ProbePath& path, const double* alpha1A, const double* k, ProbeResult* out) {
  run<1>(metrics, path, alpha1A, k, out);
}

#ifdef KS_PROBE_X4
bool runs_x4() { return __builtin_cpu_supports("avx2"); }
#else
bool runs_x4() { return false; }
void run_x4(Metrics, const ProbePath&, const double*, const double*, ProbeResult*) {}
#endif
#ifdef KS_PROBE_X8
bool runs_x8() { return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq"); }
#else
bool runs_x8() { return false; }
void run_x8(Metrics, const ProbePath&, const double*, const double*, ProbeResult*) {}
#endif

}  // namespace ks_probe
