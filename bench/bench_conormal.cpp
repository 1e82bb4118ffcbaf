// The conormal validation of the paper (§4.2, Fig. 8): a cap of polar angle a = π/4 on the unit
// sphere grows along its conormal until T = π/2 − a. For each mesh size h and CFL number c
// (Δt = c·h, hmax = h) it runs Algorithm 1 and measures E of (4.5), the L² norm over S of
// φ^N − (β − T − a), φ^N the signed distance on the final mesh.
//
//   bench_conormal [--h 0.1,0.05,...] [--c 0.1,0.25,...] [-o outdir] [--max-seconds S]
//
// Writes outdir/conormal.csv (one row per run, with per-stage times) and outdir/conormal.png
// (E against h, log-log, one line per c, with the paper's values for comparison).
#include "bench_args.hpp"

#include <bodyfit/app/case_config.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/app/plot.hpp>
#include <bodyfit/plugin_loader.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <string>
#include <vector>

using namespace bodyfit;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kCapAngle = kPi / 4;

/// E of (4.5) with the edge-midpoint rule on each flat triangle.
double cap_error(const SurfaceMesh& mesh, const ScalarField& d, double final_angle) {
  return l2_difference(mesh, d, [&](const Vec3& m) {
    return std::acos(std::clamp(m[2] / m.norm(), -1.0, 1.0)) - final_angle;
  });
}

struct Row {
  double h = 0, c = 0, dt = 0;
  int iterations = 0;
  std::size_t faces = 0;
  double error = 0, area = 0, deficit_percent = 0, angle = 0;
  double seconds = 0, setup_seconds = 0;
  StageTimes ms;  // summed over the iterations
};

Row run_one(double h, double c, const std::string& slopes) {
  const std::string text = fmt::format(R"(
[surface]
generator = "sphere"
h = {h}
[region]
shape = "cap"
axis = [0, 0, 1]
angle = 45
[model]
name = "conormal"
[time]
cfl = {c}
final_time = {T:.17g}
[remesh]
hmax = {h}
[discretize]
hermite_crossings = {hermite}
fitted_slopes = {fitted}
)",
                                       fmt::arg("h", h), fmt::arg("c", c), fmt::arg("T", kPi / 2 - kCapAngle),
                                       fmt::arg("hermite", slopes != "linear"), fmt::arg("fitted", slopes == "fitted"));
  CaseConfig config = parse_case(toml::parse(text));
  LoadedModel model = load_model(config.model);
  configure_model(model, config.model_parameters);
  Row row;
  row.h = h, row.c = c;
  auto start = std::chrono::steady_clock::now();
  CaseSetup setup = setup_case(config);
  auto after_setup = std::chrono::steady_clock::now();
  EvolutionResult result = evolve(setup.mesh, model.model(), setup.options, {}, EvolutionHooks::quiet());
  auto end = std::chrono::steady_clock::now();
  row.dt = setup.options.dt;
  row.iterations = result.iteration;
  row.faces = setup.mesh.n_faces();
  row.error = cap_error(setup.mesh, result.final_distance, kPi / 2);
  row.area = region_area(setup.mesh, kInside);
  row.deficit_percent = 100 * (2 * kPi - row.area) / (2 * kPi);
  row.angle = std::acos(1 - row.area / (2 * kPi));
  row.setup_seconds = std::chrono::duration<double>(after_setup - start).count();
  row.seconds = std::chrono::duration<double>(end - start).count();
  for (const auto& r : result.records) {
    row.ms.velocity += r.ms.velocity, row.ms.distance += r.ms.distance, row.ms.advect += r.ms.advect;
    row.ms.discretize += r.ms.discretize, row.ms.remesh += r.ms.remesh, row.ms.output += r.ms.output;
  }
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<double> hs{0.2, 0.1, 0.05, 0.025};
  std::vector<double> cs{0.1, 0.25, 0.5, 0.75, 1.0};
  std::string outdir = "bench_conormal_out", slopes = "fitted";
  double max_seconds = 1e30;  // skip the remaining (finer) runs of a c once one run took longer
  bench::Arguments args("bench_conormal",
                        "usage: bench_conormal [--h 0.2,0.1,...] [--c 0.1,0.25,...] [-o outdir] [--max-seconds S] [--slopes fitted|faces|linear]\n"
                        "  --h            mesh sizes h (hmax = h; default 0.2,0.1,0.05,0.025)\n"
                        "  --c            CFL numbers c (dt = c h; default 0.1,0.25,0.5,0.75,1)\n"
                        "  -o             output directory: conormal.csv, conormal.png (default bench_conormal_out)\n"
                        "  --max-seconds  skip the finer runs of a c once one run took longer than S\n"
                        "  --slopes       the cut's Hermite slopes ([discretize] fitted_slopes, hermite_crossings)\n");
  args.option("--h", hs);
  args.option("--c", cs);
  args.option("-o", outdir);
  args.option("--max-seconds", max_seconds);
  args.option("--slopes", slopes);
  args.parse(argc, argv);
  if (slopes != "fitted" && slopes != "faces" && slopes != "linear") args.fail("--slopes: fitted, faces or linear");
  std::filesystem::create_directories(outdir);
  spdlog::set_level(spdlog::level::warn);
  std::sort(hs.begin(), hs.end(), std::greater<>());

  std::vector<Row> rows;
  std::ofstream csv(std::filesystem::path(outdir) / "conormal.csv");
  csv << "h,c,dt,iterations,faces,E,area_G,area_deficit_percent,final_angle,seconds,setup_seconds,"
         "ms_per_iteration,ms_velocity,ms_distance,ms_advect,ms_discretize,ms_remesh\n";
  fmt::print("{:>7} {:>5} {:>8} {:>5} {:>7} {:>10} {:>9} {:>8} {:>9}   per-stage s (vel dist adv disc remesh)\n", "h",
             "c", "dt", "N", "faces", "E", "deficit%", "time s", "ms/iter");
  for (double c : cs) {
    for (double h : hs) {
      Row r = run_one(h, c, slopes);
      rows.push_back(r);
      const double per_iteration = r.iterations ? 1000 * (r.seconds - r.setup_seconds) / r.iterations : 0;
      fmt::print("{:>7.4g} {:>5.3g} {:>8.4g} {:>5} {:>7} {:>10.3e} {:>9.2f} {:>8.2f} {:>9.1f}   {:.2f} {:.2f} {:.2f} {:.2f} {:.2f}\n",
                 r.h, r.c, r.dt, r.iterations, r.faces, r.error, r.deficit_percent, r.seconds, per_iteration,
                 r.ms.velocity / 1000, r.ms.distance / 1000, r.ms.advect / 1000, r.ms.discretize / 1000,
                 r.ms.remesh / 1000);
      csv << fmt::format("{},{},{:.10g},{},{},{:.6e},{:.8f},{:.4f},{:.8f},{:.3f},{:.3f},{:.3f},{:.1f},{:.1f},{:.1f},{:.1f},{:.1f}\n",
                         r.h, r.c, r.dt, r.iterations, r.faces, r.error, r.area, r.deficit_percent, r.angle, r.seconds,
                         r.setup_seconds, per_iteration, r.ms.velocity, r.ms.distance, r.ms.advect, r.ms.discretize,
                         r.ms.remesh);
      csv.flush();
      std::fflush(stdout);
      if (r.seconds > max_seconds) break;
    }
  }

  // Fig. 8 style: E against h per c, and the paper's measurements.
  std::vector<PlotSeries> series;
  std::size_t k = 0;
  for (double c : cs) {
    PlotSeries s;
    s.label = fmt::format("c = {:g}", c);
    s.color = series_color(k++);
    for (const auto& r : rows)
      if (r.c == c) s.x.push_back(r.h), s.y.push_back(r.error);
    series.push_back(s);
  }
  PlotSeries paper;
  paper.label = "paper c = 0.5";
  paper.x = {0.1, 0.05, 0.025};
  paper.y = {2.6e-2, 1.32e-2, 5.5e-3};
  paper.color = {0, 0, 0};
  paper.dashed = true;
  series.push_back(paper);
  PlotOptions options;
  options.title = "Conormal flow on the sphere: E at T";
  options.x_label = "mesh size h";
  options.y_label = "E (L2 error of phi at T)";
  options.log_x = options.log_y = true;
  plot_png(std::filesystem::path(outdir) / "conormal.png", series, options);
  fmt::print("wrote {}/conormal.csv and {}/conormal.png\n", outdir, outdir);
  return 0;
}
