// simulate_lanes(): the batch set-up (methods/closed_form/run.cpp), the kernel at the lane width asked for,
// and run-time dispatch by processor.
#include "methods/closed_form/lanes.hpp"

#include <atomic>
#include <stdexcept>
#include <string>

#include "methods/closed_form/batch.hpp"

namespace ks {

namespace kernel {
// The instances of run<T> for 4 and 8 lanes, each in its own translation unit built for its vectors
// (when the compiler takes -mavx2, and -mavx512f -mavx512dq -mfma: engine/CMakeLists.txt).
void run_x4(const Shared& s, const Runs& in, Sums* out);
void run_x8(const Shared& s, const Runs& in, Sums* out);
}  // namespace kernel

namespace {
std::atomic<int> lane_limit{0};

int detect_lanes() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_cpu_init();
#if defined(KS_LANES_X8)
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq")) return 8;
#endif
#if defined(KS_LANES_X4)
  if (__builtin_cpu_supports("avx2")) return 4;
#endif
#endif
  return 1;
}
/// The kernel at `lanes` lanes (supported_lanes() admits only the widths this build has).
void run_width(int lanes, const kernel::Shared& s, const kernel::Runs& in, kernel::Sums* out) {
#if defined(KS_LANES_X8)
  if (lanes == 8) kernel::run_x8(s, in, out);
#endif
#if defined(KS_LANES_X4)
  if (lanes == 4) kernel::run_x4(s, in, out);
#endif
  if (lanes == 1) kernel::run<double>(s, in, out);
}

/// 8 lanes take the Reduce::last entries at a lane's last sample only; a lane that stopped before
/// adding a sample (singular, diverged) had moved past its last one. Those lanes alone run again, the
/// same operations in the same order, with their last sample's index known, and their sums replace
/// the first pass's (equal to them but for those entries). No history is written twice.
void replay_pending(int lanes, const kernel::Batch& b, int count, kernel::Sums* sums) {
  if (b.shared.last_every_sample) return;  // taken at every sample: nothing pending
  kernel::Runs again = b.runs;
  bool any = false;
  for (int l = 0; l < kernel::kMaxLanes; ++l) {
    const bool pending = l < count && sums[l].last_pending;
    again.active[l] = pending ? b.runs.active[l] : 0.0;
    again.last_at[l] = pending ? static_cast<double>(sums[l].done - 1) : -1.0;
    again.history[l] = nullptr;
    any = any || pending;
  }
  if (!any) return;
  again.any_history = false;
  again.replay = true;
  kernel::Sums second[kernel::kMaxLanes];
  run_width(lanes, b.shared, again, second);
  for (int l = 0; l < count; ++l)
    if (sums[l].last_pending) sums[l] = second[l], sums[l].last_pending = false;
}

}  // namespace

int supported_lanes() {
  static const int lanes = detect_lanes();
  return lanes;
}

int max_lanes() {
  const int limit = lane_limit.load(std::memory_order_relaxed);
  const int lanes = supported_lanes();
  if (limit <= 0 || limit >= lanes) return lanes;
  return limit >= 4 ? 4 : 1;
}

void limit_lanes(int lanes) {
  if (lanes != 0 && lanes != 1 && lanes != 4 && lanes != 8)
    throw std::invalid_argument("limit_lanes: " + std::to_string(lanes) + " lanes (1, 4, 8 or 0 for no limit)");
  lane_limit.store(lanes, std::memory_order_relaxed);
}

bool lane_compatible(const TrajectoryOptions& a, const TrajectoryOptions& b) {
  return a.method == b.method && a.integrator == b.integrator && a.dt == b.dt &&
         a.closed_loop() == b.closed_loop() && a.on_violation == b.on_violation && a.end == b.end &&
         (a.end == EndState::free || (a.end_window == b.end_window && a.end_gain == b.end_gain));
}

void simulate_lanes(int lanes, const PlanarArm3& arm, const SampledPath& sampled, const TrajectoryOptions* options,
                    int count, TrajectoryMetrics* results, TrajectoryHistory* const* histories) {
  if ((lanes != 1 && lanes != 4 && lanes != 8) || lanes > supported_lanes())
    throw std::invalid_argument("simulate_lanes: " + std::to_string(lanes) + " lanes; this processor runs " +
                                std::to_string(supported_lanes()));
  kernel::Batch b;
  kernel::prepare(b, lanes, arm, sampled, options, count, histories);
  kernel::Sums sums[kernel::kMaxLanes];
  if (b.any_active) {
    // 8 lanes take the Reduce::last entries at each lane's last sample only (SampleSums::last_at_end,
    // with a replay of runs that stop before adding a sample), unless the thread's last batch had such
    // a run (one of a study's many, as where torque bounds stop most runs): then at every sample. The
    // same bits either way.
    thread_local bool stops_seen = false;
    b.shared.last_every_sample = lanes == 8 && stops_seen;
    run_width(lanes, b.shared, b.runs, sums);
    stops_seen = false;
    for (int l = 0; l < count; ++l) stops_seen = stops_seen || sums[l].last_pending;
    replay_pending(lanes, b, count, sums);
  }
  for (int i = 0; i < count; ++i) results[i] = kernel::finish(b, i, sums[i]);
}

}  // namespace ks
