// Thermal shape optimisation: the time of one iteration split by stage, at several mesh sizes.
//
//   bench_thermal [--case meshes/cases/thermal_bracket_fine.toml] [--h 0.05,0.035,0.025]
//                 [--iterations 8] [--solver conjugate_gradient] [--set KEY=VALUE ...] [-o thermal_timing.csv]
//
// For each h the case runs with remesh.hmax = h and epsilon = 2h; the medians over the iterations
// of the driver's stages (velocity = the model's compute: regularisation, plus its solve on the first
// state; review = tetrahedralisation, assembly, factorisation and solves of the candidate) and of the
// model's own split (history.csv's ms_tetgen, ms_assembly, ms_factor, ms_solve, ms_regularise) are
// printed and written as CSV, with the tetrahedra and surface triangles.
#include "bench_args.hpp"

#include <bodyfit/app/case_config.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/plugin_loader.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <map>

using namespace bodyfit;

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

}  // namespace

int main(int argc, char** argv) try {
  std::filesystem::path case_file = "meshes/cases/thermal_bracket_fine.toml", csv_file = "thermal_timing.csv";
  std::vector<double> hs = {0.05, 0.035, 0.025};
  int iterations = 8;
  std::string solver = "conjugate_gradient";
  bench::Arguments args("bench_thermal",
                        "usage: bench_thermal [--case file.toml] [--h 0.05,0.035,0.025] [--iterations 8] [--solver name] "
                        "[--set KEY=VALUE ...] [-o thermal_timing.csv]\n"
                        "  --case        thermal case (default meshes/cases/thermal_bracket_fine.toml)\n"
                        "  --h           hmax values, one row each (epsilon = 2h)\n"
                        "  --iterations  iterations per size; times are their median (default 8)\n"
                        "  --solver      the model's linear solver (default conjugate_gradient)\n"
                        "  --set         a case value for every size, as bodyfit run --set (repeatable)\n"
                        "  -o            CSV output (default thermal_timing.csv)\n");
  args.option("--case", case_file);
  args.option("--h", hs);
  args.option("--iterations", iterations);
  args.option("--solver", solver);
  std::vector<std::string> sets;
  args.option("--set", [&](const std::string& value) { sets.push_back(value); });
  args.option("-o", csv_file);
  args.parse(argc, argv);
  spdlog::set_level(spdlog::level::warn);
  const std::vector<std::string> model_columns = {"ms_tetgen", "ms_assembly", "ms_factor", "ms_solve", "ms_regularise"};
  std::ofstream csv(csv_file);
  csv << "h,faces,tets,iterations,ms_velocity,ms_distance,ms_advect,ms_discretize,ms_remesh,ms_review,ms_total,"
         "ms_tetgen,ms_assembly,ms_factor,ms_solve,ms_regularise\n";
  fmt::print("{:>7} {:>7} {:>7} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8}  (median ms per iteration)\n", "h",
             "faces", "tets", "tetgen", "assembly", "factor", "solve", "regul.", "remesh", "other", "review", "total");
  for (double h : hs) {
    std::vector<std::string> overrides = {fmt::format("remesh.hmax={}", h), fmt::format("model.epsilon={}", 2 * h),
                                          fmt::format("model.epsilon_final={}", 2 * h),
                                          fmt::format("time.iterations={}", iterations),
                                          fmt::format("model.solver=\"{}\"", solver), "model.patience=1000"};
    overrides.insert(overrides.end(), sets.begin(), sets.end());
    CaseConfig config = read_case(case_file, overrides);
    LoadedModel model = load_model(config.model);
    configure_model(model, config.model_parameters);
    CaseSetup setup = setup_case(config);
    std::map<std::string, std::vector<double>> samples;
    EvolutionHooks hooks = EvolutionHooks::quiet();
    hooks.on_iteration = [&](const SurfaceMesh& mesh, const IterationRecord& r, const RunState&) {
      samples["faces"].push_back(double(mesh.n_faces()));
      samples["ms_velocity"].push_back(r.ms.velocity);
      samples["ms_distance"].push_back(r.ms.distance);
      samples["ms_advect"].push_back(r.ms.advect);
      samples["ms_discretize"].push_back(r.ms.discretize);
      samples["ms_remesh"].push_back(r.ms.remesh);
      samples["ms_review"].push_back(r.ms.review);
      samples["ms_total"].push_back(r.ms.total());
      for (const auto& [name, value] : r.metrics)
        if (name == "tets" || std::find(model_columns.begin(), model_columns.end(), name) != model_columns.end())
          samples[name].push_back(value);
    };
    evolve(setup.mesh, model.model(), setup.options, {}, hooks);
    auto m = [&](const char* name) { return median(samples[name]); };
    const double other = m("ms_distance") + m("ms_advect") + m("ms_discretize");
    fmt::print("{:>7.4g} {:>7.0f} {:>7.0f} {:>8.1f} {:>8.1f} {:>8.1f} {:>8.1f} {:>8.1f} {:>8.1f} {:>8.1f} {:>8.1f} {:>8.1f}\n", h,
               m("faces"), m("tets"), m("ms_tetgen"), m("ms_assembly"), m("ms_factor"), m("ms_solve"), m("ms_regularise"),
               m("ms_remesh"), other, m("ms_review"), m("ms_total"));
    csv << fmt::format("{},{:.0f},{:.0f},{},{:.2f},{:.2f},{:.2f},{:.2f},{:.2f},{:.2f},{:.2f},{:.2f},{:.2f},{:.2f},{:.2f},{:.2f}\n",
                       h, m("faces"), m("tets"), samples["ms_total"].size(), m("ms_velocity"), m("ms_distance"),
                       m("ms_advect"), m("ms_discretize"), m("ms_remesh"), m("ms_review"), m("ms_total"), m("ms_tetgen"),
                       m("ms_assembly"), m("ms_factor"), m("ms_solve"), m("ms_regularise"));
  }
  fmt::print("CSV: {}\n", csv_file.string());
  return 0;
} catch (const std::exception& e) {
  fmt::print(stderr, "bench_thermal: {}\n", e.what());
  return 1;
}
