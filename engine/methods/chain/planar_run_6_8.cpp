// Instantiations of planar_chain_run_n for N = 6 .. 8 (methods/chain/planar_run_impl.hpp); the joint
// counts are split over two files so that they compile in parallel.
#include "methods/chain/planar_run_impl.hpp"

namespace ks {

template TrajectoryMetrics planar_chain_run_n<6>(const Chain&, const ChainTask&, const VecN&, const TrajectoryOptions&,
                                                 const std::optional<Profile1>&, ChainHistory*);
template TrajectoryMetrics planar_chain_run_n<7>(const Chain&, const ChainTask&, const VecN&, const TrajectoryOptions&,
                                                 const std::optional<Profile1>&, ChainHistory*);
template TrajectoryMetrics planar_chain_run_n<8>(const Chain&, const ChainTask&, const VecN&, const TrajectoryOptions&,
                                                 const std::optional<Profile1>&, ChainHistory*);

}  // namespace ks
