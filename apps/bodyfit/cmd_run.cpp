// bodyfit run case.toml: the whole evolution (Algorithm 1) with its outputs (docs/reference/running.md).
#include "commands.hpp"
#include "validators.hpp"

#include <bodyfit/app/case_config.hpp>
#include <bodyfit/app/case_identity.hpp>
#include <bodyfit/app/output_lock.hpp>
#include <bodyfit/app/progress.hpp>
#include <bodyfit/app/run.hpp>
#include <bodyfit/app/run_directory.hpp>
#include <bodyfit/app/run_outputs.hpp>
#include <bodyfit/atomic_file.hpp>
#include <bodyfit/checkpoint.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/fault_injection.hpp>
#include <bodyfit/model_guard.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <unistd.h>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

namespace {

namespace fs = std::filesystem;
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

/// A directory holding a previous run is not written into by accident. (Temporaries alone are
/// not a run: a run killed before its first checkpoint left nothing to resume.)
void refuse_used_directory(const fs::path& outdir) {
  std::vector<fs::path> previous = run_outputs(outdir);
  std::erase_if(previous, [](const fs::path& file) { return is_atomic_temporary(file.filename().string()); });
  if (previous.empty()) return;
  std::string names;
  for (std::size_t i = 0; i < previous.size() && i < 4; ++i) names += (i ? ", " : "") + previous[i].filename().string();
  if (previous.size() > 4) names += ", ...";
  throw InputError(fmt::format("{} holds a previous run ({} files: {}): continue it with --resume, or replace it with "
                               "--overwrite (which removes the run's files and nothing else)",
                               outdir.string(), previous.size(), names));
}

/// --resume continues the case its checkpoint was written for: another case (file or --set values)
/// is refused, but for the end of the run and the outputs (resume_may_change), unless --force.
void check_same_case(const Checkpoint& c, const std::string& case_text, bool force, const fs::path& checkpoint) {
  if (c.case_text.empty()) {
    spdlog::warn("{}: the checkpoint records no case (format {}: written before checkpoints recorded it, or by a "
                 "program that gave none): the case is not compared with the one it was started with",
                 checkpoint.string(), c.format);
    return;
  }
  auto shown = [](const std::string& value) { return value.empty() ? std::string("(absent)") : value; };
  std::vector<CaseChange> changes;
  try {
    changes = case_changes(c.case_text, case_text);
  } catch (const InputError& e) {
    if (!force)
      throw InputError(fmt::format("{}: {}: the checkpoint is damaged or not one of bodyfit's (--force resumes "
                                   "without comparing the cases)",
                                   checkpoint.string(), e.what()));
    spdlog::warn("{}: {}; --force: resuming without comparing the cases", checkpoint.string(), e.what());
    return;
  }
  std::vector<std::string> refused;
  for (const CaseChange& change : changes) {
    const std::string text = fmt::format("{}: {} -> {}", change.key, shown(change.before), shown(change.after));
    if (resume_may_change(change.key)) spdlog::info("resuming with {}", text);
    else if (is_input_digest(change.key) && change.before.empty())  // a checkpoint from before the digests
      spdlog::info("the checkpoint records no digest of {} (written before checkpoints recorded them)",
                   change.key.substr(change.key.find('.') + 1));
    else refused.push_back(text);
  }
  if (refused.empty()) return;
  if (force) {
    spdlog::warn("--force: resuming with another case than the checkpoint's ({})", fmt::join(refused, "; "));
    return;
  }
  throw InputError(fmt::format("--resume: the case differs from the one {} was written for ({}); run it in another "
                               "directory, or continue with the new values anyway with --force",
                               checkpoint.string(), fmt::join(refused, "; ")));
}

/// The output directory, ready to be written: created; with --overwrite the previous run's files
/// (the driver's and the model's) removed; the temporaries of killed writes removed; on --resume the per-state files past the
/// checkpoint removed (the resumed run writes again those it should).
void prepare_directory(const fs::path& outdir, const RunArguments& args, int resumed_iteration,
                       const std::vector<std::string>& model_files) {
  std::error_code ec;
  fs::create_directories(outdir, ec);
  if (ec) throw IoError(fmt::format("{}: cannot create the output directory ({})", outdir.string(), ec.message()));
  if (args.overwrite) remove_run_outputs(outdir, model_files);
  if (const std::size_t n = remove_stale_temporaries(outdir))
    spdlog::info("{}: removed {} temporary files of interrupted writes", outdir.string(), n);
  if (resumed_iteration >= 0) remove_states_from(outdir, resumed_iteration);
}

int run_case(const RunArguments& args) {
  // From the start (a Ctrl-C during setup stops before the first iteration), and even when the
  // shell started us with SIGINT ignored (background jobs).
  for (int signal : {SIGINT, SIGTERM, SIGHUP}) std::signal(signal, on_run_signal);
  const InjectedSignal inject = parse_injected_signal(args.inject_signal);
  limit_model_calls(args.model_timeout);
  if (!args.inject_fault.empty()) arm_fault(args.inject_fault);
  if (!args.inject_io_error.empty()) arm_fault(args.inject_io_error, FaultKind::IoError);

  // Set-up writes nothing: a bad case, model, mesh or checkpoint leaves the directory as it was.
  CaseConfig config = read_case(args.case_file, args.sets);
  // The case and the files it names: a data file edited between a run and its --resume is another case.
  const std::string case_text =
      canonical_case(with_input_digests(config.effective, fs::path(args.case_file).parent_path()));
  const fs::path outdir =
      args.output_dir.empty() ? fs::path(fs::path(args.case_file).stem().string() + ".out") : fs::path(args.output_dir);
  const fs::path checkpoint = outdir / "checkpoint.bin";
  std::error_code ec;
  if (fs::equivalent(args.case_file, outdir / "case.toml", ec))  // the effective case would replace it
    throw InputError(fmt::format("{}: the output directory {} would overwrite the case file (its case.toml): choose "
                                 "another with -o",
                                 args.case_file, outdir.string()));
  OutputLock::check_free(outdir);
  if (!args.resume && !args.overwrite) refuse_used_directory(outdir);
  if (args.resume && !fs::exists(checkpoint))
    throw InputError(fmt::format("--resume: no checkpoint in {}: nothing to resume (run without --resume)",
                                 outdir.string()));

  // The model, S and its fixed reference, then T^0 (rebuilt on --resume too: it gives h for the CFL step).
  Run run(std::move(config), outdir);  // moved: a copy of a TOML table forgets where its values were written
  spdlog::info("model '{}' ({})", run.model()->name(), run.model().file().string());
  // The directory is this run's until it ends; a run that ended since the check above left its files.
  const OutputLock lock(outdir);
  if (!args.resume && !args.overwrite) refuse_used_directory(outdir);

  RunState start;
  std::optional<Checkpoint> resumed;
  if (args.resume) {
    resumed = load_checkpoint(checkpoint);
    check_same_case(*resumed, case_text, args.force, checkpoint);
    start = resumed->run;
  }
  GuardedModel& model = run.guarded(start.iteration);
  if (resumed && resumed->model) {
    model.load_state(*resumed->model);
  } else if (resumed) {
    spdlog::warn("{}: format {} checkpoint without model state: model '{}' starts afresh (results may differ "
                 "from an uninterrupted run)",
                 checkpoint.string(), resumed->format, model.name());
  }

  // From here on the directory is written.
  set_fault_iteration(start.iteration);
  prepare_directory(outdir, args, resumed ? start.iteration : -1, model.output_files());
  RunOutputs outputs(run.config(), outdir, model, case_text, &g_interrupted, inject);
  if (resumed) {
    run.mesh() = std::move(resumed->mesh);
    outputs.resume(run.mesh(), start, resumed->model.value_or(ModelState()));
    spdlog::info("resuming from iteration {} (t = {})", start.iteration, start.time);
  } else {
    outputs.begin(run.mesh());
  }
  write_atomically(outdir / "case.toml", [&](std::ostream& out) {
    out << "# effective case of `bodyfit run " << args.case_file << "` (after --set overrides)\n" << run.config().effective
        << "\n";
  });
  spdlog::info("h = {:.4g}, dt = {:.4g}, final time {}, {} faces", run.mesh_size(), run.options().dt,
               run.options().final_time, run.mesh().n_faces());

  // A line per iteration on the console, after its files are written.
  const bool terrain = run.config().surface.kind == SurfaceSpec::Kind::Terrain;  // metres and seconds
  Progress progress(run.options(), start, {.time_unit = terrain ? "s" : "", .length_unit = terrain ? "m" : "",
                                           .verbose = args.verbose});
  EvolutionHooks hooks = outputs.hooks();
  hooks.on_iteration = [write = hooks.on_iteration, &progress](const SurfaceMesh& m, const IterationRecord& r,
                                                               const RunState& state) {
    write(m, r, state);
    progress.iteration(r);
  };
  EvolutionResult result;
  try {
    result = run.evolve(start, hooks);
  } catch (const std::exception&) {
    outputs.report_checkpoint();
    throw;
  }
  progress.summary(result, outdir.string(), outputs.written());
  if (result.reason == StopReason::Interrupted) {
    spdlog::warn("iteration {} (t = {}) is complete and saved; continue with --resume", result.iteration, result.time);
    return int(ExitCode::Interrupted);
  }
  if (result.reason == StopReason::Rejected) {
    spdlog::error("stopped: {}", result.message);
    return int(ExitCode::Plugin);
  }
  return 0;
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
