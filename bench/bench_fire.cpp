// Time per iteration of the wildfire model (paper §4.3) at the paper's mesh size, and the
// area/perimeter plot of finished runs.
//
//   bench_fire [--case meshes/cases/fire_one_disk.toml] [--h 200] [--iterations 6] [--max-cfl k] [-o outdir]
//     (--max-cfl 0: one pass of Algorithm 1 per step, as in the paper; default: the case's sub-steps)
//     Runs the case's first iterations with the terrain and hmax at edge length h (h = 200 m gives
//     ≈ 225,000 triangles on the calibrated 50 km landscape, near the paper's 240,000; the steep
//     landscape has ~1.6 times the plan area, so h = 150 m gives 412,000), prints the per-stage times of
//     every iteration (wall and process CPU time: the machine may be shared) and writes
//     outdir/fire_timing.csv.
//
//   bench_fire --plot outdir run_dir [run_dir...]
//     Reads each run's history.csv (from `bodyfit run`) and writes outdir/fire_area.png and
//     outdir/fire_perimeter.png: burnt area (km²) and front length (km) against time (min).
#include "bench_args.hpp"

#include <bodyfit/app/case_config.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/app/plot.hpp>
#include <bodyfit/plugin_loader.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using namespace bodyfit;

namespace {

double cpu_seconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

// Columns of a CSV file with a header row, by name.
std::map<std::string, std::vector<double>> read_columns(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream header(line);
  for (std::string name; std::getline(header, name, ',');) names.push_back(name);
  std::map<std::string, std::vector<double>> columns;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::size_t k = 0;
    for (std::string cell; std::getline(row, cell, ',') && k < names.size(); ++k)
      columns[names[k]].push_back(cell.empty() ? std::nan("") : std::stod(cell));
  }
  return columns;
}

int plot_runs(const std::filesystem::path& outdir, const std::vector<std::filesystem::path>& runs) {
  std::filesystem::create_directories(outdir);
  std::vector<PlotSeries> area, perimeter;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    auto columns = read_columns(runs[i] / "history.csv");
    PlotSeries a;
    a.label = runs[i].filename().string();  // "run_fire_one_disk" -> "one disk"
    for (const std::string prefix : {"run_", "fire_"})
      if (a.label.rfind(prefix, 0) == 0) a.label.erase(0, prefix.size());
    std::replace(a.label.begin(), a.label.end(), '_', ' ');
    a.color = series_color(i);
    a.markers = false;
    PlotSeries p = a;
    for (std::size_t k = 0; k < columns["time"].size(); ++k) {
      const double minutes = columns["time"][k] / 60;
      a.x.push_back(minutes), a.y.push_back(columns["area"][k] / 1e6);
      p.x.push_back(minutes), p.y.push_back(columns["interface_length"][k] / 1e3);
    }
    area.push_back(a), perimeter.push_back(p);
  }
  // Head room for the legend (top right): an invisible point (no label, no marker, no segment)
  // raises the y range so the curves end below it.
  for (auto* series : {&area, &perimeter}) {
    double top = 0;
    for (const auto& s : *series)
      for (double y : s.y) top = std::max(top, y);
    PlotSeries room;
    room.x = {0.0}, room.y = {1.3 * top};
    room.markers = false;
    series->push_back(room);
  }
  PlotOptions options;
  options.width = 640, options.height = 440;
  options.x_label = "time (min)";
  options.title = "Burnt area";
  options.y_label = "area (km2)";
  plot_png(outdir / "fire_area.png", area, options);
  options.title = "Front length (perimeter)";
  options.y_label = "perimeter (km)";
  plot_png(outdir / "fire_perimeter.png", perimeter, options);
  fmt::print("wrote {0}/fire_area.png and {0}/fire_perimeter.png\n", outdir.string());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path case_file = "meshes/cases/fire_one_disk.toml";
  double h = 200;
  int iterations = 6;
  double max_cfl = -1;  // < 0: the case's [time] max_cfl
  std::filesystem::path outdir = "bench_fire_out";
  std::filesystem::path plot_dir;
  std::vector<std::filesystem::path> runs;
  bench::Arguments args("bench_fire",
                        "usage: bench_fire [--case file.toml] [--h 200] [--iterations 6] [--max-cfl k] [-o outdir]\n"
                        "       bench_fire --plot outdir run_dir [run_dir...]\n"
                        "  --case        fire case (default meshes/cases/fire_one_disk.toml)\n"
                        "  --h           terrain edge length and hmax in metres (default 200)\n"
                        "  --iterations  iterations to time (default 6)\n"
                        "  --max-cfl     sub-step cap (0: one pass per step; default: the case's)\n"
                        "  -o            output directory: fire_timing.csv (default bench_fire_out)\n"
                        "  --plot        plot the burnt area and front length of finished `bodyfit run` outputs\n");
  args.option("--case", case_file);
  args.option("--h", h);
  args.option("--iterations", iterations);
  args.option("-o", outdir);
  args.option("--max-cfl", max_cfl);
  args.option("--plot", plot_dir);
  args.positionals("run_dir", runs);
  args.parse(argc, argv);
  if (!plot_dir.empty()) {
    if (runs.empty()) args.fail("--plot needs at least one run directory");
    return plot_runs(plot_dir, runs);
  }
  if (!runs.empty()) args.fail("run directories are read only with --plot");
  std::filesystem::create_directories(outdir);
  spdlog::set_level(spdlog::level::warn);

  CaseConfig config = read_case(case_file, {fmt::format("surface.h={}", h), fmt::format("remesh.hmax={}", h)});
  LoadedModel model = load_model(config.model);
  configure_model(model, config.model_parameters);
  const auto wall0 = std::chrono::steady_clock::now();
  const double cpu0 = cpu_seconds();
  CaseSetup setup = setup_case(config);
  const double setup_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const double setup_cpu = cpu_seconds() - cpu0;
  fmt::print("{}: h = {} m, T^0 has {} triangles (setup {:.2f} s wall, {:.2f} s CPU)\n", case_file.string(), h,
             setup.mesh.n_faces(), setup_wall, setup_cpu);

  EvolutionHooks hooks = EvolutionHooks::quiet();
  setup.options.max_iterations = iterations;
  if (max_cfl >= 0) setup.options.max_cfl = max_cfl;  // 0: one pass per step, as in the paper
  fmt::print("max_cfl = {} (0: no sub-steps)\n", setup.options.max_cfl);
  std::ofstream csv(outdir / "fire_timing.csv");
  csv << "iteration,faces,ms_velocity,ms_distance,ms_advect,ms_discretize,ms_remesh,ms_output,ms_total,"
         "ms_wall,ms_cpu,ros_min,ros_mean,ros_max\n";
  fmt::print("{:>4} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>9} {:>9}  (ms: vel dist adv disc remesh, total, CPU)\n",
             "n", "faces", "vel", "dist", "adv", "disc", "remesh", "total", "cpu");
  auto last_wall = std::chrono::steady_clock::now();
  double last_cpu = cpu_seconds();
  StageTimes sum;
  double cpu_sum = 0;
  int count = 0;
  hooks.on_iteration = [&](const SurfaceMesh& mesh, const IterationRecord& r, const RunState&) {
    const auto now = std::chrono::steady_clock::now();
    const double wall_ms = 1000 * std::chrono::duration<double>(now - last_wall).count();
    const double cpu_ms = 1000 * (cpu_seconds() - last_cpu);
    last_wall = now, last_cpu = cpu_seconds();
    auto metric = [&](const char* name) {
      for (const auto& [key, value] : r.metrics)
        if (key == name) return value;
      return std::nan("");
    };
    fmt::print("{:>4} {:>8} {:>8.0f} {:>8.0f} {:>8.0f} {:>8.0f} {:>8.0f} {:>9.0f} {:>9.0f}  {} sub-step(s)\n", r.iteration,
               mesh.n_faces(), r.ms.velocity, r.ms.distance, r.ms.advect, r.ms.discretize, r.ms.remesh, r.ms.total(),
               cpu_ms, r.substeps);
    csv << fmt::format("{},{},{:.1f},{:.1f},{:.1f},{:.1f},{:.1f},{:.1f},{:.1f},{:.1f},{:.1f},{:.5g},{:.5g},{:.5g}\n",
                       r.iteration, mesh.n_faces(), r.ms.velocity, r.ms.distance, r.ms.advect, r.ms.discretize,
                       r.ms.remesh, r.ms.output, r.ms.total(), wall_ms, cpu_ms, metric("ros_min"), metric("ros_mean"),
                       metric("ros_max"));
    sum.velocity += r.ms.velocity, sum.distance += r.ms.distance, sum.advect += r.ms.advect;
    sum.discretize += r.ms.discretize, sum.remesh += r.ms.remesh, sum.output += r.ms.output;
    cpu_sum += cpu_ms;
    ++count;
    std::fflush(stdout);
  };
  evolve(setup.mesh, model.model(), setup.options, {}, hooks);
  if (count > 0) {
    const double n = count;
    fmt::print("mean per iteration over {} iterations: {:.0f} ms (vel {:.0f}, dist {:.0f}, adv {:.0f}, disc {:.0f}, "
               "remesh {:.0f}); process CPU {:.0f} ms\n",
               count, sum.total() / n, sum.velocity / n, sum.distance / n, sum.advect / n, sum.discretize / n,
               sum.remesh / n, cpu_sum / n);
  }
  fmt::print("wrote {}\n", (outdir / "fire_timing.csv").string());
  return 0;
}
