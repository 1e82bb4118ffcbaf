// What a run leaves in its directory (run_outputs.hpp), written from the evolution's hooks.
#include <bodyfit/app/run_outputs.hpp>

#include <bodyfit/app/history.hpp>
#include <bodyfit/app/model_files.hpp>
#include <bodyfit/app/render.hpp>
#include <bodyfit/checkpoint_writer.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/fault_injection.hpp>
#include <bodyfit/io.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <csignal>
#include <optional>
#include <sstream>

namespace bodyfit {

namespace fs = std::filesystem;

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
  if (parts.size() >= 2)
    s.signal = parts[1] == "INT"    ? SIGINT
               : parts[1] == "TERM" ? SIGTERM
               : parts[1] == "HUP"  ? SIGHUP
               : parts[1] == "KILL" ? SIGKILL
                                    : 0;
  if (parts.size() == 3 && parts[2] == "scheduled") s.force_checkpoint = false;
  else if (parts.size() != 2) s.signal = 0;
  if (s.iteration < 0 || s.signal == 0)
    throw InputError(fmt::format("--inject-signal {}: expected ITERATION:SIGNAL (INT, TERM, HUP or KILL), optionally "
                                 "followed by :scheduled",
                                 text));
  return s;
}

struct RunOutputs::Impl {
  Impl(const CaseConfig& config, fs::path outdir, GuardedModel& model, const std::string& case_text,
       const std::atomic<bool>* stop, InjectedSignal inject)
      : config(config), outdir(std::move(outdir)), model(model), stop(stop), inject(inject),
        files(this->outdir, config.output.grid_format, model.outputs(), std::string(model.name())),
        checkpoints(this->outdir / "checkpoint.bin",
                    {.every = config.output.checkpoint_every, .seconds = config.output.checkpoint_seconds}, case_text),
        history(this->outdir / "history.csv") {}

  bool interrupted() const { return stop && stop->load(); }

  std::vector<double> png_field(const StateView& s) const {
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

  void on_state(const StateView& s) {
    set_fault_iteration(s.iteration);
    const auto& out = config.output;
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
      fault_point("vtu");  // the VTU without its .pvd entry
      pvd->add(s.time, name);
      fault_point("pvd");
      ++vtu_written;
    }
    if (out.png_every > 0 && (s.iteration % out.png_every == 0 || s.final)) {
      RenderOptions render_options;
      set_view(render_options, out.view);
      render_options.width = out.width, render_options.height = out.height;
      render_options.field = png_field(s);
      render_options.field_name = out.field;
      render_options.title = fmt::format("n = {}  t = {:.4g}", s.iteration, s.time);
      render_png(s.mesh, outdir / fmt::format("snap_{:05d}.png", s.iteration), render_options);
      ++png_written;
    }
  }

  void on_iteration(const SurfaceMesh& m, const IterationRecord& r, const RunState& run) {
    set_fault_iteration(r.iteration);
    // Saved at every iteration, whatever the cadence (computing the final state's fields changes
    // the model's state): the checkpoint of the end or of a failure is the iteration's own.
    ModelState state;
    model.save_state(state);
    const bool injected = r.iteration == inject.iteration;
    const bool due = checkpoints.due(r.iteration) || interrupted() || (injected && inject.force_checkpoint);
    // The loop's share of the checkpoint (waiting for the previous write, copying the state)
    // belongs to this row's ms_output; the evolution adds the hook's time only after the row
    // is written. The row goes to disk before the checkpoint, so that a resume finds its rows.
    IterationRecord row = r;
    if (due) row.ms.output += checkpoints.snapshot(m, run, &state);
    history.add(row);
    model_state = std::move(state);  // the iteration is complete: its row is on disk
    last_run = run;
    fault_point("row");  // the row without its checkpoint
    if (due) checkpoints.start();
    if (due && fault_armed("checkpoint")) checkpoints.wait(), fault_point("checkpoint");
    if (injected) {
      checkpoints.wait();
      std::raise(inject.signal);
    }
  }

  /// A failure while the mesh is still the last completed iteration: its checkpoint, so that
  /// everything up to it is on disk and --resume continues from it.
  void on_failure(const SurfaceMesh& m, const RunState& run) {
    if (run.iteration != last_run.iteration || checkpoints.last_iteration() == run.iteration) return;
    set_fault_iteration(run.iteration);
    checkpoint_last(m);
    checkpoints.wait();
  }

  /// The final outputs, before the model's finish(): a failing finish() cannot lose them.
  void on_end(const SurfaceMesh& m, const EvolutionResult& result) {
    set_fault_iteration(result.iteration);
    history.flush();  // row 0 of a run that made no iteration; the rows a resume kept
    if (checkpoints.last_iteration() != last_run.iteration) checkpoint_last(m);
    checkpoints.wait();
    if (result.reason == StopReason::Interrupted) return;
    fault_point("final");
    write_mesh(m, outdir / "final.mesh");
    fault_point("final-sol");
    write_scalar_sol(outdir / "final.sol", result.final_distance);
    fault_point("finish");
    final_written = true;
  }

  void checkpoint_last(const SurfaceMesh& mesh) {
    checkpoints.snapshot(mesh, last_run, &model_state);
    checkpoints.start();
  }

  const CaseConfig& config;
  const fs::path outdir;
  GuardedModel& model;
  const std::atomic<bool>* stop;
  const InjectedSignal inject;
  GridFiles files;
  CheckpointWriter checkpoints;
  RunHistory history;
  std::optional<PvdWriter> pvd;
  ModelState model_state;  ///< the model's state after the last completed iteration
  RunState last_run;       ///< the last completed iteration: its row is on disk
  int vtu_written = 0, png_written = 0;
  bool final_written = false;
};

RunOutputs::RunOutputs(const CaseConfig& config, fs::path outdir, GuardedModel& model, const std::string& case_text,
                       const std::atomic<bool>* stop, InjectedSignal inject)
    : impl_(std::make_unique<Impl>(config, std::move(outdir), model, case_text, stop, inject)) {}

RunOutputs::~RunOutputs() = default;

void RunOutputs::begin(const SurfaceMesh& mesh) {
  Impl& o = *impl_;
  o.model.save_state(o.model_state);
  o.checkpoints.snapshot(mesh, o.last_run, &o.model_state);
  o.checkpoints.start();
  o.checkpoints.wait();
  fault_point("checkpoint");  // the first checkpoint on disk, nothing else yet
  o.pvd.emplace(o.outdir / "series.pvd");
  o.history.add(measure_state(mesh, 0, 0));  // held back until iteration 1 names the model's columns
}

void RunOutputs::resume(const SurfaceMesh& mesh, const RunState& run, const ModelState& model_state) {
  Impl& o = *impl_;
  o.last_run = run;
  o.model_state = model_state;
  o.checkpoints.assume_written(run.iteration);
  if (!o.history.resume(run.iteration)) {
    if (run.iteration == 0) o.history.add(measure_state(mesh, 0, 0));  // killed before row 0 was written
    else spdlog::warn("{}: rows missing before iteration {}", (o.outdir / "history.csv").string(), run.iteration);
  }
  // The resumed run adds the checkpoint's state again. Exactly before it: a time within Δt/2 may
  // be an earlier state's, when the last step was shortened.
  o.pvd.emplace(PvdWriter::resume(o.outdir / "series.pvd", std::nextafter(run.time, -INFINITY)));
}

EvolutionHooks RunOutputs::hooks() {
  Impl* o = impl_.get();
  EvolutionHooks hooks;
  hooks.stop = o->stop;
  hooks.on_state = [o](const StateView& s) { o->on_state(s); };
  hooks.on_iteration = [o](const SurfaceMesh& m, const IterationRecord& r, const RunState& run) {
    o->on_iteration(m, r, run);
  };
  hooks.on_failure = [o](const SurfaceMesh& m, const RunState& run) { o->on_failure(m, run); };
  hooks.on_end = [o](const SurfaceMesh& m, const EvolutionResult& result) { o->on_end(m, result); };
  hooks.outputs = &o->files;
  return hooks;
}

void RunOutputs::report_checkpoint() {
  try {
    impl_->checkpoints.wait();
    spdlog::info("{} holds iteration {}: --resume continues from there", (impl_->outdir / "checkpoint.bin").string(),
                 impl_->checkpoints.last_iteration());
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
  }
}

std::vector<std::string> RunOutputs::written() const {
  const Impl& o = *impl_;
  std::vector<std::string> files;
  if (o.vtu_written) files.push_back(fmt::format("series.pvd + {} step_*.vtu", o.vtu_written));
  if (o.png_written) files.push_back(fmt::format("{} snap_*.png", o.png_written));
  files.push_back("history.csv");
  files.push_back("checkpoint.bin");
  files.push_back("case.toml");
  if (o.final_written) files.push_back("final.mesh + final.sol");
  std::error_code ec;
  for (const std::string& name : o.model.output_files())
    if (fs::exists(o.outdir / name, ec)) files.push_back(name);
  return files;
}

}  // namespace bodyfit
