#pragma once
// Cutting the zero level set of a P1 function into the mesh (first half of step 4 of Algorithm 1,
// paper §3.4): afterwards the interface is a chain of mesh edges tagged e:interface (ref 10), the
// faces are labelled kInside (φ < 0) or kOutside, and v:phi holds φ (0 on the interface).
// The result is conforming but may contain thin triangles: remesh() comes next.
// docs/reference/levelset_mesher.md describes the cutting patterns, the snapping rule and the degenerate cases.
#include <bodyfit/mesh.hpp>

#include <span>

namespace bodyfit {

struct DiscretizeOptions {
  /// Snapping: where the zero of φ on an edge (v, w) lies closer to v than snap_ratio × |vw|
  /// (i.e. |φ(v)| / (|φ(v)| + |φ(w)|) < snap_ratio), v itself is put on the level set (φ(v) = 0,
  /// the vertex does not move) instead of inserting a point next to it, which would leave a sliver.
  /// A snap that would make the interface touch itself at a vertex is not done. 0 disables snapping.
  /// The default, shared by `bodyfit discretize` and `run`, moves the interface by at most 1e-3 of
  /// an edge: the remesher opens the slivers a near-vertex cut leaves (mmgs -ls snaps more).
  double snap_ratio = 1e-3;
  /// The same rule for the vertices the remesher cannot move (on the boundary, on a ridge or a
  /// required edge, corners, required vertices), with the larger of the two ratios: a cut passing
  /// next to such a vertex leaves a sliver that no relocation can open, whereas a free vertex is
  /// moved away by the remesher. This is what keeps the interface clean where a front meets the
  /// boundary when snap_ratio is 0 (as in evolutions).
  double fixed_snap_ratio = 0.05;
  /// Where a crossed edge is cut. true: at the zero of the cubic Hermite interpolant of φ along the
  /// edge, whose end slopes come from the vertex gradients of φ (vertex_gradient): φ is a smooth
  /// function sampled at the vertices, and the linear zero is off the true level set by
  /// ≈ h²|φ''|/(8|φ'|) where the interface is curved. The cubic zero is used only when it lies within
  /// a quarter edge of the linear one, the slopes agree in sign with φ(b) − φ(a), and it stays inside
  /// the edge; otherwise, and when false, the zero of the linear interpolant (the paper's and
  /// mmgs's rule; exact for φ affine along the edge, where both agree).
  bool hermite_crossings = true;
  /// The Hermite slopes: true = the gradient of a least-squares quadratic through φ on the two
  /// rings of each vertex (second order on any mesh); false = the averaged face gradients
  /// (vertex_gradient), first order on an irregular mesh, whose scatter of the cut points was
  /// turned into a steady loss of area by the remesher (docs/validation/drift.md).
  bool fitted_slopes = true;
  /// With fitted_slopes, the quadratic is trusted where it describes φ on the two rings: its
  /// weighted RMS residual at most this fraction of the fitted slope times the rings' mean radius.
  /// Above it φ has a kink within the rings (a distance's ridge: the middle of a part or a gap a
  /// few edges wide, a corner of the front) and the vertex takes the averaged face gradient.
  double fit_residual_limit = 0.05;
  /// Specks: a connected part of either region whose area is below speck_area·h² (h the mean edge
  /// length of the input mesh) is given to the region around it, so its interface disappears.
  /// Such a part is below what the mesh resolves (a noise-born island of φ a fraction of one
  /// triangle across) and, as the remesher never changes the topology of the regions, it would pin
  /// a cluster of poor triangles. 0 keeps every part. The search grows parts from the interface and
  /// stops at this area, so it costs in proportion to the interface; a whole component of S lying
  /// in one region has no interface and is never a speck.
  double speck_area = 0.1;
  /// Parts cut off the old region. With `grown_from` (the signed distance d^n to the region the
  /// new one grows from, at the input's vertices; empty: off), a part of the inside region none of
  /// whose faces has a corner where d^n ≤ 0 does not meet the old region, and is given to the
  /// outside whatever its size. A front that only grows from itself (no new source ahead of it)
  /// cannot leave such a part: it is the tip of a tongue cut off its neck between two vertices.
  /// The search grows the inside parts from the interface and stops at the first face that meets
  /// the old region, so it costs in proportion to the region gained.
  std::span<const double> grown_from{};
  /// In an evolution: fill `grown_from` with d^n at every step's cut (`[discretize] drop_detached`).
  bool drop_detached = false;
};

struct DiscretizeReport {
  std::size_t crossed_edges = 0;      ///< edges where φ changes sign strictly (after snapping)
  std::size_t inserted_vertices = 0;  ///< one per crossed edge
  std::size_t snapped_vertices = 0;   ///< vertices whose φ was set to 0
  std::size_t rejected_snaps = 0;     ///< snaps refused because they would pinch the interface
  std::size_t split_faces = 0;        ///< input faces cut into 2 or 3 triangles
  std::size_t flipped_diagonals = 0;  ///< quads (2-crossing pattern) where the other diagonal was better
  std::size_t interface_edges = 0;    ///< edges tagged e:interface on return
  std::size_t inside_faces = 0;       ///< faces labelled kInside on return
  std::size_t removed_detached = 0;   ///< inside parts that did not meet the old region (grown_from)
  /// Vertices where the input φ is exactly 0 but the inside region would touch itself (a saddle
  /// of φ at the vertex, or inside parts meeting at a boundary vertex): they are put on the
  /// outside (φ set to a small positive value) and the cut passes next to them.
  std::size_t separated_vertices = 0;
  /// Vertices where the interface is still not a simple curve on return (interface-degree other
  /// than 0 or 2, or more than 1 on the boundary). Always 0; kept as a self-check.
  std::size_t pinched_vertices = 0;
  std::size_t removed_specks = 0;     ///< parts of a region given to the region around them (speck_area)
  /// Hermite slopes taken from the quadratic fit, and those that fell back to the averaged face
  /// gradient (too few neighbours, an ill-conditioned fit, or a residual above fit_residual_limit).
  std::size_t fitted_slopes = 0;
  std::size_t refused_fits = 0;
};

/// Cut the zero level set of `phi` (one value per vertex index) into `mesh`. Previous interface
/// tags and region labels are replaced; ridge, required, corner and boundary tags are kept (the
/// two halves of a split edge inherit them) and every face keeps its orientation. `mesh` is
/// garbage-collected on return. Throws InputError when phi has the wrong size or is not finite.
DiscretizeReport discretize(SurfaceMesh& mesh, const ScalarField& phi, const DiscretizeOptions& options = {});

}  // namespace bodyfit
