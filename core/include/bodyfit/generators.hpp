#pragma once
// Mesh generators: geodesic spheres and flat squares (height fields from grids: the application library).
#include <bodyfit/mesh.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace bodyfit {

struct SphereOptions {
  std::size_t faces = 20480;  ///< target face count (≥ 20); the result is within ±10 %
  double radius = 1.0;
  Vec3 center{0, 0, 0};
};
/// Sphere of about `faces` triangles (within ±10 %), all vertices exactly on the sphere, minimum
/// triangle quality ≥ 0.7, outward orientation. The closest geodesic count is used: class I
/// (subdivided icosahedron, frequency k, 20k² faces, exact for 20k²) or Goldberg–Coxeter class II/III
/// (20(a² + ab + b²) faces); counts with no geodesic sphere within 10 % (some below 300) get a
/// Delaunay triangulation of N/2 + 2 points spread by Coulomb repulsion.
SurfaceMesh make_sphere(const SphereOptions& options = {});

struct PlaneOptions {
  double size = 2;  ///< side of the square [-size/2, size/2]² at z = 0
  double h = 0.05;  ///< target edge length
};
/// A flat open square triangulated with rows of near-equilateral triangles of edge ≈ h (odd rows
/// shifted by half a cell; the end cells of those rows are the worst triangles, quality > 0.5):
/// one boundary loop, normals +z, region label 2. Throws InputError for a non-positive size or h.
SurfaceMesh make_plane(const PlaneOptions& options = {});

}  // namespace bodyfit
