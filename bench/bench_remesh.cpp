// Benchmark of discretize + remesh against the figures of `mmgs -ls` (docs/validation/remeshing.md).
//
//   bench_remesh [--quick] [--spheres 9700,242000 (0: none)] [--no-terrain] [csv]   (default csv: bench_remesh.csv)
//
// Sphere: geodesic unit sphere, φ = β − π/4 (β = acos z), hmax = mean input edge; the remesher
// projects onto the exact sphere. Terrain: make_terrain over [0,50]² (in km) with a 1 km disk, the
// remesher projects onto the input triangles. Then one evolution step: the cap grows by about one
// element (β − (π/4 + h)), discretize + remesh of the already-remeshed mesh; its cost is compared
// with the full first remeshing.
#include "bench_args.hpp"

#include <bodyfit/app/terrain.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/levelset_mesher.hpp>
#include <bodyfit/projection.hpp>
#include <bodyfit/remesh.hpp>
#include <bodyfit/validate.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

using namespace bodyfit;

namespace {

double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Row {
  std::string name;
  std::size_t input_faces = 0, output_faces = 0;
  double discretize_ms = 0, remesh_ms = 0;
  RemeshReport report;
  QualityStats quality;
  double interface_error = 0;  // rad (sphere) or km (terrain)
  double hausdorff = 0;        // max distance of vertices and edge midpoints to S
  long euler = 0;
  std::size_t loops = 0;
  bool valid = false;
  std::size_t interface_vertices = 0;
};

void print(const Row& r) {
  std::printf(
      "%-22s in %7zu out %7zu | discretize %8.1f ms remesh %8.1f ms total %8.1f ms | q min %.3f mean %.3f "
      "<0.3 %.4f | iface err %.2e (%zu v) | hausdorff %.2e | chi %ld loops %zu | %s | splits %zu collapses %zu "
      "flips %zu moves %zu split rounds %d passes %d (%s)\n",
      r.name.c_str(), r.input_faces, r.output_faces, r.discretize_ms, r.remesh_ms, r.discretize_ms + r.remesh_ms,
      r.quality.min, r.quality.mean, r.quality.share_below_0_3, r.interface_error, r.interface_vertices, r.hausdorff,
      r.euler, r.loops, r.valid ? "valid" : "INVALID", r.report.splits, r.report.collapses, r.report.flips,
      r.report.relocations, r.report.split_rounds, r.report.passes, to_string(r.report.stop));
  std::fflush(stdout);
}

/// Discretize φ into `mesh`, remesh, and measure everything.
Row run_case(const std::string& name, SurfaceMesh& mesh, const ScalarField& phi, RemeshOptions options,
             const std::function<double(const Vec3&)>& interface_error,
             const std::function<double(const Vec3&)>& distance_to_s, long euler, std::size_t loops) {
  Row row;
  row.name = name;
  row.input_faces = mesh.n_faces();
  double t0 = now_ms();
  DiscretizeOptions cut;
  cut.snap_ratio = 0;  // snapping moves the interface by up to snap_ratio·h: the remesher cleans up instead
  discretize(mesh, phi, cut);
  double t1 = now_ms();
  row.report = remesh(mesh, options);
  double t2 = now_ms();
  row.discretize_ms = t1 - t0;
  row.remesh_ms = t2 - t1;
  row.output_faces = mesh.n_faces();
  row.quality = quality_stats(mesh);
  for (auto e : mesh.edges()) {
    auto h = mesh.halfedge_handle(e, 0);
    Vec3 a = mesh.point(mesh.from_vertex_handle(h)), b = mesh.point(mesh.to_vertex_handle(h));
    row.hausdorff = std::max({row.hausdorff, distance_to_s(a), distance_to_s((a + b) * 0.5)});
    if (mesh.interface(e)) row.interface_error = std::max({row.interface_error, interface_error(a), interface_error(b)});
  }
  for (auto v : mesh.vertices())
    for (auto e : mesh.ve_range(v))
      if (mesh.interface(e)) {
        ++row.interface_vertices;
        break;
      }
  row.euler = euler_characteristic(mesh);
  row.loops = boundary_loops(mesh).size();
  ValidateOptions vo;
  vo.euler_characteristic = euler;
  vo.boundary_loops = loops;
  auto report = validate_mesh(mesh, vo);
  row.valid = report.ok();
  if (!report.ok()) std::printf("%s\n", report.summary().c_str());
  print(row);
  return row;
}

double mean_edge(const SurfaceMesh& mesh) { return edge_length_stats(mesh).mean; }

/// The procedural terrain of generators.hpp over [0, 50 km]² with about `faces` triangles, in km.
SurfaceMesh make_km_terrain(std::size_t faces) {
  TerrainOptions t;
  t.h = std::sqrt(t.extent * t.extent / double(faces) * 4 / std::sqrt(3.0));
  auto mesh = make_terrain(t);
  for (auto v : mesh.vertices()) mesh.set_point(v, mesh.point(v) * 1e-3);
  for (auto f : mesh.faces()) mesh.region(f) = kOutside;
  return mesh;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, terrain = true;
  std::string csv = "bench_remesh.csv";
  std::vector<std::size_t> sizes;
  bench::Arguments args("bench_remesh",
                        "usage: bench_remesh [--quick] [--spheres 9700,242000] [--no-terrain] [out.csv]\n"
                        "  --quick       the 9.7k sphere only\n"
                        "  --spheres     sphere sizes in faces (0: none; default 9700,60000,242000)\n"
                        "  --no-terrain  skip the terrain case\n"
                        "  out.csv       default bench_remesh.csv\n");
  args.flag("--quick", quick);
  args.flag("--no-terrain", [&] { terrain = false; });
  args.option("--spheres", sizes);
  args.positional("out.csv", csv);
  args.parse(argc, argv);
  std::vector<Row> rows;
  if (sizes.empty()) sizes = quick ? std::vector<std::size_t>{9700} : std::vector<std::size_t>{9700, 60000, 242000};

  auto beta = [](const Vec3& p) { return std::acos(std::clamp(p[2] / p.norm(), -1.0, 1.0)); };
  auto sphere_distance = [](const Vec3& p) { return std::abs(p.norm() - 1.0); };
  for (std::size_t faces : sizes) {
    if (faces == 0) continue;
    auto mesh = make_sphere({.faces = faces});
    double h = mean_edge(mesh);
    RemeshOptions options;
    options.hmax = h;
    options.reference = ReferenceSurface::sphere(Vec3(0, 0, 0), 1.0);
    auto phi_for = [&](const SurfaceMesh& m, double radius) {
      ScalarField phi(m.n_vertices());
      for (auto v : m.vertices()) phi[v.idx()] = beta(m.point(v)) - radius;
      return phi;
    };
    auto cap_error = [&](double radius) { return [=](const Vec3& p) { return std::abs(beta(p) - radius); }; };
    std::string tag = "sphere_" + std::to_string(mesh.n_faces());
    {
      // Reference point for the incremental cost: the same job with every vertex in the work queue.
      auto copy = mesh;
      RemeshOptions full = options;
      full.incremental = false;
      rows.push_back(run_case(tag + "_full", copy, phi_for(copy, M_PI / 4), full, cap_error(M_PI / 4), sphere_distance, 2, 0));
    }
    auto first = run_case(tag, mesh, phi_for(mesh, M_PI / 4), options, cap_error(M_PI / 4), sphere_distance, 2, 0);
    rows.push_back(first);
    // One evolution step: the cap grows by about one element.
    auto step = run_case(tag + "_step", mesh, phi_for(mesh, M_PI / 4 + h), options, cap_error(M_PI / 4 + h),
                         sphere_distance, 2, 0);
    rows.push_back(step);
    std::printf("  evolution-step cost / first remesh: %.3f, remesh only vs full (non-incremental) remesh: %.3f\n",
                (step.discretize_ms + step.remesh_ms) / (first.discretize_ms + first.remesh_ms),
                step.remesh_ms / rows[rows.size() - 3].remesh_ms);
  }

  if (terrain) {
    std::size_t faces = quick ? 20000 : 240000;
    auto mesh = make_km_terrain(faces);
    auto reference = std::make_shared<const ReferenceSurface>(mesh);
    RemeshOptions options;
    options.hmax = mean_edge(mesh);
    options.reference = reference;
    Vec3 centre(25, 25, 0);
    auto disk_phi = [&](const SurfaceMesh& m, double radius) {
      ScalarField phi(m.n_vertices());
      for (auto v : m.vertices()) {
        Vec3 p = m.point(v);
        phi[v.idx()] = std::hypot(p[0] - centre[0], p[1] - centre[1]) - radius;
      }
      return phi;
    };
    auto disk_error = [&](double radius) {
      return [=](const Vec3& p) { return std::abs(std::hypot(p[0] - centre[0], p[1] - centre[1]) - radius); };
    };
    auto to_s = [&](const Vec3& p) { return (reference->closest(p).point - p).norm(); };
    std::string tag = "terrain_" + std::to_string(mesh.n_faces());
    auto first = run_case(tag, mesh, disk_phi(mesh, 1.0), options, disk_error(1.0), to_s, 1, 1);
    rows.push_back(first);
    auto step = run_case(tag + "_step", mesh, disk_phi(mesh, 1.0 + options.hmax), options,
                         disk_error(1.0 + options.hmax), to_s, 1, 1);
    rows.push_back(step);
    std::printf("  evolution-step cost / first remesh: %.3f (discretize + remesh)\n",
                (step.discretize_ms + step.remesh_ms) / (first.discretize_ms + first.remesh_ms));
  }

  std::ofstream out(csv);
  out << "case,input_faces,output_faces,discretize_ms,remesh_ms,total_ms,q_min,q_mean,share_below_0_3,"
         "interface_error,hausdorff,euler,boundary_loops,valid,splits,collapses,flips,relocations,passes,split_rounds,stop\n";
  for (const auto& r : rows)
    out << r.name << ',' << r.input_faces << ',' << r.output_faces << ',' << r.discretize_ms << ',' << r.remesh_ms << ','
        << r.discretize_ms + r.remesh_ms << ',' << r.quality.min << ',' << r.quality.mean << ','
        << r.quality.share_below_0_3 << ',' << r.interface_error << ',' << r.hausdorff << ',' << r.euler << ','
        << r.loops << ',' << (r.valid ? 1 : 0) << ',' << r.report.splits << ',' << r.report.collapses << ','
        << r.report.flips << ',' << r.report.relocations << ',' << r.report.passes << ','
        << r.report.split_rounds << ',' << to_string(r.report.stop) << '\n';
  std::printf("wrote %s\n", csv.c_str());
  return 0;
}
