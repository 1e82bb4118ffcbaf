#pragma once
// Cutting the zero level set of a P1 function into the mesh (first half of step 4 of Algorithm 1,
// paper §3.4): afterwards the interface is a chain of mesh edges tagged e:interface (ref 10), the
// faces are labelled kInside (φ < 0) or kOutside, and v:phi holds φ (0 on the interface).
// The result is conforming but may contain thin triangles: remesh() comes next.
#include <bodyfit/mesh.hpp>

namespace bodyfit {

struct DiscretizeOptions {
  /// A vertex whose |φ| is below snap_ratio × (length of an edge it shares with a crossing) is
  /// moved onto the level set (φ set to 0) instead of inserting a point next to it.
  double snap_ratio = 0.05;
};

struct DiscretizeReport {
  std::size_t crossed_edges = 0;
  std::size_t inserted_vertices = 0;
  std::size_t snapped_vertices = 0;
  std::size_t split_faces = 0;
};

/// Cut the zero level set of `phi` (one value per vertex) into `mesh` (garbage-collected on return).
DiscretizeReport discretize(SurfaceMesh& mesh, const ScalarField& phi, const DiscretizeOptions& options = {});

}  // namespace bodyfit
