#pragma once
// The processes running one command together: the ranks of an MPI job (mpirun, srun), or this
// process alone. MPI itself lives in a module loaded on demand (src/mpi_module.hpp), so nothing
// here needs MPI to build or to start.
#include <functional>
#include <string>

namespace bodyfit {

/// How this process was started, as its environment says before MPI starts.
struct LaunchEnvironment {
  enum class Launcher {
    none,    ///< no launcher (also a SLURM batch script or salloc shell: see allocation_tasks)
    mpirun,  ///< Open MPI's mpirun (OMPI_COMM_WORLD_SIZE)
    srun,    ///< a task of a SLURM job step started by srun (SLURM_STEP_NUM_TASKS)
    pmi,     ///< another PMI or PMIx launcher (PMI_SIZE, PMIX_RANK)
  };
  Launcher launcher = Launcher::none;
  /// How many processes the launcher started: the MPI job must have exactly these ranks (0 when
  /// the environment does not say, as with PMIx alone).
  int processes = 1;
  /// A process-management interface this process can join the others through: PMIx (PMIX_RANK)
  /// or PMI-2 (PMI_FD). srun --mpi=none starts tasks with neither.
  bool pmix = false, pmi2 = false;
  /// Under srun: its MPI plugin (--mpi, or the site's MpiDefault: SLURM_MPI_TYPE).
  std::string srun_mpi;
  /// In a SLURM allocation but not started by srun (a batch script, an salloc shell): the tasks
  /// allocated (SLURM_NTASKS), of which this process is only one; else 0.
  int allocation_tasks = 0;
};

/// Reads the launch from this process's environment.
LaunchEnvironment read_launch_environment();
/// Reads it from `lookup`, which gives a variable's value or null when it is absent (for tests).
LaunchEnvironment read_launch_environment(const std::function<const char*(const char*)>& lookup);

/// Whether an MPI launcher started this process (read_launch_environment().launcher != none).
bool started_by_mpi_launcher();

class ProcessGroup {
 public:
  /// This process alone (rank 0 of 1).
  ProcessGroup() = default;
  /// Join the MPI job (loads the module, MPI_Init). InputError when bodyfit was built without MPI,
  /// its module cannot be loaded or started, srun started this task without a process-management
  /// interface MPI can use (srun --mpi=none; PMI-2 for Open MPI, which speaks PMIx only), or MPI
  /// sees another number of ranks than the launcher started (each would run every member).
  static ProcessGroup join_mpi();
  ProcessGroup(ProcessGroup&& other) noexcept;
  ProcessGroup& operator=(ProcessGroup&&) = delete;
  ProcessGroup(const ProcessGroup&) = delete;
  ~ProcessGroup();  ///< MPI_Finalize when joined

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool is_mpi() const { return api_ != nullptr; }
  /// Whether `value` holds on every rank; every rank must call it (it is also a barrier).
  bool all_true(bool value) const;
  /// Stop every rank of the job with `code` (exits this process alone when not under MPI).
  [[noreturn]] void abort(int code) const;

 private:
  const void* api_ = nullptr;  ///< the module's mpi::Api, or null
  int rank_ = 0, size_ = 1;
};

}  // namespace bodyfit
