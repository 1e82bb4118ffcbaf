// Speed of discretize() on geodesic spheres cut by a polar cap and by a random-looking level set.
// Usage: bench_discretize [csv file] — prints a table, writes one CSV row per (faces, level set).
#include "bench_args.hpp"

#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/levelset_mesher.hpp>
#include <bodyfit/validate.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <fstream>
#include <functional>
#include <string>

using namespace bodyfit;

namespace {

double milliseconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

/// CPU time of this thread: on a shared, loaded machine wall time mostly measures the neighbours.
double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

}  // namespace

int main(int argc, char** argv) {
  std::string csv_path = "bench_discretize.csv";
  bench::Arguments args("bench_discretize",
                        "usage: bench_discretize [out.csv]\n"
                        "  Times discretize() on spheres of 15k, 60k and 240k faces cut by a polar cap and by a\n"
                        "  wavy level set; prints a table and writes it to out.csv (default bench_discretize.csv).\n");
  args.positional("out.csv", csv_path);
  args.parse(argc, argv);
  std::ofstream csv(csv_path);
  csv << "faces,level_set,crossed_edges,faces_after,discretize_cpu_ms_best,discretize_cpu_ms_median,"
         "discretize_wall_ms_best,discretize_cpu_ms_reserved_best,validate_ms\n";
  fmt::print("{:>8} {:>8} {:>9} {:>10} {:>12} {:>12} {:>12} {:>14} {:>10}\n", "faces", "phi", "crossed", "after",
             "cpu best ms", "cpu median", "wall best ms", "reserved cpu", "valid ms");
  const std::pair<std::string, std::function<double(const Vec3&)>> level_sets[] = {
      {"cap", [](const Vec3& p) { return std::acos(std::clamp(p[2] / p.norm(), -1.0, 1.0)) - 0.8; }},
      {"waves", [](const Vec3& p) { return std::sin(9 * p[0]) * std::cos(7 * p[1]) + 0.5 * std::sin(11 * p[2]) - 0.1; }},
  };
  for (std::size_t faces : {15000u, 60000u, 240000u}) {
    const SurfaceMesh sphere = make_sphere({.faces = faces});
    for (const auto& [name, f] : level_sets) {
      ScalarField phi(sphere.n_vertices());
      for (auto v : sphere.vertices()) phi[v.idx()] = f(sphere.point(v));
      std::vector<double> times, cpu, cpu_reserved;
      SurfaceMesh mesh;
      DiscretizeReport report;
      for (int run = 0; run < 7; ++run) {
        mesh = sphere;
        auto start = std::chrono::steady_clock::now();
        double cpu_start = thread_cpu_ms();
        report = discretize(mesh, phi);
        cpu.push_back(thread_cpu_ms() - cpu_start);
        times.push_back(milliseconds_since(start));
        // The same with room reserved: the first cut of a freshly copied mesh pays for growing
        // every OpenMesh property array once, which a mesh that was edited before has room for.
        mesh = sphere;
        mesh.reserve(mesh.n_vertices() + 2 * report.crossed_edges, mesh.n_edges() + 6 * report.crossed_edges,
                     mesh.n_faces() + 4 * report.crossed_edges);
        cpu_start = thread_cpu_ms();
        discretize(mesh, phi);
        cpu_reserved.push_back(thread_cpu_ms() - cpu_start);
      }
      std::sort(times.begin(), times.end());
      std::sort(cpu.begin(), cpu.end());
      std::sort(cpu_reserved.begin(), cpu_reserved.end());
      auto start = std::chrono::steady_clock::now();
      bool valid = validate_mesh(mesh).ok();
      double validate_ms = milliseconds_since(start);
      fmt::print("{:>8} {:>8} {:>9} {:>10} {:>12.2f} {:>12.2f} {:>12.2f} {:>14.2f} {:>10.1f}{}\n", sphere.n_faces(),
                 name, report.crossed_edges, mesh.n_faces(), cpu.front(), cpu[cpu.size() / 2], times.front(),
                 cpu_reserved.front(), validate_ms, valid ? "" : "  INVALID");
      csv << fmt::format("{},{},{},{},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f}\n", sphere.n_faces(), name,
                         report.crossed_edges, mesh.n_faces(), cpu.front(), cpu[cpu.size() / 2], times.front(),
                         cpu_reserved.front(), validate_ms);
    }
  }
  fmt::print("wrote {}\n", csv_path);
  return 0;
}
