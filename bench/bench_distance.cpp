// Accuracy and speed of the signed geodesic distance (docs/validation/levelset.md).
//
// Unit geodesic spheres of 20k² faces (k = 11, 22, 44, 88, 176), the cap of polar angle a = π/4 given
// by the non-distance level set φ0 = cos a − z; the exact signed distance is β − a (β = acos z).
// Prints faces, h (mean edge length), the L2 error (dual-cell weighted), the L∞ error near the
// interface (|exact| < 2h), the observed orders and the time (best of the repetitions: wall and
// thread CPU time, and the wall time of each stage); writes the table as CSV.
//
//   bench_distance [out.csv] [repetitions]
#include "bench_args.hpp"

#include <bodyfit/distance.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

namespace {

/// CPU time of this thread: the machine may be shared, and wall time then measures the queue.
double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

struct Row {
  std::size_t faces = 0, vertices = 0;
  double h = 0, l2 = 0, linf_near = 0, linf = 0, ms = 0, cpu_ms = 0, setup_ms = 0, init_ms = 0, march_ms = 0;
  std::size_t initialised = 0, marched = 0;
};

Row measure(std::size_t k, int repetitions) {
  using namespace bodyfit;
  const double cap = std::numbers::pi / 4;
  const SurfaceMesh mesh = make_sphere({.faces = 20 * k * k});
  ScalarField phi(mesh.n_vertices());
  for (auto v : mesh.vertices()) phi[v.idx()] = std::cos(cap) - mesh.point(v)[2];
  Row row;
  row.faces = mesh.n_faces();
  row.vertices = mesh.n_vertices();
  row.h = edge_length_stats(mesh).mean;
  ScalarField d;
  double best = 1e300;
  for (int r = 0; r < repetitions; ++r) {
    DistanceReport report;
    const double c0 = thread_cpu_ms();
    const auto t0 = std::chrono::steady_clock::now();
    d = signed_distance(mesh, phi, {}, &report);
    const auto t1 = std::chrono::steady_clock::now();
    row.cpu_ms = r == 0 ? thread_cpu_ms() - c0 : std::min(row.cpu_ms, thread_cpu_ms() - c0);
    const double ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
    if (ms < best) {
      best = ms;
      row.setup_ms = report.setup_ms;
      row.init_ms = report.init_ms;
      row.march_ms = report.march_ms;
    }
    row.initialised = report.initialised;
    row.marched = report.marched;
  }
  row.ms = best;
  std::vector<double> dual(mesh.n_vertices(), 0.0);
  for (auto f : mesh.faces())
    for (auto v : mesh.fv_range(f)) dual[v.idx()] += face_area(mesh, f) / 3;
  double sum = 0;
  for (auto v : mesh.vertices()) {
    const double z = std::clamp(mesh.point(v)[2] / mesh.point(v).norm(), -1.0, 1.0);
    const double exact = std::acos(z) - cap;
    const double err = std::abs(d[v.idx()] - exact);
    sum += err * err * dual[v.idx()];
    row.linf = std::max(row.linf, err);
    if (std::abs(exact) < 2 * row.h) row.linf_near = std::max(row.linf_near, err);
  }
  row.l2 = std::sqrt(sum);
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  std::string csv = "distance.csv";
  int repetitions = 5;
  bench::Arguments args("bench_distance",
                        "usage: bench_distance [out.csv] [repetitions]\n"
                        "  out.csv      CSV output (default distance.csv)\n"
                        "  repetitions  runs per sphere; times are the best (default 5)\n");
  args.positional("out.csv", csv);
  args.positional("repetitions", repetitions);
  args.parse(argc, argv);
  repetitions = std::max(1, repetitions);
  std::vector<Row> rows;
  std::printf("%9s %9s %10s %10s %6s %12s %6s %10s %9s %9s %8s %8s %7s %7s %7s\n", "faces", "vertices", "h", "L2", "ord",
              "Linf|d|<2h", "ord", "Linf", "init", "marched", "ms", "cpu_ms", "setup", "segs", "march");
  for (std::size_t k : {11, 22, 44, 88, 176}) {
    rows.push_back(measure(k, repetitions));
    const Row& r = rows.back();
    double o2 = NAN, oi = NAN;
    if (rows.size() > 1) {
      const Row& p = rows[rows.size() - 2];
      o2 = std::log(p.l2 / r.l2) / std::log(p.h / r.h);
      oi = std::log(p.linf_near / r.linf_near) / std::log(p.h / r.h);
    }
    std::printf("%9zu %9zu %10.3e %10.3e %6.2f %12.3e %6.2f %10.3e %9zu %9zu %8.2f %8.2f %7.2f %7.2f %7.2f\n", r.faces, r.vertices, r.h,
                r.l2, o2, r.linf_near, oi, r.linf, r.initialised, r.marched, r.ms, r.cpu_ms, r.setup_ms, r.init_ms, r.march_ms);
  }
  std::ofstream out(csv);
  out << "faces,vertices,h,l2,linf_near,linf,initialised,marched,ms,cpu_ms,setup_ms,segments_ms,march_ms\n";
  for (const Row& r : rows)
    out << r.faces << ',' << r.vertices << ',' << r.h << ',' << r.l2 << ',' << r.linf_near << ',' << r.linf << ','
        << r.initialised << ',' << r.marched << ',' << r.ms << ',' << r.cpu_ms << ',' << r.setup_ms << ',' << r.init_ms << ','
        << r.march_ms << '\n';
  std::printf("wrote %s\n", csv.c_str());
  return 0;
}
