#pragma once
// The processes running one command together: the ranks of an MPI job (mpirun, srun), or this
// process alone. MPI itself lives in a module loaded on demand (src/mpi_module.hpp), so nothing
// here needs MPI to build or to start.
namespace bodyfit {

/// Whether the environment says an MPI launcher started this process: Open MPI's mpirun
/// (OMPI_COMM_WORLD_SIZE), a PMI or PMIx launcher such as SLURM's srun (PMI_SIZE, PMIX_RANK), or
/// a SLURM job step (SLURM_NTASKS).
bool started_by_mpi_launcher();

class ProcessGroup {
 public:
  /// This process alone (rank 0 of 1).
  ProcessGroup() = default;
  /// Join the MPI job (loads the module, MPI_Init): InputError when bodyfit was built without MPI
  /// or its module cannot be loaded or started.
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
