#pragma once
// P1 fields carried from one surface mesh to points of another mesh of the same surface: each point
// takes the field at its closest point of the source mesh, interpolated barycentrically. The thermal
// model carries d_G from each state's mesh to the fixed volume mesh's boundary, and u, p back.
#include <bodyfit/mesh.hpp>
#include <bodyfit/projection.hpp>

#include <array>
#include <vector>

namespace bodyfit::thermal {

/// Where points lie on a source mesh: the three vertices of the face holding each one's closest
/// point, and its barycentric coordinates there.
struct SurfaceLocations {
  std::vector<std::array<int, 3>> vertices;
  std::vector<std::array<double, 3>> weights;
};

/// The vertex positions of `mesh`, by index.
std::vector<Vec3> vertex_points(const SurfaceMesh& mesh);

/// The points' closest points on `source`; `reference` is ReferenceSurface(source) (its triangle i
/// is source's face i: source must be garbage-collected, InputError otherwise).
SurfaceLocations locate(const SurfaceMesh& source, const ReferenceSurface& reference, const std::vector<Vec3>& points);

/// The P1 field `field` (one value per source vertex) at the located points.
std::vector<double> interpolate(const SurfaceLocations& locations, const std::vector<double>& field);

}  // namespace bodyfit::thermal
