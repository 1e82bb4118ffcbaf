// How a process was started, read from its environment (process_group.hpp): mpirun, a task of an
// srun step (with PMIx, PMI-2 or no interface), another PMI launcher, a SLURM batch script.
#include <bodyfit/app/process_group.hpp>

#include <doctest/doctest.h>

#include <map>
#include <string>

using namespace bodyfit;
using Launcher = LaunchEnvironment::Launcher;

namespace {

LaunchEnvironment launch_with(const std::map<std::string, std::string>& environment) {
  return read_launch_environment([&](const char* name) -> const char* {
    const auto found = environment.find(name);
    return found == environment.end() ? nullptr : found->second.c_str();
  });
}

}  // namespace

TEST_CASE("launch: no launcher, one process") {
  const LaunchEnvironment launch = launch_with({{"HOME", "/root"}});
  CHECK(launch.launcher == Launcher::none);
  CHECK(launch.processes == 1);
  CHECK(launch.allocation_tasks == 0);
  CHECK_FALSE(launch.pmix);
  CHECK_FALSE(launch.pmi2);
}

TEST_CASE("launch: a SLURM batch script or salloc shell is one process of the allocation") {
  // What sbatch -n 2 gives its script (no step variables): not a launcher.
  const LaunchEnvironment launch =
      launch_with({{"SLURM_JOB_ID", "7"}, {"SLURM_NTASKS", "2"}, {"SLURM_PROCID", "0"}, {"SLURM_LOCALID", "0"}});
  CHECK(launch.launcher == Launcher::none);
  CHECK(launch.processes == 1);
  CHECK(launch.allocation_tasks == 2);
}

TEST_CASE("launch: srun tasks with PMIx, PMI-2 and no interface") {
  // What srun -n 2 gives its tasks, then what each --mpi plugin adds.
  const std::map<std::string, std::string> step{{"SLURM_JOB_ID", "9"},         {"SLURM_NTASKS", "2"},
                                                {"SLURM_STEP_NUM_TASKS", "2"}, {"SLURM_STEP_ID", "0"},
                                                {"SLURM_PROCID", "1"}};
  auto step_with = [&](const std::map<std::string, std::string>& plugin) {
    std::map<std::string, std::string> environment = step;
    environment.insert(plugin.begin(), plugin.end());
    return launch_with(environment);
  };

  LaunchEnvironment launch = step_with({{"SLURM_MPI_TYPE", "pmix"}, {"PMIX_RANK", "1"}});
  CHECK(launch.launcher == Launcher::srun);
  CHECK(launch.processes == 2);
  CHECK(launch.pmix);
  CHECK_FALSE(launch.pmi2);
  CHECK(launch.srun_mpi == "pmix");
  CHECK(launch.allocation_tasks == 0);

  launch = step_with({{"SLURM_MPI_TYPE", "pmi2"}, {"PMI_FD", "11"}, {"PMI_RANK", "1"}, {"PMI_SIZE", "2"}});
  CHECK(launch.launcher == Launcher::srun);
  CHECK(launch.processes == 2);
  CHECK_FALSE(launch.pmix);
  CHECK(launch.pmi2);
  CHECK(launch.srun_mpi == "pmi2");

  launch = step_with({{"SLURM_MPI_TYPE", "none"}});
  CHECK(launch.launcher == Launcher::srun);
  CHECK(launch.processes == 2);
  CHECK_FALSE(launch.pmix);
  CHECK_FALSE(launch.pmi2);
  CHECK(launch.srun_mpi == "none");
}

TEST_CASE("launch: mpirun's size wins over the SLURM step of its daemons") {
  // mpirun in an allocation starts its daemons with srun, one task per node: its ranks inherit
  // that step (1 task) while the job has 4 ranks.
  const LaunchEnvironment launch = launch_with({{"OMPI_COMM_WORLD_SIZE", "4"},
                                                {"OMPI_COMM_WORLD_RANK", "3"},
                                                {"PMIX_RANK", "3"},
                                                {"SLURM_STEP_NUM_TASKS", "1"},
                                                {"SLURM_NTASKS", "4"}});
  CHECK(launch.launcher == Launcher::mpirun);
  CHECK(launch.processes == 4);
  CHECK(launch.pmix);
}

TEST_CASE("launch: other PMI launchers, with and without their size") {
  LaunchEnvironment launch = launch_with({{"PMI_SIZE", "3"}, {"PMI_RANK", "0"}, {"PMI_FD", "5"}});
  CHECK(launch.launcher == Launcher::pmi);
  CHECK(launch.processes == 3);
  CHECK(launch.pmi2);
  // PMIx alone does not put the size in the environment: unknown, not checked.
  launch = launch_with({{"PMIX_RANK", "0"}});
  CHECK(launch.launcher == Launcher::pmi);
  CHECK(launch.processes == 0);
  CHECK(launch.pmix);
}

TEST_CASE("launch: counts that are not positive numbers are ignored") {
  for (const char* text : {"", "0", "-2", "2x", "x"}) {
    const std::string value = text;
    CAPTURE(value);
    const LaunchEnvironment launch = launch_with({{"OMPI_COMM_WORLD_SIZE", value}, {"SLURM_NTASKS", value}});
    CHECK(launch.launcher == Launcher::none);
    CHECK(launch.processes == 1);
    CHECK(launch.allocation_tasks == 0);
  }
}
