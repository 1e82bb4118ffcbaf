// libbodyfit_mpi: the MPI calls of `bodyfit ensemble` (src/mpi_module.hpp).
#include "mpi_module.hpp"

#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace bodyfit::mpi {
namespace {

void library_version(char* text, int size) {
  if (size <= 0) return;
  char version[MPI_MAX_LIBRARY_VERSION_STRING] = "";
  int length = 0;
  MPI_Get_library_version(version, &length);
  const int kept = std::clamp(length, 0, size - 1);
  std::memcpy(text, version, std::size_t(kept));
  text[kept] = '\0';
}

bool init(int* rank, int* size, char* error, int error_size) {
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (!initialised) {
    int provided = 0;
    const int rc = MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    if (rc != MPI_SUCCESS) {
      char text[MPI_MAX_ERROR_STRING];
      int length = 0;
      MPI_Error_string(rc, text, &length);
      std::snprintf(error, std::size_t(error_size), "MPI_Init_thread failed: %s", text);
      return false;
    }
  }
  MPI_Comm_rank(MPI_COMM_WORLD, rank);
  MPI_Comm_size(MPI_COMM_WORLD, size);
  return true;
}

bool all_true(bool value) {
  int mine = value ? 1 : 0, all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  return all == 1;
}

void finalize() {
  int finalised = 0;
  MPI_Finalized(&finalised);
  if (!finalised) MPI_Finalize();
}

void abort(int code) { MPI_Abort(MPI_COMM_WORLD, code); }

constexpr Api kApi{kApiVersion, &library_version, &init, &all_true, &finalize, &abort};

}  // namespace
}  // namespace bodyfit::mpi

extern "C" __attribute__((visibility("default"))) const bodyfit::mpi::Api* bodyfit_mpi_api() {
  return &bodyfit::mpi::kApi;
}
