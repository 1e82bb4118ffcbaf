// Remeshing real meshes at the default options, as `bodyfit remesh in.off -o out.mesh` does, and
// what a user of scans and CAD parts checks afterwards (docs/validation/real_meshes.md):
//
//   bench_real_meshes [--dir meshes/public] [--meshes a.off,b.off] [--no-distance-checks] [-o real_meshes.csv]
//
// Per mesh: faces in and out, the worst and mean quality, the distance between the output and the
// input both ways (output vertices and face centroids to the input's triangles; input vertices to
// the output's), in units of the default hausd (diagonal/1000), the change of area, the length of
// sharp edges (dihedral angle above 45°) before and after, triangle pairs of the output that
// intersect (not sharing a vertex), and the time.
#include "bench_args.hpp"

#include <bodyfit/app/stages.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/projection.hpp>

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

using Triangle = std::array<Vec3, 3>;

/// Whether two triangles overlap by more than `tolerance` along every axis of the separating-axis
/// test (their normals, the 9 cross products of their edges, and the in-plane edge normals for the
/// coplanar case).
bool triangles_intersect(const Triangle& a, const Triangle& b, double tolerance) {
  const Vec3 na = OpenMesh::cross(a[1] - a[0], a[2] - a[0]), nb = OpenMesh::cross(b[1] - b[0], b[2] - b[0]);
  std::vector<Vec3> axes{na, nb};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) axes.push_back(OpenMesh::cross(a[(i + 1) % 3] - a[i], b[(j + 1) % 3] - b[j]));
  for (int i = 0; i < 3; ++i) {
    axes.push_back(OpenMesh::cross(na, a[(i + 1) % 3] - a[i]));
    axes.push_back(OpenMesh::cross(nb, b[(i + 1) % 3] - b[i]));
  }
  for (Vec3 axis : axes) {
    const double n = axis.norm();
    if (n < 1e-300) continue;
    axis /= n;
    double a0 = 1e300, a1 = -1e300, b0 = 1e300, b1 = -1e300;
    for (const Vec3& p : a) a0 = std::min(a0, OpenMesh::dot(p, axis)), a1 = std::max(a1, OpenMesh::dot(p, axis));
    for (const Vec3& p : b) b0 = std::min(b0, OpenMesh::dot(p, axis)), b1 = std::max(b1, OpenMesh::dot(p, axis));
    if (a1 < b0 + tolerance || b1 < a0 + tolerance) return false;
  }
  return true;
}

/// Pairs of faces that intersect and share no vertex (a uniform grid of face bounding boxes).
std::size_t self_intersections(const SurfaceMesh& mesh) {
  const BoundingBox box = bounding_box(mesh);
  const double cell = std::max(edge_length_stats(mesh).mean * 2, 1e-12), tolerance = 1e-9 * box.diagonal();
  std::vector<Triangle> tri;
  std::vector<std::array<int, 3>> ids;
  for (auto f : mesh.faces()) {
    Triangle t;
    std::array<int, 3> id;
    int k = 0;
    for (auto v : mesh.fv_range(f)) t[k] = mesh.point(v), id[k++] = v.idx();
    tri.push_back(t);
    ids.push_back(id);
  }
  auto key = [&](int x, int y, int z) { return (std::int64_t(x) * 73856093) ^ (std::int64_t(y) * 19349663) ^ (std::int64_t(z) * 83492791); };
  std::unordered_map<std::int64_t, std::vector<int>> grid;
  auto range = [&](const Triangle& t, int axis) {
    double lo = std::min({t[0][axis], t[1][axis], t[2][axis]}), hi = std::max({t[0][axis], t[1][axis], t[2][axis]});
    return std::pair<int, int>(int(std::floor((lo - box.min[axis]) / cell)), int(std::floor((hi - box.min[axis]) / cell)));
  };
  std::size_t count = 0;
  for (std::size_t i = 0; i < tri.size(); ++i) {
    const auto [x0, x1] = range(tri[i], 0);
    const auto [y0, y1] = range(tri[i], 1);
    const auto [z0, z1] = range(tri[i], 2);
    std::vector<int> candidates;
    for (int x = x0; x <= x1; ++x)
      for (int y = y0; y <= y1; ++y)
        for (int z = z0; z <= z1; ++z) {
          auto& bucket = grid[key(x, y, z)];
          candidates.insert(candidates.end(), bucket.begin(), bucket.end());
          bucket.push_back(int(i));
        }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    for (int j : candidates) {
      bool shared = false;
      for (int a : ids[i])
        for (int b : ids[std::size_t(j)]) shared |= a == b;
      if (!shared && triangles_intersect(tri[i], tri[std::size_t(j)], tolerance)) ++count;
    }
  }
  return count;
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
    const std::size_t x_in = self_intersections(input), x_out = self_intersections(output);
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
