// bodyfit run case.toml: the whole evolution (Algorithm 1) with its outputs (docs/running.md).
#include "commands.hpp"

#include <bodyfit/atomic_file.hpp>
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/app/case_identity.hpp>
#include <bodyfit/checkpoint_writer.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/fault_injection.hpp>
#include <bodyfit/app/history.hpp>
#include <bodyfit/app/model_files.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/model_guard.hpp>
#include <bodyfit/plugin_loader.hpp>
#include <bodyfit/app/render.hpp>
#include <bodyfit/app/run_directory.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

namespace {

namespace fs = std::filesystem;
using namespace bodyfit;

std::atomic<bool> g_interrupted{false};
extern "C" void on_sigint(int) { g_interrupted.store(true); }

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
};

/// The test hook of --inject-signal: the iteration and the signal it raises once that iteration's
/// history row and checkpoint are written (SIGINT exercises the clean stop, SIGKILL a crash
/// between two iterations). With ":scheduled" iteration N gets a checkpoint only if the cadence
/// asks for one (a crash between two checkpoints); the write in flight, if any, completes first.
struct InjectedSignal {
  int iteration = -1;
  int signal = 0;
  bool force_checkpoint = true;
};
InjectedSignal parse_injected_signal(const std::string& text) {
  if (text.empty()) return {};
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, ':');) parts.push_back(part);
  InjectedSignal s;
  try {
    if (parts.size() >= 2) s.iteration = std::stoi(parts[0]);
  } catch (const std::exception&) {
    s.iteration = -1;
  }
  if (parts.size() >= 2) s.signal = parts[1] == "INT" ? SIGINT : parts[1] == "KILL" ? SIGKILL : 0;
  if (parts.size() == 3 && parts[2] == "scheduled") s.force_checkpoint = false;
  else if (parts.size() != 2) s.signal = 0;
  if (s.iteration < 0 || s.signal == 0)
    throw InputError(fmt::format("--inject-signal {}: expected ITERATION:INT or ITERATION:KILL, optionally followed "
                                 "by :scheduled",
                                 text));
  return s;
}

std::vector<double> png_field(const CaseConfig& config, const StateView& s) {
  const auto& name = config.output.field;
  if (name == "region") return {};
  if (name == "d") return s.distance;
  if (s.model)
    for (const auto& [n, values] : s.model->point_fields)
      if (n == name) return values;
  auto field = named_vertex_field(s.mesh, name);
  if (field.empty() && s.model) {
    static bool warned = false;
    if (!warned) spdlog::warn("[output] field '{}' is not known; colouring by region", name), warned = true;
  }
  return field;
}

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
  std::vector<std::string> refused;
  for (const CaseChange& change : case_changes(c.case_text, case_text)) {
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

/// What a run leaves in its directory, written from the evolution's hooks: a VTU and its .pvd
/// entry per state, a history row per iteration, checkpoints on the cadence (and always of the
/// last completed iteration: at the end, on Ctrl-C, on a failure that leaves it in memory), PNG
/// snapshots and the final mesh. The named fault points are those of docs/running.md.
class RunOutputs {
 public:
  RunOutputs(const CaseConfig& config, fs::path outdir, GuardedModel& model, const std::string& case_text,
             InjectedSignal inject)
      : config_(config), outdir_(std::move(outdir)), model_(model), inject_(inject),
        files_(outdir_, config.output.grid_format, model.outputs(), std::string(model.name())),
        checkpoints_(outdir_ / "checkpoint.bin",
                     {.every = config.output.checkpoint_every, .seconds = config.output.checkpoint_seconds}, case_text),
        history_(outdir_ / "history.csv") {}

  /// A new run: the checkpoint of the start, first and waited for (any other file of the run then
  /// comes with a checkpoint to resume from), then row 0.
  void begin(const SurfaceMesh& mesh) {
    model_.save_state(model_state_);
    checkpoints_.snapshot(mesh, last_run_, &model_state_);
    checkpoints_.start();
    checkpoints_.wait();
    fault_point("checkpoint");  // the first checkpoint on disk, nothing else yet
    pvd_.emplace(outdir_ / "series.pvd");
    history_.add(measure_state(mesh, 0, 0));  // held back until iteration 1 names the model's columns
  }

  /// A resumed run: the rows and the .pvd entries before the checkpoint's state.
  void resume(const SurfaceMesh& mesh, const RunState& run, const ModelState& model_state) {
    last_run_ = run;
    model_state_ = model_state;
    checkpoints_.assume_written(run.iteration);
    if (!history_.resume(run.iteration)) {
      if (run.iteration == 0) history_.add(measure_state(mesh, 0, 0));  // killed before row 0 was written
      else spdlog::warn("{}: rows missing before iteration {}", (outdir_ / "history.csv").string(), run.iteration);
    }
    // The resumed run adds the checkpoint's state again. Exactly before it: a time within Δt/2 may
    // be an earlier state's, when the last step was shortened.
    pvd_.emplace(PvdWriter::resume(outdir_ / "series.pvd", std::nextafter(run.time, -INFINITY)));
  }

  EvolutionHooks hooks() {
    EvolutionHooks hooks;
    hooks.stop = &g_interrupted;
    hooks.on_state = [this](const StateView& s) { on_state(s); };
    hooks.on_iteration = [this](const SurfaceMesh& m, const IterationRecord& r, const RunState& run) {
      on_iteration(m, r, run);
    };
    hooks.on_failure = [this](const SurfaceMesh& m, const RunState& run) { on_failure(m, run); };
    hooks.on_end = [this](const SurfaceMesh& m, const EvolutionResult& result) { on_end(m, result); };
    hooks.outputs = &files_;
    return hooks;
  }

  /// After a failure: the write in flight completed, where a resume would start.
  void report_checkpoint() {
    try {
      checkpoints_.wait();
      spdlog::info("{} holds iteration {}: --resume continues from there", (outdir_ / "checkpoint.bin").string(),
                   checkpoints_.last_iteration());
    } catch (const std::exception& e) {
      spdlog::error("{}", e.what());
    }
  }

 private:
  void on_state(const StateView& s) {
    set_fault_iteration(s.iteration);
    const auto& out = config_.output;
    if (out.vtu_every > 0 && (s.iteration % out.vtu_every == 0 || s.final)) {
      VtuFields fields;
      fields.point_scalars.emplace_back("d", s.distance);
      if (s.velocity) fields.point_vectors.emplace_back("velocity", *s.velocity);
      if (s.model) {
        for (const auto& f : s.model->point_fields) fields.point_scalars.push_back(f);
        for (const auto& f : s.model->vector_fields) fields.point_vectors.push_back(f);
      }
      const std::string name = fmt::format("step_{:05d}.vtu", s.iteration);
      write_vtu(s.mesh, outdir_ / name, fields);
      fault_point("vtu");  // the VTU without its .pvd entry
      pvd_->add(s.time, name);
      fault_point("pvd");
    }
    if (out.png_every > 0 && (s.iteration % out.png_every == 0 || s.final)) {
      RenderOptions render_options;
      set_view(render_options, out.view);
      render_options.width = out.width, render_options.height = out.height;
      render_options.field = png_field(config_, s);
      render_options.field_name = out.field;
      render_options.title = fmt::format("n = {}  t = {:.4g}", s.iteration, s.time);
      render_png(s.mesh, outdir_ / fmt::format("snap_{:05d}.png", s.iteration), render_options);
    }
  }

  void on_iteration(const SurfaceMesh& m, const IterationRecord& r, const RunState& run) {
    set_fault_iteration(r.iteration);
    // Saved at every iteration, whatever the cadence (computing the final state's fields changes
    // the model's state): the checkpoint of the end or of a failure is the iteration's own.
    ModelState state;
    model_.save_state(state);
    const bool injected = r.iteration == inject_.iteration;
    const bool due = checkpoints_.due(r.iteration) || g_interrupted.load() || (injected && inject_.force_checkpoint);
    // The loop's share of the checkpoint (waiting for the previous write, copying the state)
    // belongs to this row's ms_output; the evolution adds the hook's time only after the row
    // is written. The row goes to disk before the checkpoint, so that a resume finds its rows.
    IterationRecord row = r;
    if (due) row.ms.output += checkpoints_.snapshot(m, run, &state);
    history_.add(row);
    model_state_ = std::move(state);  // the iteration is complete: its row is on disk
    last_run_ = run;
    fault_point("row");  // the row without its checkpoint
    if (due) checkpoints_.start();
    if (due && fault_armed("checkpoint")) checkpoints_.wait(), fault_point("checkpoint");
    if (injected) {
      checkpoints_.wait();
      std::raise(inject_.signal);
    }
  }

  /// A failure while the mesh is still the last completed iteration: its checkpoint, so that
  /// everything up to it is on disk and --resume continues from it.
  void on_failure(const SurfaceMesh& m, const RunState& run) {
    if (run.iteration != last_run_.iteration || checkpoints_.last_iteration() == run.iteration) return;
    set_fault_iteration(run.iteration);
    checkpoint_last(m);
    checkpoints_.wait();
  }

  /// The final outputs, before the model's finish(): a failing finish() cannot lose them.
  void on_end(const SurfaceMesh& m, const EvolutionResult& result) {
    set_fault_iteration(result.iteration);
    history_.flush();  // row 0 of a run that made no iteration; the rows a resume kept
    if (checkpoints_.last_iteration() != last_run_.iteration) checkpoint_last(m);
    checkpoints_.wait();
    if (result.reason == StopReason::Interrupted) return;
    fault_point("final");
    write_mesh(m, outdir_ / "final.mesh");
    fault_point("final-sol");
    write_scalar_sol(outdir_ / "final.sol", result.final_distance);
    fault_point("finish");
  }

  void checkpoint_last(const SurfaceMesh& mesh) {
    checkpoints_.snapshot(mesh, last_run_, &model_state_);
    checkpoints_.start();
  }

  const CaseConfig& config_;
  const fs::path outdir_;
  GuardedModel& model_;
  const InjectedSignal inject_;
  GridFiles files_;  ///< the model's grids, written as files when it finishes
  CheckpointWriter checkpoints_;
  RunHistory history_;
  std::optional<PvdWriter> pvd_;
  ModelState model_state_;  ///< the model's state after the last completed iteration
  RunState last_run_;       ///< the last completed iteration: its row is on disk
};

int run_case(const RunArguments& args) {
  // From the start (a Ctrl-C during setup stops before the first iteration), and even when the
  // shell started us with SIGINT ignored (background jobs).
  std::signal(SIGINT, on_sigint);
  const InjectedSignal inject = parse_injected_signal(args.inject_signal);
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
  if (!args.resume && !args.overwrite) refuse_used_directory(outdir);
  if (args.resume && !fs::exists(checkpoint))
    throw InputError(fmt::format("--resume: no checkpoint in {}: nothing to resume (run without --resume)",
                                 outdir.string()));

  LoadedModel model = load_model(config.model);
  report_model_crashes(std::string(model->name()));
  {
    PluginCall call("configure", -1);
    configure_model(model, config.model_parameters, case_surface_source(config));
  }
  spdlog::info("model '{}' ({})", model->name(), model.file().string());

  // S and its fixed reference, then T^0 (rebuilt on --resume too: it gives h for the CFL step).
  CaseSetup setup = setup_case(config);
  SurfaceMesh& mesh = setup.mesh;
  EvolutionOptions& options = setup.options;
  options.output_dir = outdir;
  options.height_field = config.surface.kind == SurfaceSpec::Kind::Terrain;

  RunState start;
  std::optional<Checkpoint> resumed;
  if (args.resume) {
    resumed = load_checkpoint(checkpoint);
    check_same_case(*resumed, case_text, args.force, checkpoint);
    start = resumed->run;
  }
  GuardedModel guarded(model.model(), start.iteration);
  if (resumed && resumed->model) {
    guarded.load_state(*resumed->model);
  } else if (resumed) {
    spdlog::warn("{}: format {} checkpoint without model state: model '{}' starts afresh (results may differ "
                 "from an uninterrupted run)",
                 checkpoint.string(), resumed->format, model->name());
  }

  // From here on the directory is written.
  set_fault_iteration(start.iteration);
  const std::vector<std::string> model_files = model->output_files();
  prepare_directory(outdir, args, resumed ? start.iteration : -1, model_files);
  RunOutputs outputs(config, outdir, guarded, case_text, inject);
  if (resumed) {
    mesh = std::move(resumed->mesh);
    outputs.resume(mesh, start, resumed->model.value_or(ModelState()));
    spdlog::info("resuming from iteration {} (t = {})", start.iteration, start.time);
  } else {
    outputs.begin(mesh);
  }
  write_atomically(outdir / "case.toml", [&](std::ostream& out) {
    out << "# effective case of `bodyfit run " << args.case_file << "` (after --set overrides)\n" << config.effective << "\n";
  });
  spdlog::info("h = {:.4g}, dt = {:.4g}, final time {}, {} faces", setup.h, options.dt, options.final_time,
               mesh.n_faces());

  const EvolutionHooks hooks = outputs.hooks();
  EvolutionResult result;
  try {
    result = evolve(mesh, guarded, options, start, hooks);
  } catch (const std::exception&) {
    outputs.report_checkpoint();
    throw;
  }
  if (result.reason == StopReason::Interrupted) {
    spdlog::warn("interrupted: iteration {} (t = {}) is complete and saved; continue with --resume", result.iteration,
                 result.time);
    return int(ExitCode::Interrupted);
  }
  if (result.reason == StopReason::Rejected) {
    spdlog::error("stopped: {}; outputs in {}", result.message, outdir.string());
    return int(ExitCode::Plugin);
  }
  spdlog::info("done: {} after iteration {} (t = {}); outputs in {}", result.message, result.iteration, result.time,
               outdir.string());
  return 0;
}

bodyfit::cli::Command setup_run(CLI::App& app) {
  auto* cmd = app.add_subcommand("run", "run a case: evolve the region G(t) with a velocity model (docs/running.md)");
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
  // Test hooks (no group: hidden from --help): a crash or Ctrl-C at a known point of the run.
  cmd->add_option("--inject-signal", args->inject_signal, "")->group("");
  cmd->add_option("--inject-fault", args->inject_fault, "")->group("");
  cmd->add_option("--inject-io-error", args->inject_io_error, "")->group("")->excludes("--inject-fault");
  return {cmd, [args]() { return run_case(*args); }};
}

BODYFIT_COMMAND(80, setup_run);

}  // namespace
