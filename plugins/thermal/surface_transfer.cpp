#include "surface_transfer.hpp"

#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <algorithm>

namespace bodyfit::thermal {

std::vector<Vec3> vertex_points(const SurfaceMesh& mesh) {
  std::vector<Vec3> points(mesh.n_vertices());
  for (auto v : mesh.vertices()) points[std::size_t(v.idx())] = mesh.point(v);
  return points;
}

SurfaceLocations locate(const SurfaceMesh& source, const ReferenceSurface& reference, const std::vector<Vec3>& points) {
  if (reference.n_triangles() != source.n_faces())
    throw InputError(fmt::format("surface transfer: the reference has {} triangles for {} faces (a mesh with deleted "
                                 "elements must be garbage-collected first)",
                                 reference.n_triangles(), source.n_faces()));
  SurfaceLocations out;
  out.vertices.resize(points.size());
  out.weights.resize(points.size());
  int hint = -1;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const SurfacePoint q = reference.closest(points[i], hint);
    hint = q.face;
    const auto face = source.face_handle(q.face);
    std::array<int, 3> v{};
    std::array<Vec3, 3> p;
    int k = 0;
    for (auto vh : source.fv_range(face)) v[std::size_t(k)] = vh.idx(), p[std::size_t(k++)] = source.point(vh);
    // Barycentric coordinates of q in (p0, p1, p2), clamped to the triangle (q lies on it up to
    // round-off).
    const Vec3 e0 = p[1] - p[0], e1 = p[2] - p[0], r = q.point - p[0];
    const double d00 = e0.sqrnorm(), d01 = OpenMesh::dot(e0, e1), d11 = e1.sqrnorm();
    const double d20 = OpenMesh::dot(r, e0), d21 = OpenMesh::dot(r, e1), det = d00 * d11 - d01 * d01;
    double b1 = det > 0 ? (d11 * d20 - d01 * d21) / det : 0, b2 = det > 0 ? (d00 * d21 - d01 * d20) / det : 0;
    b1 = std::clamp(b1, 0.0, 1.0), b2 = std::clamp(b2, 0.0, 1.0 - b1);
    out.vertices[i] = v;
    out.weights[i] = {1 - b1 - b2, b1, b2};
  }
  return out;
}

std::vector<double> interpolate(const SurfaceLocations& locations, const std::vector<double>& field) {
  std::vector<double> out(locations.vertices.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const auto& v = locations.vertices[i];
    const auto& w = locations.weights[i];
    out[i] = w[0] * field.at(std::size_t(v[0])) + w[1] * field.at(std::size_t(v[1])) + w[2] * field.at(std::size_t(v[2]));
  }
  return out;
}

}  // namespace bodyfit::thermal
