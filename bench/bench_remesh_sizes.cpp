// Remeshing to a size far from the input's, in one call (docs/validation/remeshing.md, "Any target
// size"): the bodyfit side of the comparison with CGAL's isotropic remeshing (bench_cgal_remesh).
//
//   bench_remesh_sizes input (--ratios 0.73,0.5,3 | --hmax h[,h...]) [--faces N] [--repeat 3]
//                      [--hausd d] [--csv out.csv]
//
// For each target: hmax = ratio × the input's mean edge (or the given hmax), hmin = hmax / 20, the
// input triangles as the reference surface (as `bodyfit remesh` and CGAL's default projection), no
// interface. --faces N instead looks for the hmax whose output has about N faces (a bisection, each
// step a full remesh), to compare at equal output size. --repeat k runs each
// target k times and reports the median time. --hausd raises the allowed distance to S (by default
// D/1000 bounds the size by the curvature: h ≤ √(8·hausd·R), 0.17 on a unit sphere).
// Prints and appends to the CSV (columns as bench_cgal_remesh's, plus bodyfit's own):
// tool,input_faces,target,iterations,ms,faces,q_min,q_mean,share_below_0_3,max_edge_ratio,
// cpu_ms,split_rounds,passes,stop,long_edges,splits,collapses,flips,relocations,valid
// (target = hmax; max_edge_ratio = longest edge / hmax; iterations = the passes).
#include "bench_args.hpp"

#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/remesh.hpp>
#include <bodyfit/validate.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <string>
#include <vector>

using namespace bodyfit;

namespace {

double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

struct Run {
  double hmax = 0, ms = 0, cpu_ms = 0, max_edge = 0;
  SurfaceMesh mesh;
  RemeshReport report;
  QualityStats quality;
  bool valid = false;
};

Run remesh_once(const SurfaceMesh& input, double hmax, double hausd) {
  Run run;
  run.hmax = hmax;
  run.mesh = input;
  RemeshOptions options;
  options.hmax = hmax;
  options.hausd = hausd;
  const double cpu0 = process_cpu_ms();
  const auto start = std::chrono::steady_clock::now();
  run.report = remesh(run.mesh, options);
  run.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  run.cpu_ms = process_cpu_ms() - cpu0;
  run.quality = quality_stats(run.mesh);
  run.max_edge = edge_length_stats(run.mesh).max;
  ValidateOptions vo;
  vo.euler_characteristic = euler_characteristic(input);
  vo.boundary_loops = boundary_loops(input).size();
  run.valid = validate_mesh(run.mesh, vo).ok();
  return run;
}

}  // namespace

int main(int argc, char** argv) {
  std::string input_path, csv;
  std::vector<double> ratios, hmaxes;
  std::size_t faces_wanted = 0;
  int repeat = 1;
  double hausd = 0;
  bench::Arguments args("bench_remesh_sizes",
                        "usage: bench_remesh_sizes input (--ratios 0.73,0.5,3 | --hmax h,...) [--faces N] [--repeat k]\n"
                        "                          [--hausd d] [--csv out.csv]\n"
                        "  remesh the input (Medit/OFF/OBJ/PLY/STL) to each target in one call: hmax = ratio × its mean\n"
                        "  edge, or the given hmax; --faces: the hmax whose output has about N faces (bisection);\n"
                        "  --repeat: median of k runs; prints time, faces, quality, longest edge / hmax, passes and why\n"
                        "  they stopped, and appends a row per target to out.csv.\n");
  args.positional("input", input_path);
  args.option("--ratios", ratios);
  args.option("--hmax", hmaxes);
  args.option("--faces", faces_wanted);
  args.option("--repeat", repeat);
  args.option("--hausd", hausd);
  args.option("--csv", csv);
  args.parse(argc, argv);
  if (input_path.empty()) args.fail("no input mesh");
  if (ratios.empty() && hmaxes.empty()) args.fail("give --ratios or --hmax");
  repeat = std::max(repeat, 1);
  const SurfaceMesh input = read_mesh(input_path);
  const double mean = mean_edge_length(input);
  for (double r : ratios) hmaxes.push_back(r * mean);
  std::printf("input %s: %zu faces, mean edge %.5g\n", input_path.c_str(), input.n_faces(), mean);

  for (double hmax : hmaxes) {
    if (faces_wanted > 0) {
      // The output's faces fall as hmax grows, by jumps where a class of the input's edges crosses
      // the split bound: bisection on log hmax within ±30 % of the given one, keeping the closest.
      double lo = hmax * 0.7, hi = hmax * 1.3, best = hmax, best_gap = 1e300;
      for (int step = 0; step < 8; ++step) {
        const double mid = std::sqrt(lo * hi);
        const std::size_t faces = remesh_once(input, mid, hausd).mesh.n_faces();
        const double gap = std::abs(double(faces) - double(faces_wanted));
        if (gap < best_gap) {
          best_gap = gap;
          best = mid;
        }
        (faces > faces_wanted ? lo : hi) = mid;
      }
      hmax = best;
    }
    std::vector<Run> runs;
    for (int k = 0; k < repeat; ++k) runs.push_back(remesh_once(input, hmax, hausd));
    std::sort(runs.begin(), runs.end(), [](const Run& a, const Run& b) { return a.ms < b.ms; });
    const Run& r = runs[runs.size() / 2];
    std::vector<double> cpu;
    for (const auto& run : runs) cpu.push_back(run.cpu_ms);
    std::sort(cpu.begin(), cpu.end());
    const double cpu_median = cpu[cpu.size() / 2];
    std::printf("bodyfit in %7zu hmax %.5g (%.3g × mean edge) | %9.1f ms (cpu %.1f, median of %d) | faces %7zu | q min %.3f "
                "mean %.4f <0.3 %.2e | max edge / hmax %.3f | %d split rounds + %d passes, %s, %zu long edges | splits %zu "
                "collapses %zu flips %zu moves %zu | %s\n",
                input.n_faces(), hmax, hmax / mean, r.ms, cpu_median, repeat, r.mesh.n_faces(), r.quality.min, r.quality.mean,
                r.quality.share_below_0_3, r.max_edge / hmax, r.report.split_rounds, r.report.passes, to_string(r.report.stop),
                r.report.long_edges, r.report.splits, r.report.collapses, r.report.flips, r.report.relocations,
                r.valid ? "valid" : "INVALID");
    std::fflush(stdout);
    if (!csv.empty()) {
      const bool fresh = !std::ifstream(csv).good();
      std::ofstream out(csv, std::ios::app);
      if (fresh)
        out << "tool,input_faces,target,iterations,ms,faces,q_min,q_mean,share_below_0_3,max_edge_ratio,cpu_ms,split_rounds,"
               "passes,stop,long_edges,splits,collapses,flips,relocations,valid\n";
      out << "bodyfit," << input.n_faces() << ',' << hmax << ',' << r.report.passes << ',' << r.ms << ',' << r.mesh.n_faces()
          << ',' << r.quality.min << ',' << r.quality.mean << ',' << r.quality.share_below_0_3 << ',' << r.max_edge / hmax << ','
          << cpu_median << ',' << r.report.split_rounds << ',' << r.report.passes << ',' << to_string(r.report.stop) << ','
          << r.report.long_edges << ',' << r.report.splits << ',' << r.report.collapses << ',' << r.report.flips << ','
          << r.report.relocations << ',' << (r.valid ? 1 : 0) << '\n';
    }
  }
  return 0;
}
