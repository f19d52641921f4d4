#pragma once
// Whether an MPI launcher started this process. Judged from the environment alone (no MPI call), so
// that a program without MPI linked can ask it too.

namespace ks {

/// True when an MPI launcher (mpirun/mpiexec of Open MPI or MPICH, srun with PMI/PMIx) started this
/// process.
bool launched_under_mpi();

}  // namespace ks
