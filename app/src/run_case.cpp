// A case run into its output directory (run_case.hpp).
#include <bodyfit/app/run_case.hpp>

#include <bodyfit/app/case_identity.hpp>
#include <bodyfit/app/output_lock.hpp>
#include <bodyfit/app/progress.hpp>
#include <bodyfit/app/run_directory.hpp>
#include <bodyfit/atomic_file.hpp>
#include <bodyfit/checkpoint.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/fault_injection.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <fstream>

namespace bodyfit {
namespace {

namespace fs = std::filesystem;

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
void prepare_directory(const fs::path& outdir, const RunRequest& args, int resumed_iteration,
                       const std::vector<std::string>& model_files) {
  std::error_code ec;
  fs::create_directories(outdir, ec);
  if (ec) throw IoError(fmt::format("{}: cannot create the output directory ({})", outdir.string(), ec.message()));
  if (args.overwrite) remove_run_outputs(outdir, model_files);
  if (const std::size_t n = remove_stale_temporaries(outdir))
    spdlog::info("{}: removed {} temporary files of interrupted writes", outdir.string(), n);
  if (resumed_iteration >= 0) remove_states_from(outdir, resumed_iteration);
}

CaseConfig read_request_case(const RunRequest& request) {
  if (!request.case_table) return read_case(request.case_file, request.sets);
  toml::table table = *request.case_table;
  for (const auto& assignment : request.sets) apply_override(table, assignment);
  return parse_case(table, request.case_dir);
}

}  // namespace

RunOutcome run_case(const RunRequest& args) {
  // Set-up writes nothing: a bad case, model, mesh or checkpoint leaves the directory as it was.
  CaseConfig config = read_request_case(args);
  const fs::path base_dir = args.case_table ? args.case_dir : args.case_file.parent_path();
  // The case and the files it names: a data file edited between a run and its --resume is another case.
  const std::string case_text = canonical_case(with_input_digests(config.effective, base_dir));
  const std::string case_name = args.case_file.empty() ? std::string("case") : args.case_file.string();
  if (args.output_dir.empty() && args.case_file.empty())
    throw InputError("a case given as a table needs an output directory");
  const fs::path outdir =
      args.output_dir.empty() ? fs::path(fs::path(args.case_file).stem().string() + ".out") : args.output_dir;
  const fs::path checkpoint = outdir / "checkpoint.bin";
  std::error_code ec;
  if (!args.case_file.empty() && fs::equivalent(args.case_file, outdir / "case.toml", ec))  // the effective case would replace it
    throw InputError(fmt::format("{}: the output directory {} would overwrite the case file (its case.toml): choose "
                                 "another with -o",
                                 case_name, outdir.string()));
  OutputLock::check_free(outdir);
  if (!args.resume && !args.overwrite) refuse_used_directory(outdir);
  if (args.resume && !fs::exists(checkpoint))
    throw InputError(fmt::format("--resume: no checkpoint in {}: nothing to resume (run without --resume)",
                                 outdir.string()));

  // The model, S and its fixed reference, then T^0 (rebuilt on --resume too: it gives h for the CFL step).
  Run run(std::move(config), outdir, args.load_model);  // moved: a copy of a TOML table forgets where its values were written
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
  RunOutputs outputs(run.config(), outdir, model, case_text, args.interrupted, args.inject);
  if (resumed) {
    run.mesh() = std::move(resumed->mesh);
    outputs.resume(run.mesh(), start, resumed->model.value_or(ModelState()));
    spdlog::info("resuming from iteration {} (t = {})", start.iteration, start.time);
  } else {
    outputs.begin(run.mesh());
  }
  write_atomically(outdir / "case.toml", [&](std::ostream& out) {
    out << "# effective case of `bodyfit run " << case_name << "` (after --set overrides)\n" << run.config().effective
        << "\n";
  });
  spdlog::info("h = {:.4g}, dt = {:.4g}, final time {}, {} faces", run.mesh_size(), run.options().dt,
               run.options().final_time, run.mesh().n_faces());

  // A line per iteration on the console, after its files are written.
  const bool terrain = run.config().surface.kind == SurfaceSpec::Kind::Terrain;  // metres and seconds
  Progress progress(run.options(), start, {.time_unit = terrain ? "s" : "", .length_unit = terrain ? "m" : "",
                                           .verbose = args.verbose});
  EvolutionHooks hooks = outputs.hooks();
  if (args.progress)
    hooks.on_iteration = [write = hooks.on_iteration, &progress](const SurfaceMesh& m, const IterationRecord& r,
                                                                 const RunState& state) {
      write(m, r, state);
      progress.iteration(r);
    };
  RunOutcome outcome;
  outcome.output_dir = outdir;
  try {
    outcome.result = run.evolve(start, hooks);
  } catch (const std::exception&) {
    outputs.report_checkpoint();
    throw;
  }
  if (args.progress) progress.summary(outcome.result, outdir.string(), outputs.written());
  if (outcome.result.reason == StopReason::Interrupted) {
    spdlog::warn("iteration {} (t = {}) is complete and saved; continue with --resume", outcome.result.iteration,
                 outcome.result.time);
    outcome.exit_code = int(ExitCode::Interrupted);
  } else if (outcome.result.reason == StopReason::Rejected) {
    spdlog::error("stopped: {}", outcome.result.message);
    outcome.exit_code = int(ExitCode::Plugin);
  }
  return outcome;
}

}  // namespace bodyfit
