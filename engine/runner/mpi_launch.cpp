#include "runner/mpi_launch.hpp"

#include <cstdlib>

namespace ks {

namespace {
bool env_set(const char* name) {
  const char* v = std::getenv(name);
  return v && *v;
}
}  // namespace

bool launched_under_mpi() {
  return env_set("OMPI_COMM_WORLD_SIZE") || env_set("PMIX_RANK") || env_set("PMI_RANK") || env_set("PMI_SIZE") ||
         env_set("MPI_LOCALNRANKS");
}

}  // namespace ks
