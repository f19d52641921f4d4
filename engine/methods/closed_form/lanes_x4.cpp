// The trajectory kernel in 4 lanes of AVX2 (compiled with -mavx2 whatever the rest of the build).
#include "methods/closed_form/kernel.hpp"

namespace ks::kernel {

void run_x4(const Shared& s, const Runs& in, Sums* out) { run<Lanes<4>>(s, in, out); }

}  // namespace ks::kernel
