#pragma once
// One motion run (kind = "motion"): the executor's part for rest-to-rest point-to-point motions.
#include "runner/execute.hpp"

namespace ks {

/// Execute motion run `run` on the scenario's chain (its base frame) and [world]: the motion
/// problem of seed 002 Chapter 7 solved by SLSQP (or, run.solve false, its initial cubic evaluated).
/// `stride`: 0 = no history, N = every N-th sample and the last (t [s], q, qd, tau). Never throws:
/// a problem that cannot be set up or numbers that are not finite end with status failure (NaN
/// metrics), limits or margins broken at the end infeasible, a negative clearance collision.
RunOutcome run_motion(const Scenario& sc, const MotionRun& run, int stride);

}  // namespace ks
