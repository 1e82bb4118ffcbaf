#include "core_location.hpp"
#include "mpi_module.hpp"

#include <bodyfit/config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/process_group.hpp>

#include <fmt/format.h>

#include <dlfcn.h>

#include <cstdlib>

namespace bodyfit {
namespace {

const mpi::Api& api_of(const void* api) { return *static_cast<const mpi::Api*>(api); }

}  // namespace

bool started_by_mpi_launcher() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "SLURM_NTASKS"})
    if (std::getenv(name)) return true;
  return false;
}

ProcessGroup ProcessGroup::join_mpi() {
  if constexpr (!config::have_mpi)
    throw InputError("this bodyfit was built without MPI (install libopenmpi-dev and reconfigure): run the ensemble "
                     "without mpirun, on local threads (--jobs)");
  const std::filesystem::path module = core_library_directory() / config::mpi_module_from_libdir;
  // RTLD_GLOBAL: Open MPI's own components, loaded by MPI_Init, resolve symbols of libmpi. Never
  // closed: MPI may not be initialised twice in a process.
  void* handle = dlopen(module.c_str(), RTLD_NOW | RTLD_GLOBAL);
  if (!handle) {
    const char* reason = dlerror();
    throw InputError(fmt::format("cannot load bodyfit's MPI module {}: {}", module.string(), reason ? reason : "?"));
  }
  auto entry = reinterpret_cast<decltype(&bodyfit_mpi_api)>(dlsym(handle, "bodyfit_mpi_api"));
  const mpi::Api* table = entry ? entry() : nullptr;
  if (!table || table->version != mpi::kApiVersion)
    throw InputError(fmt::format("{} is not the MPI module of this bodyfit (reinstall bodyfit)", module.string()));
  ProcessGroup group;
  char error[512] = "";
  if (!table->init(&group.rank_, &group.size_, error, int(sizeof error))) throw InputError(error);
  group.api_ = table;
  return group;
}

ProcessGroup::ProcessGroup(ProcessGroup&& other) noexcept : api_(other.api_), rank_(other.rank_), size_(other.size_) {
  other.api_ = nullptr;
}

ProcessGroup::~ProcessGroup() {
  if (api_) api_of(api_).finalize();
}

bool ProcessGroup::all_true(bool value) const { return api_ ? api_of(api_).all_true(value) : value; }

void ProcessGroup::abort(int code) const {
  if (api_) api_of(api_).abort(code);
  std::_Exit(code);
}

}  // namespace bodyfit
