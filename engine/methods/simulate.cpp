// simulate(): each method's entry. The local and vertex methods run the per-sample loop of their
// model (methods/closed_form/run.cpp for the seed's 3R, methods/chain/trajectory.cpp for any chain);
// the path-global method (global_spline) solves for the whole path (methods/path_global/). This file
// is the methods room's top floor: it includes the rooms below, none of them includes it.
#include "methods/base/trajectory.hpp"
#include "methods/chain/trajectory.hpp"
#include "methods/path_global/chain.hpp"
#include "methods/path_global/solve_closed_form.hpp"

namespace ks {

TrajectoryMetrics simulate(const PlanarArm3& arm, const SampledPath& sampled, const TrajectoryOptions& o,
                           TrajectoryHistory* history) {
  if (o.method == TrajectoryMethod::global_spline) return solve_global_spline(arm, sampled, o, history);
  return simulate_local(arm, sampled, o, history);
}

TrajectoryMetrics simulate(const PlanarArm3& arm, const Path2& path, const TrajectoryOptions& o,
                           TrajectoryHistory* history) {
  return simulate(arm, SampledPath(path, o.dt), o, history);
}

TrajectoryMetrics simulate(const Chain& chain, const ChainTask& task, const VecN& q0, const TrajectoryOptions& o,
                           ChainHistory* history) {
  if (o.method == TrajectoryMethod::global_spline) return solve_global_spline_chain(chain, task, q0, o, history);
  return simulate_local(chain, task, q0, o, history);
}

}  // namespace ks
