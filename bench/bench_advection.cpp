// Advection benchmark: φ0 = β − π/4 (β the polar angle) carried along the unit field e_β for
// T = π/4 in one advect() call, on geodesic spheres of 2.4k to 620k faces; exact φ(T) = β − a − T
// where β > T. Errors in the band |β − π/2| < 0.25.
//   bench_advection [out.csv] [--rk 4] [--cells C] [--p1] [--repeat N] [--sizes 11,22,44]
// (sizes are the sphere frequencies k, 20k² faces; times are medians over N calls, default 5)
#include "bench_args.hpp"

#include <bodyfit/advection.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

using namespace bodyfit;

int main(int argc, char** argv) {
  std::string csv = "bench_advection.csv";
  AdvectionOptions options;
  std::vector<int> ks = {11, 22, 44, 88, 176};
  int repeat = 5;  // timings are the median of this many calls (a shared machine is noisy)
  bench::Arguments args("bench_advection",
                        "usage: bench_advection [out.csv] [--rk 4] [--cells C] [--p1] [--repeat N] [--sizes 11,22,44]\n"
                        "  out.csv   CSV output (default bench_advection.csv)\n"
                        "  --rk      Runge-Kutta order of the characteristics (2 or 4)\n"
                        "  --cells   cells crossed per sub-step (max_cells_per_substep)\n"
                        "  --p1      plain P1 values at the feet (no gradient correction)\n"
                        "  --repeat  calls per size; times are their median (default 5)\n"
                        "  --sizes   sphere frequencies k (20k^2 faces; default 11,22,44,88,176)\n");
  args.positional("out.csv", csv);
  args.option("--rk", options.rk_order);
  args.option("--cells", options.max_cells_per_substep);
  args.flag("--p1", [&] { options.gradient_correction = false; });
  args.option("--repeat", repeat);
  args.option("--sizes", ks);
  args.parse(argc, argv);
  repeat = std::max(1, repeat);
  const double a = M_PI / 4, T = M_PI / 4;
  std::ofstream out(csv);
  out << "faces,h,band_l2,band_linf,order,ms,cpu_ms,setup_ms,substeps,lost\n";
  std::printf("advection of beta - pi/4 along e_beta, T = pi/4, RK%d, %.2f cells per sub-step, %s\n",
              options.rk_order, options.max_cells_per_substep,
              options.gradient_correction ? "gradient-corrected values" : "plain P1 values");
  std::printf("%9s %9s %11s %11s %6s %9s %9s %9s %11s %5s\n", "faces", "h", "band L2", "band Linf", "order", "ms",
              "cpu ms", "setup ms", "substeps", "lost");
  double previous_l2 = 0, previous_h = 0;
  for (int k : ks) {
    const SurfaceMesh mesh = make_sphere({.faces = std::size_t(20) * k * k});
    const std::size_t nv = mesh.n_vertices();
    ScalarField phi(nv);
    VectorField velocity(nv);
    std::vector<double> beta(nv);
    for (auto v : mesh.vertices()) {
      const Vec3 p = mesh.point(v);
      const double b = std::acos(std::clamp(p[2] / p.norm(), -1.0, 1.0));
      const double al = std::atan2(p[1], p[0]);
      beta[v.idx()] = b;
      phi[v.idx()] = b - a;
      velocity[v.idx()] = Vec3(std::cos(al) * std::cos(b), std::sin(al) * std::cos(b), -std::sin(b));
    }
    // Each timing is the median over `repeat` calls; the fixed cost (tables, Z-order, vertex
    // gradients) is that of the same call with T = 0.
    auto median = [](std::vector<double> v) {
      std::sort(v.begin(), v.end());
      return v[v.size() / 2];
    };
    std::vector<double> setup_runs, wall_runs, cpu_runs;
    AdvectionReport report;
    ScalarField result;
    for (int r = 0; r < repeat; ++r) {
      const auto s0 = std::chrono::steady_clock::now();
      (void)advect(mesh, phi, velocity, 0.0, options);
      setup_runs.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - s0).count());
      const auto t0 = std::chrono::steady_clock::now();
      const std::clock_t c0 = std::clock();
      result = advect(mesh, phi, velocity, T, options, &report);
      cpu_runs.push_back(1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC);  // all threads
      wall_runs.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    const double setup_ms = median(setup_runs), ms = median(wall_runs), cpu_ms = median(cpu_runs);

    // Dual (barycentric) areas: a third of each incident face.
    std::vector<double> dual(nv, 0.0);
    for (auto f : mesh.faces()) {
      const double third = face_area(mesh, f) / 3;
      for (auto v : mesh.fv_range(f)) dual[v.idx()] += third;
    }
    double l2 = 0, linf = 0;
    for (std::size_t i = 0; i < nv; ++i) {
      if (std::abs(beta[i] - M_PI / 2) >= 0.25) continue;
      const double e = result[i] - (beta[i] - a - T);
      l2 += dual[i] * e * e;
      linf = std::max(linf, std::abs(e));
    }
    l2 = std::sqrt(l2);
    const double h = edge_length_stats(mesh).mean;
    const double order = previous_l2 > 0 ? std::log(previous_l2 / l2) / std::log(previous_h / h) : 0.0;
    std::printf("%9zu %9.5f %11.3e %11.3e %6.2f %9.1f %9.1f %9.1f %11zu %5zu\n", std::size_t(mesh.n_faces()), h, l2,
                linf, order, ms, cpu_ms, setup_ms, report.substeps, report.lost);
    out << mesh.n_faces() << ',' << h << ',' << l2 << ',' << linf << ',' << order << ',' << ms << ',' << cpu_ms << ','
        << setup_ms << ',' << report.substeps << ',' << report.lost << '\n';
    previous_l2 = l2;
    previous_h = h;
  }
  std::printf("written %s\n", csv.c_str());
  return 0;
}
