#pragma once
// Interface-preserving adaptive remeshing of a surface mesh (second half of step 4 of Algorithm 1,
// paper §3.4): split / collapse / flip / relocate until sizes and qualities settle, then repair the
// slivers left, never folding the mesh, keeping S, the interface curve, ridges, corners, boundaries
// and required entities. No operation creates a (near-)degenerate triangle (area ≤ 1e-10 of its
// squared edges, or a worst quality below min(1e-3, half the one it replaces)); a cap whose apex
// lies on its own feature edge is repaired by flipping that edge (the feature then runs through
// the apex). A ridge is detected only where S has a crease too (an evolving mesh's own sharp
// dihedral angles are not features of S).
#include <bodyfit/mesh.hpp>

#include <memory>

namespace bodyfit {

class ReferenceSurface;  // projection onto the fixed input surface S (projection.hpp)

struct RemeshOptions {
  // Sizes. 0 selects the default, relative to the bounding-box diagonal D of the mesh, so a unit
  // sphere and a 50 km terrain need no tuning.
  double hmin = 0;      ///< smallest edge length (default hmax / 20)
  double hmax = 0;      ///< largest edge length (default D / 20)
  double hausd = 0;     ///< allowed distance to the true surface and interface (default D / 1000)
  double hgrad = 1.3;   ///< max ratio of target sizes between neighbouring vertices
  double feature_angle = 45;  ///< dihedral angle (degrees) above which an edge is a ridge, if S's normals
                              ///< across it differ as much; ≤ 0: none
  int max_passes = 10;  ///< outer split/collapse/flip/relocate passes
  /// Only work where needed: elements far from the interface that already satisfy the sizing and
  /// quality criteria are left untouched (the cost follows the part that changes).
  bool incremental = true;
  /// The fixed surface S onto which new and moved vertices are projected; when null the input
  /// mesh itself is used as reference.
  std::shared_ptr<const ReferenceSurface> reference;
};

struct RemeshReport {
  std::size_t splits = 0, collapses = 0, flips = 0, relocations = 0;
  int passes = 0;
  double min_quality = 0, mean_quality = 0;
  double milliseconds = 0;
};

/// Remesh in place; `mesh` is garbage-collected on return.
RemeshReport remesh(SurfaceMesh& mesh, const RemeshOptions& options = {});

}  // namespace bodyfit
