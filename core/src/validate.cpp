#include <bodyfit/geometry.hpp>
#include <bodyfit/validate.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace bodyfit {

std::string ValidationReport::summary() const {
  std::string text;
  for (const auto& line : problems) text += line + "\n";
  if (problem_count > problems.size())
    text += fmt::format("... and {} more problems\n", problem_count - problems.size());
  if (problem_count == 0) text = "valid\n";
  return text;
}

namespace {

class Collector {
 public:
  Collector(ValidationReport& report, std::size_t max) : report_(report), max_(max) {}
  template <class... Args>
  void add(fmt::format_string<Args...> format, Args&&... args) {
    ++report_.problem_count;
    if (report_.problems.size() < max_) report_.problems.push_back(fmt::format(format, std::forward<Args>(args)...));
  }

 private:
  ValidationReport& report_;
  std::size_t max_;
};

bool finite(const Vec3& p) { return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]); }

void check_deleted(const SurfaceMesh& mesh, Collector& out) {
  std::size_t vertices = 0, edges = 0, faces = 0;
  for (std::size_t i = 0; i < mesh.n_vertices(); ++i) vertices += mesh.status(VertexHandle(int(i))).deleted();
  for (std::size_t i = 0; i < mesh.n_edges(); ++i) edges += mesh.status(EdgeHandle(int(i))).deleted();
  for (std::size_t i = 0; i < mesh.n_faces(); ++i) faces += mesh.status(FaceHandle(int(i))).deleted();
  if (vertices + edges + faces > 0)
    out.add("deleted elements remain (not garbage-collected): {} vertices, {} edges, {} faces", vertices, edges, faces);
}

void check_structure(const SurfaceMesh& mesh, Collector& out) {
  for (auto v : mesh.vertices()) {
    if (!finite(mesh.point(v))) out.add("vertex {}: non-finite coordinates", v.idx());
    if (mesh.is_isolated(v)) out.add("vertex {}: isolated (in no face)", v.idx());
    else if (!mesh.is_manifold(v)) out.add("vertex {}: non-manifold (several fans of faces)", v.idx());
  }
  for (auto f : mesh.faces()) {
    auto h = mesh.halfedge_handle(f);
    std::array<VertexHandle, 3> v;
    bool broken = false;
    for (int k = 0; k < 3; ++k) {
      if (mesh.face_handle(h) != f || mesh.to_vertex_handle(h) != mesh.from_vertex_handle(mesh.next_halfedge_handle(h)) ||
          mesh.status(mesh.edge_handle(h)).deleted() || mesh.status(mesh.to_vertex_handle(h)).deleted())
        broken = true;
      v[k] = mesh.to_vertex_handle(h);
      h = mesh.next_halfedge_handle(h);
    }
    if (h != mesh.halfedge_handle(f) || v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) broken = true;
    if (broken) out.add("face {}: broken halfedge cycle (not a triangle of three distinct vertices)", f.idx());
  }
}

void check_geometry(const SurfaceMesh& mesh, const ValidateOptions& options, Collector& out) {
  for (auto f : mesh.faces()) {
    auto p = face_points(mesh, f);
    double longest = std::max({(p[1] - p[0]).sqrnorm(), (p[2] - p[1]).sqrnorm(), (p[0] - p[2]).sqrnorm()});
    double area = triangle_area(p[0], p[1], p[2]);
    if (!(area > options.degenerate_area_ratio * longest))
      out.add("face {}: degenerate (area {:.3g}, longest edge {:.3g})", f.idx(), area, std::sqrt(longest));
  }
  if (options.fold_angle_degrees > 0) {
    double cos_limit = std::cos(options.fold_angle_degrees * std::numbers::pi / 180);
    for (auto e : mesh.edges()) {
      if (mesh.is_boundary(e)) continue;
      auto f0 = mesh.face_handle(mesh.halfedge_handle(e, 0)), f1 = mesh.face_handle(mesh.halfedge_handle(e, 1));
      Vec3 n0 = face_normal(mesh, f0), n1 = face_normal(mesh, f1);
      if (n0.sqrnorm() == 0 || n1.sqrnorm() == 0) continue;  // reported as degenerate
      double c = OpenMesh::dot(n0, n1);
      if (c < cos_limit)
        out.add("edge {}: faces {} and {} folded onto each other (normals at {:.1f} degrees)", e.idx(), f0.idx(),
                f1.idx(), std::acos(std::clamp(c, -1.0, 1.0)) * 180 / std::numbers::pi);
    }
  }
  // Duplicated faces: equal sets of three points, found by sorting.
  std::vector<std::pair<std::array<double, 9>, int>> keys;
  keys.reserve(mesh.n_faces());
  for (auto f : mesh.faces()) {
    auto p = face_points(mesh, f);
    std::array<std::array<double, 3>, 3> sorted;
    for (int k = 0; k < 3; ++k) sorted[k] = {p[k][0], p[k][1], p[k][2]};
    std::sort(sorted.begin(), sorted.end());
    std::array<double, 9> key;
    for (int k = 0; k < 9; ++k) key[k] = sorted[k / 3][k % 3];
    keys.emplace_back(key, f.idx());
  }
  std::sort(keys.begin(), keys.end());
  for (std::size_t i = 1; i < keys.size(); ++i)
    if (keys[i].first == keys[i - 1].first)
      out.add("faces {} and {}: duplicated (same three points)", keys[i - 1].second, keys[i].second);
}

void check_regions(const SurfaceMesh& mesh, const ValidateOptions& options, Collector& out) {
  for (auto f : mesh.faces())
    if (mesh.region(f) != kInside && mesh.region(f) != kOutside)
      out.add("face {}: region label {} is neither inside ({}) nor outside ({})", f.idx(), mesh.region(f), kInside,
              kOutside);
  std::vector<int> degree(mesh.n_vertices(), 0);
  for (auto e : mesh.edges()) {
    bool expected = false;
    if (!mesh.is_boundary(e))
      expected = mesh.inside(mesh.face_handle(mesh.halfedge_handle(e, 0))) !=
                 mesh.inside(mesh.face_handle(mesh.halfedge_handle(e, 1)));
    if (mesh.interface(e) != expected) {
      if (expected)
        out.add("edge {}: separates inside from outside but is not tagged interface", e.idx());
      else
        out.add("edge {}: tagged interface but its faces have the same label (or it is on the boundary)", e.idx());
    }
    if (!mesh.interface(e)) continue;
    if (mesh.edge_ref(e) != kInterfaceRef)
      out.add("edge {}: interface edge with ref {} instead of {}", e.idx(), mesh.edge_ref(e), kInterfaceRef);
    for (int side = 0; side < 2; ++side) {
      auto v = mesh.to_vertex_handle(mesh.halfedge_handle(e, side));
      ++degree[v.idx()];
      if (options.check_phi_on_interface && !(std::abs(mesh.phi(v)) <= options.phi_tolerance))
        out.add("vertex {}: on the interface with phi = {:.3g}", v.idx(), mesh.phi(v));
    }
  }
  for (auto v : mesh.vertices())
    if (degree[v.idx()] != 0 && degree[v.idx()] != 2 && !mesh.is_boundary(v))
      out.add("vertex {}: {} interface edges (the interface is not a simple curve there)", v.idx(), degree[v.idx()]);
}

void check_expected(const SurfaceMesh& mesh, const ValidateOptions& options, Collector& out) {
  if (options.euler_characteristic) {
    long chi = euler_characteristic(mesh);
    if (chi != *options.euler_characteristic)
      out.add("Euler characteristic {} instead of {}", chi, *options.euler_characteristic);
  }
  if (options.boundary_loops) {
    std::size_t loops = boundary_loops(mesh).size();
    if (loops != *options.boundary_loops) out.add("{} boundary loops instead of {}", loops, *options.boundary_loops);
  }
  if (options.distance_to_reference)
    for (auto v : mesh.vertices()) {
      double d = options.distance_to_reference(mesh.point(v));
      if (!(d <= options.max_reference_distance))
        out.add("vertex {}: at distance {:.3g} from the reference (allowed {:.3g})", v.idx(), d,
                options.max_reference_distance);
    }
}

}  // namespace

ValidationReport validate_mesh(const SurfaceMesh& mesh, const ValidateOptions& options) {
  ValidationReport report;
  Collector out(report, options.max_problems);
  check_deleted(mesh, out);
  check_structure(mesh, out);
  check_geometry(mesh, options, out);
  if (options.check_regions) check_regions(mesh, options, out);
  check_expected(mesh, options, out);
  return report;
}

}  // namespace bodyfit
