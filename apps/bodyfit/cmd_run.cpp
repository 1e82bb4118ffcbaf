// bodyfit run case.toml: the whole evolution (Algorithm 1) with its outputs (docs/running.md).
#include "commands.hpp"

#include <bodyfit/atomic_file.hpp>
#include <bodyfit/case_config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/evolution.hpp>
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
};

const char* kHistoryColumns =
    "iteration,time,dt,area,interface_length,components,min_quality,mean_quality,vertices,faces,"
    "ms_velocity,ms_distance,ms_advect,ms_discretize,ms_remesh,ms_output,ms_total";

/// history.csv: header + one row per state, rewritten atomically after every iteration.
class History {
 public:
  explicit History(fs::path file) : file_(std::move(file)) {}

  /// Keep the rows of an earlier run up to `last_iteration` (for --resume).
  void resume(int last_iteration) {
    std::ifstream in(file_);
    std::string line;
    if (!std::getline(in, header_)) return;
    while (std::getline(in, line)) {
      if (line.empty()) continue;
      if (std::stoi(line.substr(0, line.find(','))) <= last_iteration) rows_.push_back(line);
    }
  }
  void add(const IterationRecord& r) {
    if (header_.empty() || (metric_names_.empty() && !r.metrics.empty() && rows_.size() <= 1)) {
      header_ = kHistoryColumns;
      metric_names_.clear();
      for (const auto& [name, value] : r.metrics) header_ += "," + name, metric_names_.push_back(name);
    } else if (metric_names_.empty()) {
      // After a resume: recover the metric names from the header.
      std::stringstream ss(header_.substr(std::string(kHistoryColumns).size()));
      for (std::string name; std::getline(ss, name, ',');)
        if (!name.empty()) metric_names_.push_back(name);
    }
    std::string row = fmt::format("{},{:.17g},{:.17g},{:.17g},{:.17g},{},{:.6g},{:.6g},{},{},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f}",
                                  r.iteration, r.time, r.dt, r.area, r.interface_length, r.components, r.min_quality,
                                  r.mean_quality, r.vertices, r.faces, r.ms.velocity, r.ms.distance, r.ms.advect,
                                  r.ms.discretize, r.ms.remesh, r.ms.output, r.ms.total());
    for (const auto& name : metric_names_) {
      row += ",";
      for (const auto& [n, v] : r.metrics)
        if (n == name) row += fmt::format("{:.10g}", v);
    }
    rows_.push_back(row);
    write_atomically(file_, [&](std::ostream& out) {
      out << header_ << "\n";
      for (const auto& line : rows_) out << line << "\n";
    });
  }

 private:
  fs::path file_;
  std::string header_;
  std::vector<std::string> metric_names_;
  std::vector<std::string> rows_;
};

std::vector<double> png_field(const CaseConfig& config, const StateView& s) {
  const auto& name = config.output.field;
  if (name == "region") return {};
  if (name == "d") return s.distance;
  if (s.model_fields)
    for (const auto& [n, values] : *s.model_fields)
      if (n == name) return values;
  auto field = named_vertex_field(s.mesh, name);
  if (field.empty() && s.model_fields) {
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
  options.stop = &g_interrupted;

  const fs::path checkpoint = outdir / "checkpoint.bin";
  History history(outdir / "history.csv");
  std::unique_ptr<PvdWriter> pvd;
  if (args.resume) {
    if (!fs::exists(checkpoint))
      throw InputError(fmt::format("--resume: no checkpoint in {} (run without --resume first)", outdir.string()));
    Checkpoint c = load_checkpoint(checkpoint);
    mesh = std::move(c.mesh);
    options.start_iteration = c.iteration;
    options.start_time = c.time;
    history.resume(c.iteration);
    pvd = std::make_unique<PvdWriter>(PvdWriter::resume(outdir / "series.pvd", c.time - 0.5 * options.dt));
    spdlog::info("resuming from iteration {} (t = {})", c.iteration, c.time);
  } else {
    pvd = std::make_unique<PvdWriter>(outdir / "series.pvd");
    save_checkpoint(checkpoint, mesh, 0, 0);
    history.add(measure_state(mesh, 0, 0));
  }
  spdlog::info("h = {:.4g}, dt = {:.4g}, final time {}, {} faces", h, options.dt, options.final_time, mesh.n_faces());

  const auto& out = config.output;
  options.on_state = [&](const StateView& s) {
    const bool last = s.velocity == nullptr;
    if (out.vtu_every > 0 && (s.iteration % out.vtu_every == 0 || last)) {
      VtuFields fields;
      fields.point_scalars.emplace_back("d", s.distance);
      if (s.velocity) fields.point_vectors.emplace_back("velocity", *s.velocity);
      if (s.model_fields)
        for (const auto& f : *s.model_fields) fields.point_scalars.push_back(f);
      const std::string name = fmt::format("step_{:05d}.vtu", s.iteration);
      write_vtu(s.mesh, outdir / name, fields);
      pvd->add(s.time, name);
    }
    if (out.png_every > 0 && (s.iteration % out.png_every == 0 || last)) {
      RenderOptions render_options;
      set_view(render_options, out.view);
      render_options.width = out.width, render_options.height = out.height;
      render_options.field = png_field(config, s);
      render_options.field_name = out.field;
      render_options.title = fmt::format("n = {}  t = {:.4g}", s.iteration, s.time);
      render_png(s.mesh, outdir / fmt::format("snap_{:05d}.png", s.iteration), render_options);
    }
  };
  options.on_iteration = [&](const SurfaceMesh& m, const IterationRecord& r) {
    history.add(r);
    save_checkpoint(checkpoint, m, r.iteration, r.time);
  };

  EvolutionResult result = evolve(mesh, model.model(), options);

  if (result.reason == StopReason::Interrupted) {
    spdlog::warn("interrupted: iteration {} (t = {}) is complete and saved; continue with --resume", result.iteration,
                 result.time);
    return 130;
  }
  write_mesh(mesh, outdir / "final.mesh");
  write_scalar_sol(outdir / "final.sol", result.final_distance);
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
  return {cmd, [args]() { return run_case(*args); }};
}

BODYFIT_COMMAND(80, setup_run);

}  // namespace
