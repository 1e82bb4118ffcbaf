// bodyfit run case.toml: the whole evolution (Algorithm 1) with its outputs (docs/running.md).
#include "commands.hpp"

#include <bodyfit/atomic_file.hpp>
#include <bodyfit/case_config.hpp>
#include <bodyfit/checkpoint_writer.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/history.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/plugin_loader.hpp>
#include <bodyfit/render.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <csignal>
#include <fstream>
#include <memory>
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

int run_case(const RunArguments& args) {
  // From the start (a Ctrl-C during setup stops before the first iteration), and even when the
  // shell started us with SIGINT ignored (background jobs).
  std::signal(SIGINT, on_sigint);
  CaseConfig config = read_case(args.case_file, args.sets);
  const fs::path outdir =
      args.output_dir.empty() ? fs::path(fs::path(args.case_file).stem().string() + ".out") : fs::path(args.output_dir);
  fs::create_directories(outdir);
  write_atomically(outdir / "case.toml", [&](std::ostream& out) {
    out << "# effective case of `bodyfit run " << args.case_file << "` (after --set overrides)\n" << config.effective << "\n";
  });

  LoadedModel model = load_model(config.model);
  configure_model(model, config.model_parameters);
  spdlog::info("model '{}' ({})", model->name(), model.file().string());

  // S and its fixed reference, then T^0 (rebuilt on --resume too: it gives h for the CFL step).
  CaseSetup setup = setup_case(config);
  SurfaceMesh& mesh = setup.mesh;
  EvolutionOptions& options = setup.options;
  const double h = setup.h;
  options.output_dir = outdir;
  options.terrain = config.surface.kind == SurfaceSpec::Kind::Terrain;

  const fs::path checkpoint = outdir / "checkpoint.bin";
  const auto& out = config.output;
  // Checkpoints as the cadence asks, written in the background; the one of the last completed
  // iteration is always written at the end (an interruption included).
  CheckpointWriter checkpoints(checkpoint, {.every = out.checkpoint_every, .seconds = out.checkpoint_seconds});
  RunHistory history(outdir / "history.csv");
  std::unique_ptr<PvdWriter> pvd;
  RunState start;
  // The model's state after the last completed iteration, saved at every iteration as before the
  // cadence (computing the final state's fields changes it), so that the end-of-run checkpoint is
  // exactly the one the iteration's hook would have written.
  ModelState model_state;
  if (args.resume) {
    if (!fs::exists(checkpoint))
      throw InputError(fmt::format("--resume: no checkpoint in {} (run without --resume first)", outdir.string()));
    Checkpoint c = load_checkpoint(checkpoint);
    mesh = std::move(c.mesh);
    start = c.run;
    if (c.model) {
      model->load_state(*c.model);
      model_state = *c.model;
    } else {
      spdlog::warn("{}: format {} checkpoint without model state: model '{}' starts afresh (results may differ "
                   "from an uninterrupted run)",
                   checkpoint.string(), c.format, model->name());
    }
    checkpoints.assume_written(c.run.iteration);
    if (!history.resume(c.run.iteration)) {
      if (c.run.iteration == 0) history.add(measure_state(mesh, 0, 0));  // killed before row 0 was written
      else spdlog::warn("{}: rows missing before iteration {}", (outdir / "history.csv").string(), c.run.iteration);
    }
    pvd = std::make_unique<PvdWriter>(PvdWriter::resume(outdir / "series.pvd", c.run.time - 0.5 * options.dt));
    spdlog::info("resuming from iteration {} (t = {})", c.run.iteration, c.run.time);
  } else {
    pvd = std::make_unique<PvdWriter>(outdir / "series.pvd");
    model->save_state(model_state);
    checkpoints.snapshot(mesh, start, &model_state);
    checkpoints.start();
    history.add(measure_state(mesh, 0, 0));
  }
  spdlog::info("h = {:.4g}, dt = {:.4g}, final time {}, {} faces", h, options.dt, options.final_time, mesh.n_faces());

  EvolutionHooks hooks;
  hooks.stop = &g_interrupted;
  hooks.on_state = [&](const StateView& s) {
    if (out.vtu_every > 0 && (s.iteration % out.vtu_every == 0 || s.final)) {
      VtuFields fields;
      fields.point_scalars.emplace_back("d", s.distance);
      if (s.velocity) fields.point_vectors.emplace_back("velocity", *s.velocity);
      if (s.model) {
        for (const auto& f : s.model->point_fields) fields.point_scalars.push_back(f);
        for (const auto& f : s.model->vector_fields) fields.point_vectors.push_back(f);
      }
      const std::string name = fmt::format("step_{:05d}.vtu", s.iteration);
      write_vtu(s.mesh, outdir / name, fields);
      pvd->add(s.time, name);
    }
    if (out.png_every > 0 && (s.iteration % out.png_every == 0 || s.final)) {
      RenderOptions render_options;
      set_view(render_options, out.view);
      render_options.width = out.width, render_options.height = out.height;
      render_options.field = png_field(config, s);
      render_options.field_name = out.field;
      render_options.title = fmt::format("n = {}  t = {:.4g}", s.iteration, s.time);
      render_png(s.mesh, outdir / fmt::format("snap_{:05d}.png", s.iteration), render_options);
    }
  };
  const InjectedSignal inject = parse_injected_signal(args.inject_signal);
  RunState last_run = start;
  hooks.on_iteration = [&](const SurfaceMesh& m, const IterationRecord& r, const RunState& run) {
    last_run = run;
    model_state = ModelState();
    model->save_state(model_state);
    const bool injected = r.iteration == inject.iteration;
    const bool due = checkpoints.due(r.iteration) || g_interrupted.load() || (injected && inject.force_checkpoint);
    // The loop's share of the checkpoint (waiting for the previous write, copying the state)
    // belongs to this row's ms_output; the evolution adds the hook's time only after the row
    // is written. The row goes to disk before the checkpoint, so that a resume finds its rows.
    IterationRecord row = r;
    if (due) row.ms.output += checkpoints.snapshot(m, run, &model_state);
    history.add(row);
    if (due) checkpoints.start();
    if (injected) {
      checkpoints.wait();
      std::raise(inject.signal);
    }
  };

  // An exception thrown in the plugin may carry a vtable of the plugin's own, which is unloaded
  // when `model` goes out of scope: copy the message into an exception of ours while it is loaded.
  EvolutionResult result;
  try {
    result = evolve(mesh, model.model(), options, start, hooks);
  } catch (const InputError& e) {
    throw InputError(e.what());
  } catch (const std::exception& e) {
    throw PluginError(fmt::format("model '{}': {}", model->name(), e.what()));
  } catch (...) {
    throw PluginError(fmt::format("model '{}' threw an exception that is not a std::exception", model->name()));
  }
  if (history.rows() == 1) history.flush();
  if (checkpoints.last_iteration() != last_run.iteration) {
    checkpoints.snapshot(mesh, last_run, &model_state);
    checkpoints.start();
  }
  checkpoints.wait();

  if (result.reason == StopReason::Interrupted) {
    spdlog::warn("interrupted: iteration {} (t = {}) is complete and saved; continue with --resume", result.iteration,
                 result.time);
    return 130;
  }
  write_mesh(mesh, outdir / "final.mesh");
  write_scalar_sol(outdir / "final.sol", result.final_distance);
  if (result.reason == StopReason::Rejected) {
    spdlog::error("stopped: {}; outputs in {}", result.message, outdir.string());
    return 4;
  }
  spdlog::info("done: {} after iteration {} (t = {}); outputs in {}", result.message, result.iteration, result.time,
               outdir.string());
  return 0;
}

bodyfit::cli::Command setup_run(CLI::App& app) {
  auto* cmd = app.add_subcommand("run", "run a case: evolve the region G(t) with a velocity model (docs/running.md)");
  auto args = std::make_shared<RunArguments>();
  cmd->add_option("case", args->case_file, "case file (.toml)")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", args->output_dir, "output directory (default: <case name>.out)");
  cmd->add_option("--set", args->sets, "override a key of the case, e.g. --set time.dt=0.05 (repeatable)");
  cmd->add_flag("--resume", args->resume, "continue from the last completed iteration in the output directory");
  // A test hook (no group: hidden from --help): a crash or Ctrl-C at a known point of the run.
  cmd->add_option("--inject-signal", args->inject_signal, "")->group("");
  return {cmd, [args]() { return run_case(*args); }};
}

BODYFIT_COMMAND(80, setup_run);

}  // namespace
