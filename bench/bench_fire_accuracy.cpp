// Accuracy and cost of the fire cases' CFL sub-steps: the narrow band against the whole surface
// and against a reference with 4× more sub-steps (EvolutionOptions::narrow_band, docs/validation/performance.md).
//
//   bench_fire_accuracy [--case meshes/cases/fire_four_disks.toml] [--h H] [--set key=value]...
//                       [--iterations N] [--reference-factor 4] [--reference-hmax 1]
//                       [--floor-perturbation 0.01] [--reference-floor] [--fronts DIR] [-o out.csv]
//
// Runs the case from the same T^0 as "band" (the case as shipped: its max_cfl, sub-steps in a narrow
// band), "whole" (the same sub-steps on the whole surface), "reference" (max_cfl divided by the
// factor, whole surface; --reference-hmax F < 1 also refines its meshes to F × hmax from T^1 on, on
// the same surface T^0: a reference converged in space as well as in time) and "floor" (the band run
// with hmax × (1 + --floor-perturbation): the same problem and sub-steps on other meshes from the
// first remesh on). --reference-floor adds "reference_floor", the reference on the floor's meshes:
// how far the reference itself moves when only its meshes change.
//
// After every step it records the time per iteration, the sub-steps, the components of G and its
// area, and the gap between its front and the reference's at the same time (the distances from every
// end and midpoint of either front's edges to the other: mean, median, 95th percentile, max) and the
// signed offset (the difference of the burnt areas over the fronts' mean length: > 0 ahead of the
// reference), all in units of the case's h. A curve of either front (closed, or ending on S's border)
// that keeps more than h from the other is "unmatched": a pocket one run has burnt out a step before the other, an island;
// the mean over the other curves is the matched gap. The floor run's gap to the band run is how far
// two meshes alone take the same computation apart: the yardstick for the gap to the reference.
//
// Prints a summary (the worst step of each, the last step's median and offset, the step where G
// becomes one component, the most components; then every step whose mean gap passes h/4, with its
// matched gap and unmatched curves) and writes one CSV row per run and step, with the gap to the band
// run too (band_gap_max_h, band_gap_mean_h). --fronts DIR writes every run's front at every step as
// DIR/<run>_<step>.txt, one segment "x0 y0 z0 x1 y1 z1" per line.
#include "bench_args.hpp"

#include <bodyfit/app/case_config.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/plugin_loader.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <vector>

using namespace bodyfit;

namespace {

/// Distances between two fronts: from every end and midpoint of a segment of either to the other.
/// A curve of either front (closed, or ending on S's border) that keeps more than `apart` from the other (a pocket that one run
/// has burnt out and the other not yet, an island) is counted as unmatched; `matched_mean` is the
/// mean over the other curves.
struct FrontGap {
  double mean = 0, median = 0, p95 = 0, max = 0;
  double matched_mean = 0;
  int unmatched = 0;
  double unmatched_length = 0;
};

double front_length(const Segments& front) {
  double length = 0;
  for (const auto& [a, b] : front) length += (b - a).norm();
  return length;
}

double to_segments(const Vec3& p, const Segments& to) {
  double nearest = std::numeric_limits<double>::infinity();
  for (const auto& [a, b] : to) {
    const Vec3 e = b - a;
    const double len2 = e.sqrnorm();
    const double t = len2 > 0 ? std::clamp(OpenMesh::dot(p - a, e) / len2, 0.0, 1.0) : 0.0;
    nearest = std::min(nearest, (p - (a + t * e)).norm());
  }
  return nearest;
}

/// The curve of every segment: segments that share an end are on one curve (the front's edges are
/// mesh edges, so shared ends are equal points).
std::vector<int> front_curves(const Segments& front) {
  std::vector<int> parent(front.size());
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  std::map<std::array<double, 3>, int> first_at;
  for (int i = 0; i < int(front.size()); ++i)
    for (const Vec3& p : {front[i].first, front[i].second}) {
      const auto [it, inserted] = first_at.try_emplace({p[0], p[1], p[2]}, i);
      if (!inserted) parent[root(i)] = root(it->second);
    }
  std::vector<int> curve(front.size());
  for (int i = 0; i < int(front.size()); ++i) curve[i] = root(i);
  return curve;
}

FrontGap front_gap(const Segments& a, const Segments& b, double apart) {
  std::vector<double> d;
  std::vector<char> matched;
  FrontGap g;
  for (const auto* pair : {&a, &b}) {
    const Segments& other = pair == &a ? b : a;
    const std::vector<int> curve = front_curves(*pair);
    std::map<int, double> nearest;  // per curve: its closest approach to the other front
    for (std::size_t i = 0; i < pair->size(); ++i) {
      const auto& [p, q] = (*pair)[i];
      for (const Vec3& x : {p, q, 0.5 * (p + q)}) {
        d.push_back(to_segments(x, other));
        auto [it, inserted] = nearest.try_emplace(curve[i], d.back());
        if (!inserted) it->second = std::min(it->second, d.back());
      }
    }
    for (std::size_t i = 0; i < pair->size(); ++i) {
      const bool apart_curve = nearest[curve[i]] > apart;
      for (int k = 0; k < 3; ++k) matched.push_back(!apart_curve);
      if (apart_curve) g.unmatched_length += ((*pair)[i].second - (*pair)[i].first).norm();
    }
    for (const auto& [c, closest] : nearest) g.unmatched += closest > apart;
  }
  if (d.empty()) return g;
  double matched_sum = 0;
  std::size_t matched_count = 0;
  for (std::size_t i = 0; i < d.size(); ++i)
    if (matched[i]) matched_sum += d[i], ++matched_count;
  g.matched_mean = matched_count > 0 ? matched_sum / double(matched_count) : 0;
  std::sort(d.begin(), d.end());
  for (double x : d) g.mean += x / double(d.size());
  g.median = d[(d.size() - 1) / 2];
  g.p95 = d[std::size_t(0.95 * double(d.size() - 1))];
  g.max = d.back();
  return g;
}

struct StepRecord {
  int iteration = 0;
  double time = 0, area = 0, ms = 0, band_error = 0, band_mean = 0;  // gap to the band run: max, mean (in h)
  FrontGap gap;       ///< to the reference's front at the same step
  double offset = 0;  ///< signed: (area − the reference's area) / the fronts' mean length
  int components = 0;
  std::size_t faces = 0;
  int substeps = 0;
  Segments front;
};

struct Run {
  std::string name;
  std::vector<StepRecord> steps;
  double wall_s = 0;
  double h = 0;  ///< the case's h (hmax, or the mean edge of T^0)
};

Run run(const std::string& name, const CaseConfig& config, double max_cfl, bool narrow_band, int iterations,
        double hmax_factor = 1) {
  LoadedModel model = load_model(config.model);
  configure_model(model, config.model_parameters);
  CaseSetup setup = setup_case(config);
  setup.options.max_cfl = max_cfl;
  setup.options.narrow_band = narrow_band;
  setup.options.remesh.hmax *= hmax_factor;  // T^0 is remeshed at the case's hmax: the floor differs from T^1 on
  if (iterations >= 0) setup.options.max_iterations = iterations;
  Run r{name, {}, 0, setup.h};
  EvolutionHooks hooks = EvolutionHooks::quiet();
  hooks.on_iteration = [&](const SurfaceMesh& mesh, const IterationRecord& record, const RunState&) {
    StepRecord s;
    s.iteration = record.iteration;
    s.time = record.time;
    s.area = record.area;
    s.ms = record.ms.total();
    s.components = record.components;
    s.faces = record.faces;
    s.substeps = record.substeps;
    s.front = interface_segments(mesh);
    r.steps.push_back(std::move(s));
  };
  const auto start = std::chrono::steady_clock::now();
  evolve(setup.mesh, model.model(), setup.options, {}, hooks);
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

/// The first step after which G has one component (−1: never).
int merge_step(const Run& r) {
  for (const auto& s : r.steps)
    if (s.components == 1) return s.iteration;
  return -1;
}

}  // namespace

int main(int argc, char** argv) try {
  std::filesystem::path case_file = "meshes/cases/fire_four_disks.toml";
  double h = 0;
  int iterations = -1;
  double factor = 4;
  double reference_hmax = 1;
  double perturbation = 1e-2;
  bool reference_floor = false;
  std::filesystem::path fronts_dir;
  std::filesystem::path csv_path = "bench_fire_accuracy.csv";
  std::vector<std::string> overrides;
  bench::Arguments args("bench_fire_accuracy",
                        "usage: bench_fire_accuracy [--case file.toml] [--h H] [--set key=value]... [--iterations N] "
                        "[--reference-factor 4] [--reference-hmax 1] [--floor-perturbation 0.01] [--reference-floor] "
                        "[--fronts DIR] [-o out.csv]\n"
                        "  --case              fire case with max_cfl > 0 (default meshes/cases/fire_four_disks.toml)\n"
                        "  --h                 surface.h and remesh.hmax in metres (default: the case's)\n"
                        "  --set               a case key for every run, as `bodyfit run --set` (repeatable), e.g.\n"
                        "                      --set surface.max_height=750\n"
                        "  --iterations        steps to run (default: the case's final time)\n"
                        "  --reference-factor  the reference divides max_cfl by this (default 4)\n"
                        "  --reference-hmax    the reference's meshes after T^0 at this × hmax, on the same surface\n"
                        "                      (default 1; 0.5: a reference refined in space too)\n"
                        "  --floor-perturbation  the floor run (the band run on other meshes) multiplies hmax by\n"
                        "                      1 + this after T^0 (default 0.01; 0: no floor run)\n"
                        "  --reference-floor   also run the reference with that perturbation: the reference's own\n"
                        "                      floor (its gap to the reference)\n"
                        "  --fronts            directory: every run's front at every step, <run>_<step>.txt\n"
                        "  -o                  CSV, one row per run and step (default bench_fire_accuracy.csv)\n");
  args.option("--case", case_file);
  args.option("--h", h);
  args.option("--set", [&](const std::string& value) { overrides.push_back(value); });
  args.option("--iterations", iterations);
  args.option("--reference-factor", factor);
  args.option("--reference-hmax", reference_hmax);
  args.option("--floor-perturbation", perturbation);
  args.flag("--reference-floor", reference_floor);
  args.option("--fronts", fronts_dir);
  args.option("-o", csv_path);
  args.parse(argc, argv);
  if (!(factor >= 1)) args.fail("--reference-factor must be at least 1");
  if (!(reference_hmax > 0 && reference_hmax <= 1)) args.fail("--reference-hmax must be in (0, 1]");
  if (!(perturbation >= 0 && perturbation < 0.5)) args.fail("--floor-perturbation must be in [0, 0.5)");
  if (reference_floor && !(perturbation > 0)) args.fail("--reference-floor needs --floor-perturbation > 0");
  if (!fronts_dir.empty() && !std::filesystem::is_directory(fronts_dir))
    args.fail("--fronts: no directory " + fronts_dir.string());
  spdlog::set_level(spdlog::level::warn);

  if (h > 0) {
    overrides.push_back(fmt::format("surface.h={}", h));
    overrides.push_back(fmt::format("remesh.hmax={}", h));
  }
  const CaseConfig config = read_case(case_file, overrides);
  const double max_cfl = config.time.max_cfl;
  if (!(max_cfl > 0)) args.fail("the case has no max_cfl: nothing to compare");
  std::vector<Run> runs;
  runs.push_back(run("reference", config, max_cfl / factor, false, iterations, reference_hmax));
  runs.push_back(run("band", config, max_cfl, true, iterations));
  runs.push_back(run("whole", config, max_cfl, false, iterations));
  if (perturbation > 0) runs.push_back(run("floor", config, max_cfl, true, iterations, 1 + perturbation));
  if (reference_floor)
    runs.push_back(run("reference_floor", config, max_cfl / factor, false, iterations,
                       reference_hmax * (1 + perturbation)));
  const Run& reference = runs[0];
  const double length = reference.h;
  std::map<int, const StepRecord*> by_iteration;
  for (const auto& s : reference.steps) by_iteration[s.iteration] = &s;

  std::ofstream csv(csv_path);
  csv << "run,iteration,time,faces,substeps,components,area,ms_total,gap_mean_h,gap_median_h,gap_p95_h,gap_max_h,"
         "offset_h,band_gap_max_h,band_gap_mean_h,gap_matched_mean_h,unmatched_curves,unmatched_length_h\n";
  fmt::print("{}: h = {} m, max_cfl {} (reference {} at {} × hmax), {} steps\n", case_file.string(), length,
             max_cfl, max_cfl / factor, reference_hmax, reference.steps.size());
  fmt::print("{:>15} {:>8} {:>8} {:>9} {:>6} {:>5} | to reference / h, worst step: {:>6} {:>6} {:>6}, last: {:>6} "
             "{:>7} | to band, worst: {:>6} {:>6}\n",
             "run", "wall s", "ms/step", "sub-steps", "merge", "comp", "mean", "p95", "max", "median", "offset", "mean",
             "max");
  const Run* band = &runs[1];
  for (auto& r : runs) {
    double worst = 0, worst_mean = 0, worst_p95 = 0, ms = 0, worst_band = 0, worst_band_mean = 0;
    int substeps = 0;
    int most = 0;
    for (std::size_t k = 0; k < r.steps.size(); ++k) {
      auto& s = r.steps[k];
      auto it = by_iteration.find(s.iteration);
      if (it != by_iteration.end()) {
        s.gap = front_gap(s.front, it->second->front, length);
        const double length_mean = 0.5 * (front_length(s.front) + front_length(it->second->front));
        if (length_mean > 0) s.offset = (s.area - it->second->area) / length_mean;
      }
      if (&r != band && k < band->steps.size()) {
        const FrontGap to_band = front_gap(s.front, band->steps[k].front, length);
        s.band_error = to_band.max / length;
        s.band_mean = to_band.mean / length;
        worst_band = std::max(worst_band, s.band_error);
        worst_band_mean = std::max(worst_band_mean, s.band_mean);
      }
      worst = std::max(worst, s.gap.max / length);
      worst_mean = std::max(worst_mean, s.gap.mean / length);
      worst_p95 = std::max(worst_p95, s.gap.p95 / length);
      ms += s.ms;
      substeps += s.substeps;
      most = std::max(most, s.components);
      csv << fmt::format("{},{},{},{},{},{},{:.9g},{:.1f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{},{:.2f}\n",
                         r.name, s.iteration, s.time, s.faces, s.substeps, s.components, s.area, s.ms,
                         s.gap.mean / length, s.gap.median / length, s.gap.p95 / length, s.gap.max / length,
                         s.offset / length, s.band_error, s.band_mean, s.gap.matched_mean / length, s.gap.unmatched,
                         s.gap.unmatched_length / length);
    }
    const double n = std::max<std::size_t>(1, r.steps.size());
    const StepRecord last = r.steps.empty() ? StepRecord{} : r.steps.back();
    fmt::print("{:>15} {:>8.1f} {:>8.0f} {:>9.1f} {:>6} {:>5} |                               {:>6.3f} {:>6.3f} {:>6.3f}  "
               "      {:>6.3f} {:>+7.3f} |                {:>6.3f} {:>6.3f}\n",
               r.name, r.wall_s, ms / n, substeps / n, merge_step(r), most, worst_mean, worst_p95, worst,
               last.gap.median / length, last.offset / length, worst_band_mean, worst_band);
    if (!fronts_dir.empty())
      for (const auto& s : r.steps) {
        std::ofstream f(fronts_dir / fmt::format("{}_{:03d}.txt", r.name, s.iteration));
        for (const auto& [a, b] : s.front) f << fmt::format("{} {} {} {} {} {}\n", a[0], a[1], a[2], b[0], b[1], b[2]);
      }
  }
  // The goal's bound, step by step: where a run's mean gap passes h/4, and the reference's own floor there.
  const Run* own_floor = reference_floor ? &runs.back() : nullptr;
  for (const auto& r : runs) {
    if (&r == &reference || &r == own_floor) continue;
    std::string over;
    for (std::size_t k = 0; k < r.steps.size(); ++k) {
      const double mean = r.steps[k].gap.mean / length;
      if (mean <= 0.25) continue;
      const FrontGap& gap = r.steps[k].gap;
      over += fmt::format(" {} ({:.3f}; {:.3f} without {} unmatched curve(s) of {:.1f} h", r.steps[k].iteration, mean,
                          gap.matched_mean / length, gap.unmatched, gap.unmatched_length / length);
      if (own_floor && k < own_floor->steps.size())
        over += fmt::format("; reference_floor {:.3f}", own_floor->steps[k].gap.mean / length);
      over += ")";
    }
    fmt::print("{:>15}: mean gap over h/4 at step{}\n", r.name, over.empty() ? "s: none" : over);
  }
  fmt::print("wrote {}\n", csv_path.string());
  return 0;
} catch (const std::exception& e) {  // a case that does not read, or a run that fails: say which, exit 1
  fmt::print(stderr, "bench_fire_accuracy: {}\n", e.what());
  return 1;
}
