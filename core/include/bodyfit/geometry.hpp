#pragma once
// Geometry and quality of a SurfaceMesh: areas, normals, P1 gradients, quality, edge statistics,
// and the topological invariants (Euler characteristic, components, boundary loops).
#include <bodyfit/mesh.hpp>

#include <array>
#include <functional>
#include <span>
#include <utility>
#include <vector>

namespace bodyfit {

// ---- elements ----------------------------------------------------------------------------------

std::array<Vec3, 3> face_points(const SurfaceMesh& mesh, FaceHandle f);
std::array<VertexHandle, 3> face_vertices(const SurfaceMesh& mesh, FaceHandle f);
double triangle_area(const Vec3& a, const Vec3& b, const Vec3& c);
double face_area(const SurfaceMesh& mesh, FaceHandle f);
/// Unit normal of the face (right-hand rule on its vertex order); zero for a degenerate face.
Vec3 face_normal(const SurfaceMesh& mesh, FaceHandle f);
/// Area-weighted average of the normals of the faces around v, normalised.
Vec3 vertex_normal(const SurfaceMesh& mesh, VertexHandle v);
double edge_length(const SurfaceMesh& mesh, EdgeHandle e);

/// Quality q = 4√3·area / (l1² + l2² + l3²): 1 for an equilateral triangle, 0 when degenerate.
double triangle_quality(const Vec3& a, const Vec3& b, const Vec3& c);
double face_quality(const SurfaceMesh& mesh, FaceHandle f);

/// Gradients of the three P1 basis functions of the triangle (a, b, c), in its plane.
std::array<Vec3, 3> p1_basis_gradients(const Vec3& a, const Vec3& b, const Vec3& c);
/// Tangential gradient of the P1 field u on face f (constant on the face).
Vec3 face_gradient(const SurfaceMesh& mesh, FaceHandle f, const ScalarField& u);
/// Per-face tangential gradients of u, indexed by face index.
VectorField face_gradients(const SurfaceMesh& mesh, const ScalarField& u);
/// Per-vertex gradients: area-weighted average of the face gradients around each vertex, then
/// projected on the vertex's tangent plane (vertex_normal).
VectorField vertex_gradients(const SurfaceMesh& mesh, const ScalarField& u);
/// The same at `vertices` only (zero elsewhere), bit for bit: each vertex sums its faces in the order
/// of vertex_gradients, so that a narrow band sees the values of the whole-surface computation.
VectorField vertex_gradients(const SurfaceMesh& mesh, const ScalarField& u, std::span<const int> vertices);
/// The same at one vertex (for a few vertices; vertex_gradients is one pass over all faces).
Vec3 vertex_gradient(const SurfaceMesh& mesh, VertexHandle v, const ScalarField& u);
/// v − (v·n) n.
Vec3 project_tangent(const Vec3& v, const Vec3& unit_normal);

/// Barycentric coordinates of p (assumed in or near the plane of abc) with respect to abc.
std::array<double, 3> barycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// ---- measures ----------------------------------------------------------------------------------

struct BoundingBox {
  Vec3 min{0, 0, 0}, max{0, 0, 0};
  double diagonal() const { return (max - min).norm(); }
};
BoundingBox bounding_box(const SurfaceMesh& mesh);
BoundingBox bounding_box(std::span<const Vec3> points);
/// Indices of the points sorted by their Z-order (Morton) code in the points' bounding box (21 bits
/// per axis), ties by index: a deterministic, spatially coherent order for cache-friendly sweeps.
std::vector<int> z_order(const std::vector<Vec3>& points);
/// The same with the codes taken in `box` (which must hold the points): some of a larger set's
/// points come out in the order they have in the whole set's z_order.
std::vector<int> z_order(const std::vector<Vec3>& points, const BoundingBox& box);

struct QualityStats {
  double min = 0, mean = 0, max = 0;
  double share_below_0_3 = 0;  ///< fraction of faces with q < 0.3
  std::size_t faces = 0;
};
QualityStats quality_stats(const SurfaceMesh& mesh);

struct EdgeLengthStats {
  double min = 0, mean = 0, max = 0, stddev = 0;
  std::size_t edges = 0;
};
EdgeLengthStats edge_length_stats(const SurfaceMesh& mesh);
/// Mean edge length (the h of Δt = c·h).
double mean_edge_length(const SurfaceMesh& mesh);
/// The mesh's resolution as one length: the side of the equilateral triangle of its mean face area,
/// √(4 A / (√3 F)). A uniform remesh to this size keeps about as many faces, whatever the shapes of
/// the input's triangles (stretched scans and thin parts included); the default size of the stage
/// commands and of `run` (RemeshOptions::hmax).
double resolution_length(const SurfaceMesh& mesh);

double total_area(const SurfaceMesh& mesh);
/// Area of the faces whose region label equals `region`.
double region_area(const SurfaceMesh& mesh, int region);
/// Total length of the edges tagged as interface.
double interface_length(const SurfaceMesh& mesh);
/// Line segments in space (an interface as its edges).
using Segment = std::pair<Vec3, Vec3>;
using Segments = std::vector<Segment>;
Segments interface_segments(const SurfaceMesh& mesh);
/// Hausdorff distance between two sets of segments: the largest distance from an end or midpoint
/// of a segment of either to the other set (3-D, brute force: for tests and benchmarks). ∞ when
/// only one is empty, 0 when both are.
double hausdorff_distance(const Segments& a, const Segments& b);
/// The same between the interfaces of two meshes of one surface.
double interface_hausdorff(const SurfaceMesh& a, const SurfaceMesh& b);

/// (∫_S (u_h − u)²)^½ for a P1 field u_h and an exact function u, with the edge-midpoint rule on
/// each flat triangle (exact for quadratics): the error measure E of the paper's (4.5).
double l2_difference(const SurfaceMesh& mesh, const ScalarField& u_h, const std::function<double(const Vec3&)>& u);

// ---- topology ----------------------------------------------------------------------------------

/// V − E + F over the non-deleted elements.
long euler_characteristic(const SurfaceMesh& mesh);
/// Connected components through shared edges; `labels` (optional) receives each face's component.
int connected_components(const SurfaceMesh& mesh, std::vector<int>* labels = nullptr);
/// Components of the set of faces with the given region label (adjacent through edges).
int region_components(const SurfaceMesh& mesh, int region);
/// Closed boundary loops, each as the ordered list of its vertices.
std::vector<std::vector<VertexHandle>> boundary_loops(const SurfaceMesh& mesh);
/// Count of closed interface curves and of interface curves that end on the boundary.
struct InterfaceCurves {
  int closed = 0;
  int open = 0;
};
InterfaceCurves interface_curves(const SurfaceMesh& mesh);

}  // namespace bodyfit
