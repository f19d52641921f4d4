// Instantiations of planar_chain_run_n for N = 3 .. 5 (methods/chain/planar_run_impl.hpp); the joint
// counts are split over two files so that they compile in parallel.
#include "methods/chain/planar_run_impl.hpp"

namespace ks {

template TrajectoryMetrics planar_chain_run_n<3>(const Chain&, const ChainTask&, const VecN&, const TrajectoryOptions&,
                                                 const std::optional<Profile1>&, ChainHistory*);
template TrajectoryMetrics planar_chain_run_n<4>(const Chain&, const ChainTask&, const VecN&, const TrajectoryOptions&,
                                                 const std::optional<Profile1>&, ChainHistory*);
template TrajectoryMetrics planar_chain_run_n<5>(const Chain&, const ChainTask&, const VecN&, const TrajectoryOptions&,
                                                 const std::optional<Profile1>&, ChainHistory*);

}  // namespace ks
