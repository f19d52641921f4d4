#pragma once
// Trajectory runs in SIMD lanes: 4 (AVX2) or 8 (AVX-512) runs of the closed-form 3R computed side by
// side on one core, each with exactly the results simulate() gives it alone (the same operations in
// the same order in every lane: methods/closed_form/kernel.hpp), whatever runs share its lanes and
// whatever the lane width. Lanes of runs that stop early (singular, diverged) are masked; so are the
// lanes a batch does not fill.
//
// How a caller batches (e.g. the sweep's workers): collect up to max_lanes() runs that share the arm
// (the study's robot with the run's inertia form: PlanarArm3::inertia_form is part of `arm`), the
// sampled path (the same SampledPath, i.e. the same dt) and lane_compatible() options; runs that
// differ in any of these go to different calls. Everything else may differ per run: alpha1A, elbow,
// k, null_damping, vertex_alpha, torque_bound, singular_tolerance, and the history stride. Undersampled
// runs (samples_path false) are not simulated at all and never enter a batch. A batch of fewer runs
// than lanes is fine (the rest is masked), but costs as much as a full one.
#include "methods/base/trajectory.hpp"

namespace ks {

/// The widest lane count this processor runs with this build: 8 (AVX-512F and DQ), 4 (AVX2) or 1.
int supported_lanes();
/// supported_lanes(), or less when limited by limit_lanes().
int max_lanes();
/// Limits max_lanes() to `lanes` (1, 4 or 8; 0 removes the limit), e.g. to compare lane widths in
/// tests and benchmarks or to run the single-run path. Process-wide; thread-safe.
void limit_lanes(int lanes);

/// Whether runs with options a and b may share lanes: the same method, integrator, dt and end condition.
bool lane_compatible(const TrajectoryOptions& a, const TrajectoryOptions& b);

/// Runs `count` (1 .. lanes) lane-compatible runs at once in `lanes` lanes (1, 4 or 8, at most
/// supported_lanes()). results[i] is simulate(arm, sampled, options[i], histories[i]) bit for bit,
/// and so are histories[i] when `histories` and histories[i] are not null. Throws
/// std::invalid_argument for what simulate() throws on, for runs that are not lane_compatible with
/// options[0], and for a lane count this processor or build does not run.
void simulate_lanes(int lanes, const PlanarArm3& arm, const SampledPath& sampled, const TrajectoryOptions* options,
                    int count, TrajectoryMetrics* results, TrajectoryHistory* const* histories = nullptr);

}  // namespace ks
