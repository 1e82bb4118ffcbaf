#pragma once
// Interface-preserving adaptive remeshing of a surface mesh (second half of step 4 of Algorithm 1,
// paper §3.4), to any target size in one call: first every edge above the split bound is split
// (rounds of longest-first bisection, until none is left), then collapse / flip / relocate passes run
// until nothing changes or they stop making progress, then the slivers left are repaired; never
// folding the mesh, keeping S, the interface curve, ridges, corners, boundaries
// and required entities. No operation creates a (near-)degenerate triangle (area ≤ 1e-10 of its
// squared edges, or a worst quality below min(1e-3, half the one it replaces)); a cap whose apex
// lies on its own feature edge is repaired by flipping that edge (the feature then runs through
// the apex). A ridge is detected only where S has a crease too (an evolving mesh's own sharp
// dihedral angles are not features of S).
#include <bodyfit/mesh.hpp>

#include <functional>
#include <memory>
#include <vector>

namespace bodyfit {

class ReferenceSurface;  // projection onto the fixed input surface S (projection.hpp)

struct RemeshOptions {
  // Sizes. 0 selects the default: the mesh's own resolution (a remesh keeps about as many faces;
  // refined only where the curvature needs it for hausd), so a unit sphere, a scan and a 50 km
  // landscape need no tuning. Callers that cut the mesh first (discretize, run) take it from the mesh
  // before the cut (resolution_length), since the cut's small edges are not a resolution.
  double hmin = 0;      ///< smallest edge length (default hmax / 20)
  double hmax = 0;      ///< largest edge length (default resolution_length(mesh), geometry.hpp)
  double hausd = 0;     ///< allowed distance to the true surface and interface (default D / 1000)
  /// Allowed distance to the interface curve alone (default hausd). An evolving front is cut and
  /// remeshed every step, and each remesh may move it by this much: a moving front wants a tighter
  /// bound than the surface's geometry does (docs/validation/remeshing.md, "The interface's tolerance").
  double hausd_interface = 0;
  double hgrad = 1.3;   ///< max ratio of target sizes between neighbouring vertices
  double feature_angle = 45;  ///< dihedral angle (degrees) above which an edge is a ridge, if S's normals
                              ///< across it differ as much; ≤ 0: none
  /// Safety cap on the collapse/flip/relocate passes; 0: none. The passes stop by themselves when
  /// nothing is left to do or when they stop making progress (RemeshReport::stop); a cap hit is
  /// reported as RemeshStop::PassLimit.
  int max_passes = 0;
  /// Only work where needed: elements far from the interface that already satisfy the sizing and
  /// quality criteria are left untouched (the cost follows the part that changes).
  bool incremental = true;
  /// With `incremental`: where the mesh may have changed since it was last remeshed with these
  /// options (its caller knows: an evolution marks what each step's cut changes). Only poor
  /// triangles and off-size edges with a vertex where it holds start the work; elsewhere the mesh
  /// is as the last remesh left it, and what that remesh could not improve is not tried again.
  /// Called from several threads at once. Empty (the default): anywhere.
  std::function<bool(VertexHandle)> changed;
  /// The fixed surface S onto which new and moved vertices are projected; when null the input
  /// mesh itself is used as reference.
  std::shared_ptr<const ReferenceSurface> reference;
  /// Keep every change within hausd of a reference made of triangles: a collapse, flip or move is
  /// refused when a point it removes from the mesh, or the middle of an edge it creates, would end
  /// farther than hausd from S (unless no farther than before). The sizes come from an estimate of
  /// S's curvature, which misses the creases of a faceted CAD part or a scan below the ridge angle;
  /// these checks keep the triangles from cutting across them. An analytic S, or one whose
  /// max_curvature() bends no chord of 2·hmax beyond hausd/2, needs none. A caller whose reference
  /// is a sampled height field rather than a shape may turn them off: following every lattice bump
  /// within hausd costs quality (docs/validation/real_meshes.md).
  bool check_distance_to_reference = true;
  /// After a remesh that changed the connectivity, renumber the mesh in spatial order
  /// (reorder_spatially) when it has become scattered in memory (spatial_disorder above 10 %);
  /// otherwise, and when false, only collect the garbage (collect_garbage).
  bool spatial_order = true;
};

/// Why the passes stopped.
enum class RemeshStop {
  Converged,  ///< a pass found nothing to split, collapse or flip and moved no vertex significantly
  Stalled,    ///< the passes kept working but made no progress (no new low of the work done per pass
              ///< for a few passes in a row: a local oscillation, e.g. of relocations)
  PassLimit,  ///< RemeshOptions::max_passes reached
};
const char* to_string(RemeshStop stop);

struct RemeshReport {
  std::size_t splits = 0, collapses = 0, flips = 0, relocations = 0;
  int split_rounds = 0;  ///< rounds of the first phase: every long edge split, longest first, until none is left
  int passes = 0;        ///< collapse/flip/relocate passes after it
  RemeshStop stop = RemeshStop::Converged;
  /// Edges still longer than the split bound (√2 × their target size) at the end: splits refused
  /// because they would fold or degenerate a triangle, or required edges. 0 in the normal case.
  std::size_t long_edges = 0;
  double max_edge_ratio = 0;  ///< longest edge / its target size
  double min_quality = 0, mean_quality = 0;
  /// Pairs of triangles that intersect at the end near what the remesh changed (a face around a
  /// vertex it queued or moved), looked for when the changes are held within hausd of a triangle
  /// reference (RemeshOptions::check_distance_to_reference: a CAD part, a scan), where triangles on
  /// the two sides of a sharp crease may cross; those found get the sliver repair's operations, and
  /// the ones left are counted here and warned about. 0 when not looked for.
  std::size_t self_intersections = 0;
  double milliseconds = 0;
};

/// Remesh in place; `mesh` is garbage-collected on return (and in spatial order when it was far from
/// it, see RemeshOptions::spatial_order).
RemeshReport remesh(SurfaceMesh& mesh, const RemeshOptions& options = {});

/// Garbage-collect `mesh` and renumber it in a spatially coherent order, so that neighbours are
/// close in memory: vertices along a Z-order (Morton) curve of their positions in the bounding box
/// (21 bits per axis, ties by index), then edges and faces by their smallest new vertex index (ties
/// by index). A permutation that keeps every element's properties and the connectivity; the same
/// result for any number of threads; a mesh already in this order is left as it is. Costs one sort
/// of the vertices, the rest is linear.
void reorder_spatially(SurfaceMesh& mesh);
/// The same with the vertex order given: spatial_vertex_order(mesh), found once for this and
/// spatial_disorder_after_reorder (the sort is most of the cost of either).
void reorder_spatially(SurfaceMesh& mesh, const std::vector<int>& order);
/// The live vertices (indices) in the order reorder_spatially gives them.
std::vector<int> spatial_vertex_order(const SurfaceMesh& mesh);

/// How scattered `mesh` is in memory: the share of its edges whose ends' indices differ by more than
/// 16 √(vertices) (a few rows of a well-ordered mesh, whatever the order: a generator's rows, a
/// height grid's, the Z-order), counting six per deleted vertex (the holes are filled from the end).
/// 1-5 % for a generated sphere or a Z-ordered mesh; it grows as remeshes append elements.
/// Linear, parallel.
double spatial_disorder(const SurfaceMesh& mesh);
/// spatial_disorder once reorder_spatially had run, found without moving anything (the Z-order and
/// one pass over the edges): ~1 % on a sphere, ~11 % on a surface much wider than high.
double spatial_disorder_after_reorder(const SurfaceMesh& mesh);
/// The same with the vertex order given (spatial_vertex_order(mesh)).
double spatial_disorder_after_reorder(const SurfaceMesh& mesh, const std::vector<int>& order);

/// Remove the deleted elements: the same arrays as OpenMesh's garbage_collection() (each hole, from
/// the first, takes the last live element), but only the handles that point to a moved element are
/// updated, so the cost follows the number of holes, not the size of the mesh.
void collect_garbage(SurfaceMesh& mesh);

/// Whether any vertex, edge or face of `mesh` is deleted (a parallel sweep over the status flags).
bool has_deleted_elements(const SurfaceMesh& mesh);

}  // namespace bodyfit
