// bodyfit run case.toml: the whole evolution (Algorithm 1) with its outputs (docs/reference/running.md).
#include "commands.hpp"
#include "validators.hpp"

#include <bodyfit/app/run_case.hpp>
#include <bodyfit/fault_injection.hpp>
#include <bodyfit/model_guard.hpp>

#include <atomic>
#include <csignal>
#include <memory>
#include <unistd.h>

namespace {

using namespace bodyfit;

std::atomic<bool> g_interrupted{false};
// SIGINT (Ctrl-C), SIGTERM (what SLURM, systemd and `docker stop` send) and SIGHUP (a closed
// terminal): the current iteration finishes and is checkpointed, then the run exits with 130. A
// second signal, while the first is being honoured (a model stuck in compute), ends the process at
// once: the checkpoint on disk is the last completed one (files are written to a temporary and
// renamed, and a resume removes the temporaries).
extern "C" void on_run_signal(int) {
  if (g_interrupted.exchange(true)) _exit(130);
}

struct RunArguments {
  std::string case_file;
  std::string output_dir;
  std::vector<std::string> sets;
  bool resume = false;
  bool overwrite = false;  ///< replace a previous run in the output directory (its own files only)
  bool force = false;      ///< --resume with another case than the checkpoint's
  std::string inject_fault;   ///< "POINT:N": SIGKILL at a write point of iteration N (tests; fault_injection.hpp)
  std::string inject_io_error;  ///< "POINT:N": an IoError there instead
  std::string inject_signal;  ///< "N:INT" or "N:KILL" [":scheduled"]: raise a signal after iteration N (tests)
  bool verbose = false;       ///< the stage times on every progress line
  double model_timeout = 0;   ///< seconds a call into the model may take (0: no limit)
};

int run_case(const RunArguments& args) {
  // From the start (a Ctrl-C during setup stops before the first iteration), and even when the
  // shell started us with SIGINT ignored (background jobs).
  for (int signal : {SIGINT, SIGTERM, SIGHUP}) std::signal(signal, on_run_signal);
  limit_model_calls(args.model_timeout);
  if (!args.inject_fault.empty()) arm_fault(args.inject_fault);
  if (!args.inject_io_error.empty()) arm_fault(args.inject_io_error, FaultKind::IoError);
  RunRequest request;
  request.case_file = args.case_file;
  request.sets = args.sets;
  request.output_dir = args.output_dir;
  request.resume = args.resume;
  request.overwrite = args.overwrite;
  request.force = args.force;
  request.verbose = args.verbose;
  request.interrupted = &g_interrupted;
  request.inject = parse_injected_signal(args.inject_signal);
  return bodyfit::run_case(request).exit_code;
}

bodyfit::cli::Command setup_run(CLI::App& app) {
  auto* cmd = app.add_subcommand("run", "run a case: evolve the region G(t) with a velocity model (docs/reference/running.md)");
  auto args = std::make_shared<RunArguments>();
  // No ExistingFile check: a missing file is an input error (exit 1), as for every reader.
  cmd->add_option("case", args->case_file, "case file (.toml)")->required();
  cmd->add_option("-o,--output", args->output_dir, "output directory (default: <case name>.out)");
  cmd->add_option("--set", args->sets, "override a key of the case, e.g. --set time.dt=0.05 (repeatable)");
  auto* resume =
      cmd->add_flag("--resume", args->resume, "continue from the last completed iteration in the output directory");
  cmd->add_flag("--overwrite", args->overwrite,
                "replace a previous run in the output directory (removes its files: case.toml, checkpoint.bin, "
                "history.csv, series.pvd, step_*.vtu, snap_*.png, final.mesh/.sol; nothing else)")
      ->excludes(resume);
  cmd->add_flag("--force", args->force, "with --resume: continue even though the case differs from the checkpoint's")
      ->needs(resume);
  cmd->add_flag("--verbose", args->verbose, "the milliseconds of each stage on every iteration's line");
  cmd->add_option("--model-timeout", args->model_timeout,
                  "end the run (exit 4, the last checkpoint intact) when a call into the model takes longer than this "
                  "many seconds (0: no limit)")
      ->check(bodyfit::cli::finite_at_least(0))
      ->capture_default_str();
  // Test hooks (no group: hidden from --help): a crash or Ctrl-C at a known point of the run.
  cmd->add_option("--inject-signal", args->inject_signal, "")->group("");
  cmd->add_option("--inject-fault", args->inject_fault, "")->group("");
  cmd->add_option("--inject-io-error", args->inject_io_error, "")->group("")->excludes("--inject-fault");
  return {cmd, [args]() { return run_case(*args); }};
}

BODYFIT_COMMAND(80, setup_run);

}  // namespace
