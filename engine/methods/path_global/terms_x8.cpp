// The 3R path-global objective's terms and samples in 8 lanes of AVX-512 (compiled with -mavx512f
// -mavx512dq; called only when the processor has them: supported_lanes(), methods/closed_form/lanes.hpp).
// GCC 12 reports its own _mm512_undefined_pd() in the AVX-512 intrinsics (here in _mm512_sqrt_pd) as
// uninitialized (GCC bug 105593, fixed in GCC 13): a false positive.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif
#include "methods/path_global/objective_3r.hpp"

namespace ks {

void terms_3r_x8(const Terms3RInput& in, std::size_t first, std::size_t end, bool partials, double* term,
                 double* const partial[3]) {
  terms_3r<Lanes<8>>(in, first, end, partials, term, partial);
}

void samples_3r_x8(const Terms3RInput& in, std::size_t first, std::size_t end, Sample3RBlock& out) {
  samples_3r<Lanes<8>>(in, first, end, out);
}

}  // namespace ks
