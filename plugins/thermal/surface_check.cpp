#include "surface_check.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>

#include <fmt/format.h>

#include <map>

namespace bodyfit::thermal {

double enclosed_volume(const SurfaceMesh& surface) {
  double six_v = 0;
  for (auto f : surface.faces()) {
    auto [a, b, c] = face_points(surface, f);
    six_v += OpenMesh::dot(a, OpenMesh::cross(b, c));
  }
  return six_v / 6;
}

void check_solid_surface(const SurfaceMesh& surface, const SurfaceCheckOptions& options, const char* what) {
  auto fail = [&](const std::string& message) {
    return InputError(fmt::format("{}: {}: the thermal model needs the skin of a solid", what, message));
  };
  if (surface.n_faces() < 4) throw fail(fmt::format("the surface has {} faces", surface.n_faces()));
  if (surface.has_vertex_status())
    for (auto v : surface.all_vertices())
      if (surface.status(v).deleted()) throw fail("the surface has deleted vertices (garbage-collect it first)");
  if (surface.has_face_status())
    for (auto f : surface.all_faces())
      if (surface.status(f).deleted()) throw fail("the surface has deleted faces (garbage-collect it first)");

  // Closed and manifold. OpenMesh cannot hold an edge with three faces, but it can hold a vertex
  // whose faces form several fans: count the faces met by circulation against the incidences.
  std::size_t boundary_edges = 0;
  for (auto e : surface.edges())
    if (surface.is_boundary(e)) ++boundary_edges;
  if (boundary_edges > 0)
    throw fail(fmt::format("the surface is not closed ({} boundary edges)", boundary_edges));
  std::vector<int> incident(surface.n_vertices(), 0);
  for (auto f : surface.faces())
    for (auto v : surface.fv_range(f)) ++incident[std::size_t(v.idx())];
  for (auto v : surface.vertices()) {
    if (incident[std::size_t(v.idx())] == 0)
      throw fail(fmt::format("vertex {} belongs to no face (TetGen would renumber the vertices)", v.idx()));
    int around = 0;
    for (auto f : surface.vf_range(v)) {
      (void)f;
      ++around;
    }
    if (around != incident[std::size_t(v.idx())])
      throw fail(fmt::format("the surface is not manifold at vertex {} ({} faces in several fans)", v.idx(),
                             incident[std::size_t(v.idx())]));
  }

  // Degenerate faces and duplicate points (TetGen would merge the latter and renumber).
  auto box = bounding_box(surface);
  double diagonal = (box.max - box.min).norm();
  for (auto f : surface.faces())
    if (!(face_area(surface, f) > 1e-14 * diagonal * diagonal))
      throw fail(fmt::format("face {} is degenerate (area {:.3g})", f.idx(), face_area(surface, f)));
  {
    std::map<std::array<double, 3>, int> seen;
    for (auto v : surface.vertices()) {
      const Vec3& p = surface.point(v);
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
        throw fail(fmt::format("vertex {} is not finite", v.idx()));
      auto [it, inserted] = seen.emplace(std::array<double, 3>{p[0], p[1], p[2]}, v.idx());
      if (!inserted) throw fail(fmt::format("vertices {} and {} are at the same point", it->second, v.idx()));
    }
  }

  // Orientation: the halfedge structure makes it consistent within each component; outward means a
  // positive enclosed volume (a cavity's inward skin subtracts, as it should).
  double volume = enclosed_volume(surface);
  if (!(volume > 0))
    throw fail(fmt::format("the surface encloses a volume of {:.6g}: it is oriented inward (flip its faces)", volume));

  if (options.self_intersections) {
    auto pairs = bodyfit::self_intersections(surface, 1);
    if (!pairs.empty())
      throw fail(fmt::format("the surface is self-intersecting (faces {} and {} intersect)", pairs[0].first,
                             pairs[0].second));
  }
}

}  // namespace bodyfit::thermal
