// Remeshing real meshes at the default options, as `bodyfit remesh in.off -o out.mesh` does, and
// what a user of scans and CAD parts checks afterwards (docs/validation/real_meshes.md):
//
//   bench_real_meshes [--dir meshes/public] [--meshes a.off,b.off] [--no-distance-checks] [-o real_meshes.csv]
//
// Per mesh: faces in and out, the worst and mean quality, the distance between the output and the
// input both ways (output vertices and face centroids to the input's triangles; input vertices to
// the output's), in units of the default hausd (diagonal/1000), the change of area, the length of
// sharp edges (dihedral angle above 45°) before and after, triangle pairs of the output that
// intersect (beyond the vertices and edges they share), and the time.
#include "bench_args.hpp"

#include <bodyfit/app/stages.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/projection.hpp>
#include <bodyfit/self_intersections.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <unordered_map>

using namespace bodyfit;

namespace {

/// Largest distance from `samples` (the mesh's vertices and face centroids) to `surface`.
double distance_to(const SurfaceMesh& samples, const ReferenceSurface& surface, bool centroids) {
  double worst = 0;
  for (auto v : samples.vertices()) worst = std::max(worst, (surface.closest(samples.point(v)).point - samples.point(v)).norm());
  if (centroids)
    for (auto f : samples.faces()) {
      Vec3 c(0, 0, 0);
      for (auto v : samples.fv_range(f)) c += samples.point(v) / 3.0;
      worst = std::max(worst, (surface.closest(c).point - c).norm());
    }
  return worst;
}

/// Total length of the edges whose dihedral angle exceeds 45°.
double sharp_length(const SurfaceMesh& mesh) {
  const double threshold = std::cos(45.0 * std::numbers::pi / 180);
  double length = 0;
  for (auto e : mesh.edges()) {
    if (mesh.is_boundary(e)) continue;
    const auto h = mesh.halfedge_handle(e, 0);
    const Vec3 a = face_normal(mesh, mesh.face_handle(h)), b = face_normal(mesh, mesh.face_handle(mesh.opposite_halfedge_handle(h)));
    if (OpenMesh::dot(a, b) < threshold) length += mesh.calc_edge_length(e);
  }
  return length;
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path dir = "meshes/public", csv_path = "real_meshes.csv";
  std::vector<std::string> names;
  bool no_distance_checks = false;
  bench::Arguments args("bench_real_meshes",
                        "usage: bench_real_meshes [--dir meshes/public] [--meshes a.off,b.off] [--no-distance-checks]\n"
                        "                         [-o real_meshes.csv]\n"
                        "  --dir     where the meshes are (scripts/setup.sh extracts them there)\n"
                        "  --meshes  the files in --dir (default: every .off there)\n"
                        "  --no-distance-checks  remesh without holding each change within hausd of the input\n"
                        "            (RemeshOptions::check_distance_to_reference = false)\n"
                        "  -o        the CSV written\n");
  args.option("--dir", dir);
  args.option("--meshes", names);
  args.flag("--no-distance-checks", no_distance_checks);
  args.option("-o", csv_path);
  args.parse(argc, argv);
  if (!std::filesystem::is_directory(dir)) args.fail(dir.string() + ": no such directory (scripts/setup.sh extracts the meshes)");
  if (names.empty()) {
    for (const auto& entry : std::filesystem::directory_iterator(dir))
      if (entry.path().extension() == ".off") names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
  }
  if (names.empty()) args.fail("no .off file in " + dir.string() + " (scripts/setup.sh extracts them)");
  std::ofstream csv(csv_path);
  csv << "mesh,faces_in,faces_out,q_min_in,q_min,q_mean,dist_out_to_in,dist_in_to_out,hausd,area_change_pct,"
         "sharp_length_in,sharp_length_out,self_intersections_in,self_intersections_out,ms\n";
  std::printf("%-22s %8s %8s %6s %6s %6s %9s %9s %8s %10s %10s %6s %6s %8s\n", "mesh", "in", "out", "q_in", "q_min",
              "q_mean", "out→in", "in→out", "area %", "sharp in", "sharp out", "x in", "x out", "ms");
  int failed = 0;
  for (const std::string& name : names) {
    SurfaceMesh input;
    try {
      input = read_mesh(dir / name);
    } catch (const std::exception& e) {  // a mesh that cannot be read is reported, the others measured
      std::fprintf(stderr, "bench_real_meshes: %s\n", e.what());
      ++failed;
      continue;
    }
    SurfaceMesh output = input;
    const auto start = std::chrono::steady_clock::now();
    RemeshOptions options;
    options.check_distance_to_reference = !no_distance_checks;
    remesh_stage(output, options);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const double hausd = bounding_box(input).diagonal() / 1000;  // RemeshOptions' default
    const ReferenceSurface in_surface(input), out_surface(output);
    const double out_to_in = distance_to(output, in_surface, true) / hausd;
    const double in_to_out = distance_to(input, out_surface, false) / hausd;
    const double area_change = 100 * (total_area(output) / total_area(input) - 1);
    const double sharp_in = sharp_length(input), sharp_out = sharp_length(output);
    const std::size_t x_in = self_intersections(input).size(), x_out = self_intersections(output).size();
    const auto q_in = quality_stats(input), q = quality_stats(output);
    std::printf("%-22s %8zu %8zu %6.3f %6.3f %6.3f %9.2f %9.2f %8.3f %10.4g %10.4g %6zu %6zu %8.0f\n", name.c_str(),
                input.n_faces(), output.n_faces(), q_in.min, q.min, q.mean, out_to_in, in_to_out, area_change, sharp_in,
                sharp_out, x_in, x_out, ms);
    std::fflush(stdout);
    csv << name << ',' << input.n_faces() << ',' << output.n_faces() << ',' << q_in.min << ',' << q.min << ','
        << q.mean << ',' << out_to_in << ',' << in_to_out << ',' << hausd << ',' << area_change << ',' << sharp_in << ','
        << sharp_out << ',' << x_in << ',' << x_out << ',' << ms << '\n';
  }
  std::printf("-> %s\n", csv_path.string().c_str());
  return failed ? 1 : 0;
}
