// planar_chain_run: the switch on the joint count that picks the fixed-size run
// (methods/chain/planar_run_impl.hpp, instantiated in planar_chain_run_3_5.cpp and _6_8.cpp).
#include "methods/chain/planar_run.hpp"

#include <stdexcept>
#include <string>

namespace ks {

static_assert(kMaxJoints == 8, "planar_chain_run instantiates N = 3 .. 8");

TrajectoryMetrics planar_chain_run(const Chain& chain, const ChainTask& task, const VecN& q_start,
                                   const TrajectoryOptions& o, const std::optional<Profile1>& alpha,
                                   ChainHistory* history) {
  switch (chain.dof()) {
    case 3: return planar_chain_run_n<3>(chain, task, q_start, o, alpha, history);
    case 4: return planar_chain_run_n<4>(chain, task, q_start, o, alpha, history);
    case 5: return planar_chain_run_n<5>(chain, task, q_start, o, alpha, history);
    case 6: return planar_chain_run_n<6>(chain, task, q_start, o, alpha, history);
    case 7: return planar_chain_run_n<7>(chain, task, q_start, o, alpha, history);
    case 8: return planar_chain_run_n<8>(chain, task, q_start, o, alpha, history);
    default: break;
  }
  throw std::invalid_argument("planar_chain_run: " + std::to_string(chain.dof()) +
                              " joints; the fixed-size run takes 3 to 8");
}

}  // namespace ks
