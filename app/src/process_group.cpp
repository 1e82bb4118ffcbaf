#include <bodyfit/shared_object.hpp>
#include "mpi_module.hpp"

#include <bodyfit/app/config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/app/process_group.hpp>

#include <fmt/format.h>

#include <dlfcn.h>

#include <charconv>
#include <cstdlib>
#include <string_view>

namespace bodyfit {
namespace {

const mpi::Api& api_of(const void* api) { return *static_cast<const mpi::Api*>(api); }

/// A positive count from the environment, or 0 when absent or not a number.
int count_of(const char* text) {
  if (!text) return 0;
  int value = 0;
  const std::string_view view(text);
  const auto [end, ec] = std::from_chars(view.data(), view.data() + view.size(), value);
  return ec == std::errc() && end == view.data() + view.size() && value > 0 ? value : 0;
}

using Launcher = LaunchEnvironment::Launcher;

/// Why this task cannot join the others of its srun step, or empty. Without any interface
/// (srun --mpi=none) MPI would start it alone; Open MPI speaks PMIx only (Debian's has no PMI-2
/// client) and aborts in MPI_Init with advice about rebuilding it.
std::string srun_interface_problem(const LaunchEnvironment& launch, std::string_view library) {
  if (launch.launcher != Launcher::srun || launch.pmix) return {};
  const std::string plugin = launch.srun_mpi.empty() ? "none" : launch.srun_mpi;
  if (!launch.pmi2)
    return fmt::format("srun started {} tasks without a process-management interface (srun --mpi={}): MPI would "
                       "start each alone and every task would run every member. Run srun --mpi=pmix (srun "
                       "--mpi=list shows the plugins; MpiDefault=pmix in slurm.conf makes it the default)",
                       launch.processes, plugin);
  if (library.starts_with("Open MPI"))
    return fmt::format("srun --mpi={} gives PMI-2, but bodyfit's MPI ({}) joins an srun job through PMIx: run srun "
                       "--mpi=pmix",
                       plugin, library.substr(0, library.find_first_of(",\n")));
  return {};
}

}  // namespace

LaunchEnvironment read_launch_environment(const std::function<const char*(const char*)>& lookup) {
  LaunchEnvironment launch;
  launch.pmix = lookup("PMIX_RANK") != nullptr;
  launch.pmi2 = lookup("PMI_FD") != nullptr;
  // mpirun first: under mpirun in a SLURM allocation, the ranks inherit the SLURM_STEP_* of the
  // srun step that started Open MPI's daemons (one task per node), not the job's size.
  if (const int size = count_of(lookup("OMPI_COMM_WORLD_SIZE"))) {
    launch.launcher = Launcher::mpirun;
    launch.processes = size;
  } else if (const int tasks = count_of(lookup("SLURM_STEP_NUM_TASKS"))) {
    launch.launcher = Launcher::srun;
    launch.processes = tasks;
    if (const char* plugin = lookup("SLURM_MPI_TYPE")) launch.srun_mpi = plugin;
  } else if (const int size = count_of(lookup("PMI_SIZE"))) {
    launch.launcher = Launcher::pmi;
    launch.processes = size;
  } else if (launch.pmix) {
    launch.launcher = Launcher::pmi;
    launch.processes = 0;  // PMIx passes the job's size through its server, not the environment
  } else {
    // A batch script or an salloc shell: one process of the allocation, not a task of a step.
    launch.allocation_tasks = count_of(lookup("SLURM_NTASKS"));
  }
  return launch;
}

LaunchEnvironment read_launch_environment() {
  return read_launch_environment([](const char* name) -> const char* { return std::getenv(name); });
}

bool started_by_mpi_launcher() { return read_launch_environment().launcher != Launcher::none; }

ProcessGroup ProcessGroup::join_mpi() {
  if constexpr (!config::have_mpi)
    throw InputError("this bodyfit was built without MPI (install libopenmpi-dev and reconfigure): run the ensemble "
                     "without mpirun, on local threads (--jobs)");
  const LaunchEnvironment launch = read_launch_environment();
  // RTLD_GLOBAL: Open MPI's own components, loaded by MPI_Init, resolve symbols of libmpi. Never
  // closed: MPI may not be initialised twice in a process.
  std::string failure;
  const mpi::Api* table = module_table<mpi::Api>(core_library_directory() / config::mpi_module_from_libdir,
                                                 "bodyfit_mpi_api", mpi::kApiVersion, RTLD_GLOBAL, "MPI module", failure);
  if (!table) throw InputError(failure);

  char library[256] = "";
  table->library_version(library, int(sizeof library));
  if (const std::string problem = srun_interface_problem(launch, library); !problem.empty()) throw InputError(problem);

  ProcessGroup group;
  char error[512] = "";
  if (!table->init(&group.rank_, &group.size_, error, int(sizeof error))) throw InputError(error);
  group.api_ = table;  // from here the destructor finalises MPI, also when the check below throws
  // A launcher whose processes did not find each other (each an MPI job of one) would have every
  // process run every member into the same directory.
  if (launch.processes > 0 && group.size_ != launch.processes)
    throw InputError(fmt::format("the launcher started {} processes, but MPI sees {} (rank {}): they did not join one "
                                 "job; under srun, use srun --mpi=pmix",
                                 launch.processes, group.size_, group.rank_));
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
