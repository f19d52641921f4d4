#pragma once
// The set-up and the results of a batch of runs for the loop of methods/closed_form/kernel.hpp, shared
// by simulate() (one run, the loop over double) and simulate_lanes() (4 or 8 runs in SIMD lanes).
#include <optional>
#include <vector>

#include "methods/closed_form/kernel.hpp"

namespace ks::kernel {

struct Batch {
  Shared shared;
  Runs runs;
  int count = 0;            ///< runs in the batch (lanes 0 .. count - 1)
  bool any_active = false;  ///< some run has a reachable start
  std::optional<DynamicsCoefficients> dyn;
  std::optional<Profile1> alpha_unit;  ///< vertex_alpha: each segment rises by exactly 1
  std::vector<double> alpha_rise;      ///< vertex_alpha: see Runs::alpha_rise
  std::vector<double> alpha_from;      ///< vertex_alpha: see Runs::alpha_from
  const TrajectoryOptions* options = nullptr;  ///< the runs' options (lanes 0 .. count - 1)
  HistoryView views[kMaxLanes];
};

/// Checks the runs (std::invalid_argument as simulate() throws it: a path sampled at another dt,
/// vertex_alpha with the wrong number of vertex orientations, runs that cannot share lanes), prepares
/// the histories, solves each start (inverse_kinematics) and fills `b` for `lanes` lanes.
void prepare(Batch& b, int lanes, const PlanarArm3& arm, const SampledPath& sampled, const TrajectoryOptions* options,
             int count, TrajectoryHistory* const* histories);
/// The metrics of run i of the batch from the kernel's sums (unreachable starts: not_simulated).
TrajectoryMetrics finish(const Batch& b, int i, const Sums& sums);

}  // namespace ks::kernel
