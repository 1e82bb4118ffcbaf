#pragma once
// The MPI calls of `bodyfit ensemble` live in a module (app/mpi/, libbodyfit_mpi.so in
// <libdir>/bodyfit/ beside the GDAL module), loaded only when an MPI launcher started the process
// (or with --mpi): neither the core nor the program links MPI, so every other command, and an
// ensemble on local threads, start without it. Built with bodyfit from the same headers.
#include <cstdint>

namespace bodyfit::mpi {

inline constexpr std::uint32_t kApiVersion = 2;

/// The module's entry points (MPI_COMM_WORLD; only the calling thread uses MPI).
struct Api {
  std::uint32_t version = kApiVersion;
  /// The MPI library's own name and version (MPI_Get_library_version, callable before MPI_Init),
  /// at most `size` bytes with the terminating zero: which launch interfaces it speaks.
  void (*library_version)(char* text, int size) = nullptr;
  /// MPI_Init_thread (funneled): this process's rank and the number of ranks; false with a
  /// message in `error` (of `error_size` bytes) when MPI cannot start.
  bool (*init)(int* rank, int* size, char* error, int error_size) = nullptr;
  /// Whether `value` is true on every rank (a collective: every rank calls it, also a barrier).
  bool (*all_true)(bool value) = nullptr;
  void (*finalize)() = nullptr;
  /// Stop every rank (MPI_Abort) with this exit code.
  void (*abort)(int code) = nullptr;
};

}  // namespace bodyfit::mpi

/// Defined by the module: its table of entry points.
extern "C" const bodyfit::mpi::Api* bodyfit_mpi_api();
