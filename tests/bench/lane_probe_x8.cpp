// The lane probe (lane_probe.hpp) in 8 lanes; compiled with -mavx512f -mavx512dq -mfma added (tests/bench/CMakeLists.txt).
// GCC 12's _mm512_sqrt_pd reads an intentionally undefined vector (_mm512_undefined_pd) and
// -Wuninitialized reports it (GCC bug 105593, fixed in GCC 13): a false positive.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif
#define KS_LANE_PROBE_IMPL
#include "lane_probe.hpp"

namespace ks_probe {

void run_x8(Metrics metrics, const ProbePath& path, const double* alpha1A, const double* k, ProbeResult* out) {
  run<8>(metrics, path, alpha1A, k, out);
}

}  // namespace ks_probe
