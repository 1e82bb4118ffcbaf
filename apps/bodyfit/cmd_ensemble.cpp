// bodyfit ensemble case.toml: N members of a case with sampled regions and parameters, on
// local threads or MPI ranks, reduced over the outputs the model declares (docs/reference/ensembles.md).
#include "commands.hpp"
#include "validators.hpp"

#include <bodyfit/app/config.hpp>
#include <bodyfit/app/ensemble.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/app/process_group.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <sys/resource.h>

#include <atomic>
#include <csignal>
#include <memory>

namespace {

namespace fs = std::filesystem;
using namespace bodyfit;

std::atomic<bool> g_interrupted{false};
extern "C" void on_interrupt(int) { g_interrupted.store(true); }

struct EnsembleArguments {
  std::string case_file;
  std::string output_dir;
  std::vector<std::string> sets;
  std::size_t members = 0;
  std::uint64_t seed = 0;
  bool seed_given = false;
  std::size_t jobs = 1;
  bool mpi = false;
  std::vector<std::size_t> inject_failures;
};

double peak_memory_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) / 1024.0;  // kilobytes on Linux
}

/// The MPI job when asked (--mpi) or when a launcher started us, else this process alone.
ProcessGroup process_group(bool mpi) {
  if (mpi) return ProcessGroup::join_mpi();
  const LaunchEnvironment launch = read_launch_environment();
  if (launch.launcher == LaunchEnvironment::Launcher::none) {
    if (launch.allocation_tasks > 1)
      spdlog::warn("this SLURM allocation has {} tasks, but bodyfit was not started by srun: this one process runs "
                   "every member, on its own threads (--jobs); start it with `srun bodyfit ensemble ...` to spread "
                   "the members over the tasks",
                   launch.allocation_tasks);
    return ProcessGroup();
  }
  // srun -n 1 without a process-management interface: there is no one to join (and Open MPI
  // would abort in MPI_Init).
  if (launch.launcher == LaunchEnvironment::Launcher::srun && launch.processes == 1 && !launch.pmix && !launch.pmi2)
    return ProcessGroup();
  if constexpr (!config::have_mpi) {
    // Each of the launcher's processes would run every member into the same directory.
    if (launch.processes > 1)
      throw InputError(fmt::format("started by an MPI launcher with {} processes, but this bodyfit was built without "
                                   "MPI (install libopenmpi-dev and reconfigure): run one process, with --jobs for "
                                   "its threads",
                                   launch.processes));
    spdlog::warn("started by an MPI launcher, but this bodyfit was built without MPI: this process runs the whole "
                 "ensemble alone");
    return ProcessGroup();
  }
  return ProcessGroup::join_mpi();
}

int run_ensemble_command(const EnsembleArguments& args) {
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);
  const ProcessGroup group = process_group(args.mpi);
  if (group.size() > 1 || group.is_mpi())
    spdlog::set_pattern(fmt::format("[%T.%e] [rank {}/{}] %^%l%$ %v", group.rank(), group.size()));

  EnsembleOptions options;
  options.case_file = args.case_file;
  options.overrides = args.sets;
  options.outdir = args.output_dir.empty() ? fs::path(fs::path(args.case_file).stem().string() + ".ensemble")
                                           : fs::path(args.output_dir);
  options.members = args.members;
  if (args.seed_given) options.seed = args.seed;
  options.jobs = args.jobs;
  options.stop = &g_interrupted;
  options.inject_failures = args.inject_failures;
  const EnsembleSummary summary = run_ensemble(options, group);
  spdlog::info("rank {}: {} members run, {} already complete; peak memory {:.0f} MiB", group.rank(), summary.ran,
               summary.skipped, peak_memory_mib());
  if (summary.interrupted) {
    spdlog::warn("interrupted: the complete members are kept; run the same command again to continue");
    return int(ExitCode::Interrupted);
  }
  if (!summary.reduced_here) return 0;
  spdlog::info("{} members complete, {} failed (members.csv); rasters in {}", summary.reduced.ok,
               summary.reduced.failed, options.outdir.string());
  return summary.reduced.ok > 0 ? 0 : int(ExitCode::Plugin);
}

bodyfit::cli::Command setup_ensemble(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "ensemble",
      "run N members of a case with sampled regions and parameters ([ensemble] of the case), on local "
      "threads or MPI ranks (mpirun, srun), and reduce the outputs the model declares (probabilities, means, "
      "percentiles) into rasters and tables (docs/reference/ensembles.md)");
  auto args = std::make_shared<EnsembleArguments>();
  // No ExistingFile check: a missing file is an input error (exit 1), as for every reader.
  cmd->add_option("case", args->case_file, "case file (.toml) with an [ensemble] table")->required();
  cmd->add_option("-o,--output", args->output_dir, "output directory (default: <case name>.ensemble); run the same "
                                                   "command again to continue an interrupted ensemble");
  cmd->add_option("--set", args->sets, "override a key of the case, e.g. --set time.final_time=3600 (repeatable)");
  cmd->add_option("--members", args->members, "number of members (default: ensemble.members of the case)")
      ->check(CLI::Range(std::size_t(1), std::size_t(100000000)));
  cmd->add_option("--seed", args->seed, "seed of the sampling (default: ensemble.seed of the case)")
      ->check(bodyfit::cli::count())
      ->each([args](const std::string&) { args->seed_given = true; });
  cmd->add_option("--jobs", args->jobs, "members run at once on this process's threads (each gets an equal share "
                                        "of the cores)")
      ->check(CLI::Range(std::size_t(1), std::size_t(4096)));
  cmd->add_flag("--mpi", args->mpi, "join an MPI job even when no launcher is seen in the environment");
  // Test hook (no group: hidden from --help): these members fail with a numerical error.
  cmd->add_option("--inject-failure", args->inject_failures, "")->group("");
  return {cmd, [args]() { return run_ensemble_command(*args); }};
}

BODYFIT_COMMAND(85, setup_ensemble);

}  // namespace
