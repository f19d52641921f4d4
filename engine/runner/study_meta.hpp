#pragma once
// A study's results-file metadata (store::StoreMeta): what each run kind means (/kinds), its
// Saltelli designs (/designs), the study's and robot's text, and the history policy's memory check.
#include <string>
#include <vector>

#include "schema/history_arrays.hpp"
#include "store/store.hpp"
#include "study/study.hpp"

namespace ks {

/// "" when every trajectory run of `study` keeps a history of at most kMaxHistoryBytesPerRun in
/// memory under `histories`; else why not, naming the block, the run's rows and bytes, and the
/// coarsest policy that fits ("every=N"). Checked before a results file is created or resumed.
std::string history_memory_problem(const Study& study, const HistoryPolicy& histories);

/// The meaning of each run kind the study's blocks use, as its results file records it (/kinds):
/// statuses (enum order), good_statuses, ranking (objective, then tie), key_metrics, objectives,
/// history_arrays (and, trajectory, history_units).
std::vector<store::KindMeta> kind_meta(const Study& study);

/// The StoreMeta of a study's results file (or shard) whose runs are written with `histories`.
store::StoreMeta store_meta(const Study& study, const HistoryPolicy& histories);

}  // namespace ks
