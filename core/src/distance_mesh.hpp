#pragma once
// The surface as the fast marching reads it (distance.cpp): flat arrays of corners, neighbours
// and vertex fans, with every obtuse corner split by Kimmel–Sethian unfolding.
#include <bodyfit/mesh.hpp>

#include <cstdint>
#include <vector>

namespace bodyfit::distance_detail {

/// Gram data of a corner: the triangle (x; a, b) seen from x, with ea = a − x, eb = b − x.
struct CornerGeometry {
  double aa = 0, bb = 0, ab = 0;  ///< |ea|², |eb|², ea·eb
};

inline CornerGeometry corner_geometry(const Vec3& ea, const Vec3& eb) { return {ea.sqrnorm(), eb.sqrnorm(), ea | eb}; }

/// For an obtuse corner: the vertex r found by unfolding the faces beyond the opposite edge that
/// splits the angle into two acute ones, with the geometry of the virtual triangles (x; a, r) and
/// (x; r, b).
struct ObtuseSplit {
  int corner = -1;  ///< 3f + c of the obtuse corner
  int vertex = -1;  ///< r
  CornerGeometry first, second;
};

/// One triangle of the fan around a vertex v: its two other vertices in order (v, a, b), the corner
/// 3f + c of v, and which of the corners at a and b are obtuse (bits 1 and 2).
struct FanTriangle {
  int a = 0, b = 0;
  int corner = 0;
  std::uint8_t obtuse = 0;
};

/// The surface as flat arrays: the corners of each face, the face across the edge opposite each
/// corner, and the fan of triangles around each vertex (CSR), which the marching loop reads
/// sequentially.
struct FlatMesh {
  std::size_t nv = 0, nf = 0;
  std::vector<Vec3> points;
  std::vector<int> corner_vertex;   // 3f + c → vertex
  std::vector<int> across;          // 3f + c → face across the edge opposite corner c, or −1
  std::vector<int> obtuse;          // 3f + c → index into splits, −2 obtuse without split, −1 not obtuse
  std::vector<ObtuseSplit> splits;
  std::vector<int> split_start, split_list;  // vertex r → the splits that use it (CSR)
  std::vector<int> fan_start;       // vertex → its fan triangles (CSR)
  std::vector<FanTriangle> fan;
};

/// The flat arrays of `mesh`, its obtuse corners split and its fans built.
FlatMesh prepared_mesh(const SurfaceMesh& mesh);

/// Discrete Gaussian curvature at vertex v: angle defect over a third of the incident area
/// (0 on the boundary, where the defect measures the boundary's turning instead).
double gaussian_curvature(const FlatMesh& m, int v);

}  // namespace bodyfit::distance_detail
