// Soak: thousands of iterations of a region that splits and merges twice per period
// (bench/soak_case.hpp: two overlapping caps, the conormal model with a periodic speed), with
// everything that could drift over a long run recorded per iteration: |G| against the exact
// solution, the components of G, the faces, the worst triangle and the share below quality 0.3,
// and the resident memory.
//
//   bench_soak [--h 0.08] [--iterations 3000] [--period 4] [--depth 0.7] [-o soak.csv] [--every 100]
//
// Plot with `bodyfit plot soak.csv -x iteration -y area_error -o area.png` (and the other columns).
#include "bench_args.hpp"
#include "soak_case.hpp"

#include <bodyfit/app/case_config.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/plugin_loader.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <string>

using namespace bodyfit;

int main(int argc, char** argv) {
  soak::SoakCase c;
  std::string csv_path = "soak.csv";
  long every = 100;
  bench::Arguments args("bench_soak",
                        "usage: bench_soak [--h 0.08] [--iterations 3000] [--period 4] [--depth 0.7] [-o soak.csv] "
                        "[--every 100] [--slopes fitted|faces|linear]\n"
                        "  Two overlapping caps (55 deg, axes 90 deg apart) on the unit sphere go in by depth (radians)\n"
                        "  (the exact |G| is known on the way in and at the end of each period; NaN on the way out)\n"
                        "  and back out once per period, splitting and merging; one CSV row per iteration: time, |G|,\n"
                        "  the exact |G|, relative area error, components, faces, vertices, min quality, share of\n"
                        "  faces below 0.3, resident memory (MiB). --every: print a line every that many iterations.\n"
                        "  --slopes: the cut's Hermite slopes ([discretize] fitted_slopes, hermite_crossings).\n");
  args.option("--h", c.h);
  args.option("--iterations", c.iterations);
  args.option("--period", c.period);
  args.option("--depth", c.depth);
  args.option("-o", csv_path);
  args.option("--every", every);
  args.option("--slopes", c.slopes);
  args.parse(argc, argv);
  if (c.slopes != "fitted" && c.slopes != "faces" && c.slopes != "linear") args.fail("--slopes: fitted, faces or linear");
  if (!(c.h > 0) || c.iterations < 1 || !(c.period > 0) || !(c.depth > 0) || every < 1)
    args.fail("--h, --iterations, --period, --depth and --every must be positive");
  spdlog::set_level(spdlog::level::warn);

  const auto start = std::chrono::steady_clock::now();
  const soak::ExactArea exact(c);
  CaseConfig config = parse_case(toml::parse(c.toml()));
  LoadedModel model = load_model(config.model);
  configure_model(model, config.model_parameters);
  CaseSetup setup = setup_case(config);
  const double setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fmt::print("soak: h = {}, {} faces, dt = {:.4g} ({} steps per period), depth {} rad; exact |G(0)| = {:.6f}, "
             "deepest {:.6f}; setup {:.1f} s\n",
             c.h, setup.mesh.n_faces(), setup.options.dt, std::lround(c.period / setup.options.dt), c.depth,
             exact.initial(), exact.deepest(), setup_seconds);

  std::ofstream csv(csv_path);
  csv << "iteration,time,area,exact_area,area_error,components,faces,vertices,min_quality,share_below_0_3,rss_mib\n";
  double worst_error = 0, worst_quality = 1, worst_share = 0, rss_first = 0, rss_max = 0;
  std::size_t faces_min = SIZE_MAX, faces_max = 0;
  int changes = 0, components = 0;
  EvolutionHooks hooks = EvolutionHooks::quiet();
  hooks.on_iteration = [&](const SurfaceMesh& mesh, const IterationRecord& r, const RunState&) {
    const double area_exact = exact.at(r.time);
    const double error = r.area / area_exact - 1;
    const double share = soak::share_below(mesh, 0.3);
    const double rss = soak::rss_mib();
    if (r.iteration == 1) rss_first = rss;
    if (components != 0 && r.components != components) ++changes;
    components = r.components;
    if (std::isfinite(error)) worst_error = std::max(worst_error, std::abs(error));
    worst_quality = std::min(worst_quality, r.min_quality);
    worst_share = std::max(worst_share, share);
    rss_max = std::max(rss_max, rss);
    faces_min = std::min(faces_min, r.faces), faces_max = std::max(faces_max, r.faces);
    csv << fmt::format("{},{:.8f},{:.8f},{:.8f},{:.6e},{},{},{},{:.4f},{:.6f},{:.2f}\n", r.iteration, r.time, r.area,
                       area_exact, error, r.components, r.faces, r.vertices, r.min_quality, share, rss);
    if (r.iteration % every == 0) {
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      fmt::print("n={:>6} t={:>8.3f} |G|={:.5f} exact {:.5f} ({:+.3e}) comp={} faces={} qmin={:.3f} <0.3: {:.4f} % "
                 "rss {:.1f} MiB  {:.0f} s\n",
                 r.iteration, r.time, r.area, area_exact, error, r.components, r.faces, r.min_quality, 100 * share, rss,
                 seconds);
      std::fflush(stdout);
    }
  };
  const EvolutionResult result = evolve(setup.mesh, model.model(), setup.options, {}, hooks);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fmt::print("{} iterations ({}) in {:.1f} s: max |area error| {:.3e}, worst quality {:.3f}, max share below 0.3 "
             "{:.4f} %, faces {}..{}, {} splits/merges, RSS {:.1f} MiB after the first iteration, max {:.1f} MiB\n",
             result.iteration, result.message, seconds, worst_error, worst_quality, 100 * worst_share, faces_min,
             faces_max, changes, rss_first, rss_max);
  return 0;
}
