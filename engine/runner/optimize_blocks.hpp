#pragma once
// Optimisation blocks ([[optimize]]): a study's OptimizeBlock -> an opt::Problem (one
// evaluation = the block's runs with the variables' columns set to x; the weighted objective averaged
// over them; failed runs get a deterministic penalty; the start's reach margin as the constraint) ->
// opt::optimize -> a store::OptimizationRecord (/optimizations/<name>).
#include <atomic>
#include <iosfwd>
#include <string>
#include <vector>

#include "optimize/optimize.hpp"
#include "store/store.hpp"
#include "study/study.hpp"

namespace ks {

struct OptimizeRunOptions {
  int threads = 0;  ///< local polishes (and evaluation-set runs, landscape cells) in parallel; 0: all cores
  /// polish_from: read the landscape block's cells from this results file (when all its runs are done);
  /// null (or not done): evaluate the cells here.
  const store::ResultsReader* cells = nullptr;
  /// When set (e.g. by SIGINT): the running block ends before its next evaluation and stores what it
  /// has; the later blocks do not start.
  const std::atomic<bool>* stop = nullptr;
};

/// Reach margin of the start [-]: |cos theta2| - 1 of the analytic IK at point p for orientation alpha
/// (<= 0: reachable; the seed's IK has no real solution when > 0).
double reach_margin(const PlanarArm3& arm, const Eigen::Vector2d& p, double alpha);

/// The problem of optimisation block `index` of the study (thread-safe objective). Its objective
/// refers to the study (robot, task, blocks): the study must outlive the problem.
opt::Problem make_problem(const Study& study, std::size_t index);

/// The `best` lowest-objective cells of the block `polish_from` names, as local starts (ties: run order).
std::vector<opt::Start> best_cells(const Study& study, std::size_t index, const OptimizeRunOptions& options);

struct OptimizeResult {
  opt::Summary summary;
  store::OptimizationRecord record;
  double value_at_thesis = 0.0;  ///< presets: the objective at the thesis' printed optimum (NaN otherwise)
};

/// Run optimisation block `index`.
OptimizeResult run_optimization(const Study& study, std::size_t index, const OptimizeRunOptions& options);

/// Print one block's result: stages, the best point (angles in deg) and objective, and for a preset
/// the thesis' optimum and E beside kinesweep's.
void print_optimization(std::ostream& os, const Study& study, std::size_t index, const OptimizeResult& r);

/// Run every optimisation block of the study in file order, write each to `writer` (when given) and
/// print it to `os` (when given). Returns the results (fewer than the blocks when options.stop ended
/// them: the last one's summary is then `stopped`; a block stopped before any evaluation is not written).
std::vector<OptimizeResult> run_optimizations(const Study& study, store::ResultsWriter* writer,
                                              const OptimizeRunOptions& options, std::ostream* os);

}  // namespace ks
