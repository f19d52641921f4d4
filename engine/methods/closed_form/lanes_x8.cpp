// The trajectory kernel in 8 lanes of AVX-512 (compiled with -mavx512f -mavx512dq; called only when
// the processor has both: supported_lanes()).
// GCC 12 reports its own _mm512_undefined_pd() in the AVX-512 intrinsics as maybe uninitialized
// (GCC bug 105593, fixed in GCC 13): a false positive.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include "methods/closed_form/kernel.hpp"

namespace ks::kernel {

void run_x8(const Shared& s, const Runs& in, Sums* out) { run<Lanes<8>>(s, in, out); }

}  // namespace ks::kernel
