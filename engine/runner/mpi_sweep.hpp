#pragma once
// Distributed sweeps over MPI (`mpirun -np N kinesweep run STUDY.toml`, `srun kinesweep run ...`),
// the MPI backend of run_study (runner/sweep_backend.hpp):
// - every rank writes its own shard `<out>.rank<r>.h5`: a normal, crash-safe results file of the
//   same study and schema (n_runs = all runs) holding only the runs that rank computed;
// - load balance: rank 0 hands out run ids dynamically (runner/mpi_work.hpp), each rank runs its
//   chunks in its own TBB pipeline (SweepOptions::source);
// - at the end rank 0 merges final file + shards into `<out>` in run-id order (histories re-encoded
//   in parallel), writes landscapes through run_sweep, deletes the shards, and then runs the
//   study's optimisation blocks into `<out>` like a single process;
// - resume: the done set is the union of `<out>` and every shard, whatever rank count wrote them;
//   only runs in none of them are redone.
// Only compiled when MPI was found (KINESWEEP_HAVE_MPI); without it `kinesweep run` is unchanged.
#include <string>

namespace ks {

/// `<out>.rank<r>.h5`
std::string shard_path(const std::string& output, int rank);

}  // namespace ks
