// The engine's IK problems, compiled once (see ik/solve.hpp).
#include "ik/solve_impl.hpp"

namespace ks::ik {

template void solve(const ScaraPosition&, const Vec<3>&, const Options&, Summary<3, 3>&);
template void solve(const PlanarPose&, const Vec<3>&, const Options&, Summary<3, 3>&);
template void solve(const PlanarPosition&, const Vec<3>&, const Options&, Summary<3, 2>&);
template struct Summary<3, 3>;
template struct Summary<3, 2>;
template std::ostream& operator<<(std::ostream&, const Summary<3, 3>&);
template std::ostream& operator<<(std::ostream&, const Summary<3, 2>&);

}  // namespace ks::ik
