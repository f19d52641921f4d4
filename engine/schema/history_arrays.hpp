#pragma once
// The history arrays of each kind: the only place their names, units and shapes are declared. A
// run's history is a set of arrays with one row per recorded sample (trajectory: a time step; ik:
// an iterate) and a fixed number of columns. The executor fills them in this order; the memory
// bound of a run's history, `kinesweep schema` and FORMAT.md read them from here.
#include <cstddef>
#include <string>
#include <vector>

#include "schema/params.hpp"

namespace ks {

/// One history array of a run.
struct HistoryArrayDef {
  std::string name;         ///< the dataset name under /histories/<run>
  std::string unit;         ///< stored unit: one for every column, or one per column joined by ", "
  std::size_t columns = 1;  ///< values per row
  std::string description;
};

/// The history arrays of a trajectory run of `robot` (t, q, qd, qdd, tau, x, alpha), in the order
/// the executor writes them.
std::vector<HistoryArrayDef> trajectory_history_arrays(const RobotShape& robot);
/// The history arrays of a motion run of `robot` (t, q, qd, tau at its samples), in the order the
/// executor writes them.
std::vector<HistoryArrayDef> motion_history_arrays(const RobotShape& robot);
/// The history arrays of an ik run of `problem` on `robot` (the arm of the chain problems; the seed's
/// problems have their own 3 joints): k, q, F, norm_F, step, lambda.
std::vector<HistoryArrayDef> ik_history_arrays(IkProblem problem, const RobotShape& robot);

/// Values in one row of every array (the sum of their columns).
std::size_t values_per_row(const std::vector<HistoryArrayDef>& arrays);

/// Rows a trajectory run keeps in memory for its history under stride `stride` (>= 1) on a path of
/// `duration` [s] sampled every `dt` [s]: every stride-th sample and the last one.
double history_rows(double duration, double dt, int stride);

/// The most memory one run's history may take while it runs [bytes]. A study whose trajectory runs
/// would need more is refused before it starts (use a coarser `histories = "every=N"` or "none").
inline constexpr double kMaxHistoryBytesPerRun = 64.0 * 1024 * 1024;
/// Bytes a run's history takes in memory, about rows x values x 8 bytes x 4: the buffers the run
/// fills, the arrays handed to the store, their encoded chunks and the writer's queue (measured on
/// a 3R run of 1.3e5 to 3e6 rows: 2.9 to 4.3 times the raw values).
double history_bytes_in_memory(double rows, std::size_t values_per_row);

}  // namespace ks
