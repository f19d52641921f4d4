#pragma once
// One run: (model and task constants, typed run spec, workspace) -> typed outcome. A run is a pure
// function of its spec (no shared state), which is what makes results independent of the thread
// count and resume exact.
#include <memory>

#include "schema/run_spec.hpp"
#include "study/study.hpp"

namespace ks {

/// The constants a run executes against: the study's robot and task (not copied).
struct Scenario {
  const PlanarArm3* robot = nullptr;  ///< the seed's closed-form 3R (trajectory runs when chain is null)
  const StudyTask* task = nullptr;
  const Chain* chain = nullptr;       ///< the study's chain robot; null: the closed-form 3R
  const Chain* ik_chain = nullptr;    ///< the chain of the position / pose IK problems (chain, or the 3R as one)
  const Chain* base_chain = nullptr;  ///< the chain robot in its base frame (motion runs; null: the 3R)
  const World* world = nullptr;       ///< the study's obstacles and link radii (motion runs; may be null)
  static Scenario of(const Study& s) {
    return {&s.robot, &s.task, s.chain.get(), s.arm_chain ? s.arm_chain.get() : s.chain.get(),
            s.base_chain ? s.base_chain.get() : s.chain.get(), &s.world};
  }
};

/// Per-thread buffers reused from run to run (no allocation per time step or iteration).
class RunWorkspace {
 public:
  RunWorkspace();
  ~RunWorkspace();
  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

/// Execute one run. `history_stride`: 0 = no history, N = every N-th sample (trajectory) or
/// iteration (ik). Never throws on bad numbers: trouble is the outcome's status.
RunOutcome execute(const Scenario& scenario, const RunSpec& run, int history_stride, RunWorkspace& workspace);

/// The run itself when it may share SIMD lanes with others (a closed-form 3R trajectory run that
/// samples its path, on the study's task as written), else null: execute_batch's rule.
const TrajectoryRun* lane_run(const Scenario& scenario, const RunSpec& run);

/// Execute runs[0..n) into out[0..n), wall_s[i] the seconds spent on run i (runs that share lanes
/// share their time equally). Closed-form 3R trajectory runs that can share SIMD lanes (the same
/// inertia form, dt, method and integrator: lane_compatible) run up to `lanes` at a time
/// (simulate_lanes; `lanes` is capped at max_lanes()); every other run as execute(). Each out[i]
/// equals execute(scenario, runs[i], ...) bit for bit, whatever `lanes` and whatever the other runs.
void execute_batch(const Scenario& scenario, const RunSpec* runs, std::size_t n, int history_stride, int lanes,
                   RunWorkspace& workspace, RunOutcome* out, double* wall_s);

}  // namespace ks
