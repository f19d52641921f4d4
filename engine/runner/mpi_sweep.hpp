#pragma once
// Distributed sweeps over MPI (`mpirun -np N kinesweep run STUDY.toml`, `srun kinesweep run ...`).
//
// Design (details in mpi_sweep.cpp):
// - every rank writes its own shard `<out>.rank<r>.h5`: a normal, crash-safe results file of the
//   same study and schema (n_runs = all runs) holding only the runs that rank computed;
// - load balance: rank 0 hands out run ids dynamically (a coordinator thread answers chunk requests;
//   chunks shrink as the work runs out, guided scheduling), each rank runs its chunks in its own TBB
//   pipeline (SweepOptions::source), requesting the next chunk before the current one is used up;
// - at the end rank 0 merges final file + shards into `<out>` in run-id order (histories re-encoded
//   in parallel), writes landscapes and the report through run_sweep, and deletes the shards;
// - resume: the done set is the union of `<out>` and every shard, whatever rank count wrote them;
//   only runs in none of them are redone.
// Only compiled when MPI was found (KINESWEEP_HAVE_MPI); without it `kinesweep run` is unchanged.
#include <atomic>
#include <ostream>
#include <string>

#include "runner/sweep.hpp"

namespace ks {

/// True when an MPI launcher (mpirun/mpiexec of Open MPI or MPICH, srun with PMI/PMIx) started this
/// process, judged from its environment (no MPI call). Plain `kinesweep run` never initialises MPI.
bool launched_under_mpi();

struct DistributedRun {
  std::string output;          ///< the final results file
  std::string study_arg;       ///< the study path as the user gave it (for the resume hint)
  bool resume = false, overwrite = false, quiet = false;
  /// threads (per rank; 0: the cores this rank may use, shared fairly between the ranks on a node),
  /// histories, compression, stop, on_progress (called on rank 0 with the job's global progress).
  SweepOptions options;
};

/// The distributed `kinesweep run`: MPI_Init ... MPI_Finalize. Returns the exit code (the same on
/// every rank): 0 done, 1 results file problem, 130 interrupted. Rank 0 prints the report to `out`.
int run_distributed(const Study& study, const StudySchema& schema, const DistributedRun& run, std::ostream& out,
                    std::ostream& err);

/// `<out>.rank<r>.h5`
std::string shard_path(const std::string& output, int rank);

}  // namespace ks
