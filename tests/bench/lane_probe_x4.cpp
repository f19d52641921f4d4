// The lane probe (lane_probe.hpp) in 4 lanes; compiled with -mavx2 added (tests/bench/CMakeLists.txt).
#define KS_LANE_PROBE_IMPL
#include "lane_probe.hpp"

namespace ks_probe {

void run_x4(Metrics metrics, const ProbePath& path, const double* alpha1A, const double* k, ProbeResult* out) {
  run<4>(metrics, path, alpha1A, k, out);
}

}  // namespace ks_probe
