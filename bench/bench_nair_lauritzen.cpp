// The deformational flow of Nair & Lauritzen (2010) on the unit sphere (no drift):
// two caps of radius 0.4 (the paper's bells have 1/2, which leaves a gap of 0.047 rad between them:
// under one edge at these sizes, so the cut merges them) centred on the equator at longitudes 5π/6 and 7π/6 are carried by the
// prescribed flow (plugin `prescribed`, case 4 by default: deformation plus a solid-body rotation)
// which stretches them into thin filaments until T/2 and brings them back at T = 5, where the
// exact region is the initial one. For each mesh size h (hmax = h, Δt = c·h) it measures at T
// the front's Hausdorff distance to the exact circles and the area error, and renders G at 0,
// T/2 and T.
//
//   bench_nair_lauritzen [--h 0.08,0.05,0.035] [--c 0.5] [--case 4] [--form vector|normal] [-o outdir]
//
// The case file meshes/cases/nair_lauritzen.toml runs the same at one size with `bodyfit run`.
#include "bench_args.hpp"

#include <bodyfit/app/case_config.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/plugin_loader.hpp>
#include <bodyfit/app/render.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

using namespace bodyfit;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRadius = 0.4;  ///< of each cap (radians; the paper's 1/2 leaves a gap of 0.047 rad, under one edge)
const double kLongitudes[2] = {5 * kPi / 6, 7 * kPi / 6};

/// The exact front at T: the two circles, as 4000 chords each (sagitta ≈ 1e-7).
Segments exact_front() {
  Segments front;
  for (double lon : kLongitudes) {
    const Vec3 axis(std::cos(lon), std::sin(lon), 0);
    const Vec3 e1(0, 0, 1), e2 = cross(axis, e1);
    const int n = 4000;
    auto point = [&](int k) {
      const double s = 2 * kPi * k / n;
      return std::cos(kRadius) * axis + std::sin(kRadius) * (std::cos(s) * e1 + std::sin(s) * e2);
    };
    for (int k = 0; k < n; ++k) front.emplace_back(point(k), point(k + 1));
  }
  return front;
}

std::string case_text(double h, double c, int flow_case, const std::string& form, double k, const std::string& slopes) {
  return fmt::format(R"(
[surface]
generator = "sphere"
h = {h}
[region]
shape = "cap"
axes = [[{:.17g}, {:.17g}, 0.0], [{:.17g}, {:.17g}, 0.0]]
angles = [{a:.17g}, {a:.17g}]
[model]
name = "prescribed"
flow = "nair_lauritzen"
case = {case}
period = 5.0
form = "{form}"
k = {k}
[time]
cfl = {c}
final_time = 5.0
[remesh]
hmax = {h}
[discretize]
hermite_crossings = {hermite}
fitted_slopes = {fitted}
)",
                     std::cos(kLongitudes[0]), std::sin(kLongitudes[0]), std::cos(kLongitudes[1]),
                     std::sin(kLongitudes[1]), fmt::arg("h", h), fmt::arg("a", kRadius * 180 / kPi),
                     fmt::arg("case", flow_case), fmt::arg("form", form), fmt::arg("c", c), fmt::arg("k", k),
                     fmt::arg("hermite", slopes != "linear"), fmt::arg("fitted", slopes == "fitted"));
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<double> hs{0.08, 0.05, 0.035};
  double c = 0.5, k = 2.4;
  int flow_case = 4;
  std::string form = "vector", outdir = "bench_nair_lauritzen_out", slopes = "fitted";
  bench::Arguments args("bench_nair_lauritzen",
                        "usage: bench_nair_lauritzen [--h 0.08,0.05,0.035] [--c 0.5] [--case 4] [--k 2.4] [--form vector|normal] "
                        "[--slopes fitted|faces|linear] [-o outdir]\n"
                        "  Two caps (radius 0.4 at longitudes 5pi/6, 7pi/6 on the equator) in the deformational flow\n"
                        "  of Nair & Lauritzen (2010), T = 5; at T the exact region is the initial one. Per h\n"
                        "  (hmax = h, dt = c h): Hausdorff distance of the front to the exact circles and area error\n"
                        "  at T, written to outdir/nair_lauritzen.csv, and PNGs of G at 0, T/2 and T. --k: the deformation\n"
                        "  strength (the paper's 2.4 for case 4; smaller values stretch the caps less). --slopes: the cut's\n"
                        "  Hermite slopes ([discretize] fitted_slopes, hermite_crossings).\n");
  args.option("--h", hs);
  args.option("--c", c);
  args.option("--case", flow_case);
  args.option("--k", k);
  args.option("--form", form);
  args.option("-o", outdir);
  args.option("--slopes", slopes);
  args.parse(argc, argv);
  if (slopes != "fitted" && slopes != "faces" && slopes != "linear") args.fail("--slopes: fitted, faces or linear");
  if (form != "vector" && form != "normal") args.fail("--form: vector or normal");
  if (flow_case < 1 || flow_case > 4 || !(c > 0)) args.fail("--case: 1 to 4; --c: positive");
  spdlog::set_level(spdlog::level::warn);
  std::filesystem::create_directories(outdir);
  const Segments exact = exact_front();
  const double exact_area = 2 * 2 * kPi * (1 - std::cos(kRadius));
  std::ofstream csv(std::filesystem::path(outdir) / "nair_lauritzen.csv");
  csv << "h,c,case,k,form,faces_T,iterations,hausdorff_T0,hausdorff_T,area_T,exact_area,area_error,"
         "components_half,area_error_half,min_quality,seconds\n";
  fmt::print("{:>6} {:>7} {:>5} {:>11} {:>11} {:>11} {:>8} {:>11} {:>7} {:>7}\n", "h", "faces", "N", "Hausd(0)",
             "Hausd(T)", "area err", "comp T/2", "area T/2", "qmin", "s");
  for (double h : hs) {
    const auto start = std::chrono::steady_clock::now();
    CaseConfig config = parse_case(toml::parse(case_text(h, c, flow_case, form, k, slopes)));
    LoadedModel model = load_model(config.model);
    configure_model(model, config.model_parameters);
    CaseSetup setup = setup_case(config);
    const double hausdorff0 = hausdorff_distance(interface_segments(setup.mesh), exact);
    RenderOptions view;
    view.width = 640, view.height = 480;
    view.azimuth = 180, view.elevation = 10;
    const std::string tag = fmt::format("k{}_h{}", k, h);
    view.title = fmt::format("t = 0, h = {}", h);
    render_png(setup.mesh, std::filesystem::path(outdir) / fmt::format("nl_{}_t0.png", tag), view);
    const double dt = setup.options.dt;
    int half_components = 0;
    double half_area = 0;
    double min_quality = 1;
    EvolutionHooks hooks = EvolutionHooks::quiet();
    hooks.on_iteration = [&](const SurfaceMesh& mesh, const IterationRecord& r, const RunState&) {
      min_quality = std::min(min_quality, r.min_quality);
      if (std::abs(r.time - 2.5) < 0.5 * dt) {
        half_components = r.components;
        half_area = r.area;
        RenderOptions v = view;
        v.title = fmt::format("t = {:.3g} (T/2), h = {}", r.time, h);
        render_png(mesh, std::filesystem::path(outdir) / fmt::format("nl_{}_half.png", tag), v);
      }
    };
    const EvolutionResult result = evolve(setup.mesh, model.model(), setup.options, {}, hooks);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double hausdorff = hausdorff_distance(interface_segments(setup.mesh), exact);
    const double area = region_area(setup.mesh, kInside);
    view.title = fmt::format("t = T = {:.3g}, h = {}", result.time, h);
    render_png(setup.mesh, std::filesystem::path(outdir) / fmt::format("nl_{}_T.png", tag), view);
    fmt::print("{:>6} {:>7} {:>5} {:>11.3e} {:>11.3e} {:>+11.3e} {:>8} {:>+11.3e} {:>7.3f} {:>7.1f}\n", h,
               setup.mesh.n_faces(), result.iteration, hausdorff0, hausdorff, area / exact_area - 1, half_components,
               half_area / exact_area - 1, min_quality, seconds);
    csv << fmt::format("{},{},{},{},{},{},{},{:.6e},{:.6e},{:.8f},{:.8f},{:.6e},{},{:.6e},{:.4f},{:.2f}\n", h, c, flow_case,
                       k, form, setup.mesh.n_faces(), result.iteration, hausdorff0, hausdorff, area, exact_area,
                       area / exact_area - 1, half_components, half_area / exact_area - 1, min_quality, seconds);
    csv.flush();
    std::fflush(stdout);
  }
  return 0;
}
