#pragma once
// A `run` started by an MPI launcher, in a kinesweep built without MPI linked: it continues in the
// program with MPI installed beside it (engine/CMakeLists.txt, distributed sweeps).

namespace ks::cli {

/// True when this program leaves MPI runs to another program (kinesweep-mpi).
bool has_mpi_program();
/// exec the program with MPI from this program's directory with the same arguments (argv[0]
/// included): the process keeps its id, its environment and its connection to the launcher. Returns
/// only when that fails, with exit code 1 after printing why.
int exec_mpi_program(char** argv);

}  // namespace ks::cli
