// The 3R path-global objective's terms and samples in 4 lanes of AVX2 (compiled with -mavx2; called
// only when the processor has them: supported_lanes(), methods/closed_form/lanes.hpp).
#include "methods/path_global/objective_3r.hpp"

namespace ks {

void terms_3r_x4(const Terms3RInput& in, std::size_t first, std::size_t end, bool partials, double* term,
                 double* const partial[3]) {
  terms_3r<Lanes<4>>(in, first, end, partials, term, partial);
}

void samples_3r_x4(const Terms3RInput& in, std::size_t first, std::size_t end, Sample3RBlock& out) {
  samples_3r<Lanes<4>>(in, first, end, out);
}

}  // namespace ks
