// Compiled into each executable apart: KINESWEEP_MPI_PROGRAM names the program with MPI in the one
// built without it (engine/cli/CMakeLists.txt).
#include "cli/mpi_program.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>

namespace ks::cli {

#ifdef KINESWEEP_MPI_PROGRAM
bool has_mpi_program() { return true; }

int exec_mpi_program(char** argv) {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  const std::filesystem::path program =
      (ec ? std::filesystem::path(argv[0]).parent_path() : self.parent_path()) / KINESWEEP_MPI_PROGRAM;
  execv(program.c_str(), argv);
  std::cerr << "Error: started by an MPI launcher, but " << program.string()
            << " (kinesweep with MPI) cannot be run: " << std::strerror(errno)
            << " (build it: cmake --build BUILD_DIR --target " KINESWEEP_MPI_PROGRAM ")\n";
  return 1;
}
#else
bool has_mpi_program() { return false; }

int exec_mpi_program(char**) {
  std::cerr << "Error: no program with MPI to run\n";
  return 1;
}
#endif

}  // namespace ks::cli
