// The halfedge connectivity of a triangle mesh built from its corners in a few array passes.
#pragma once

#include <bodyfit/mesh.hpp>

#include <array>
#include <cstdint>
#include <span>

namespace bodyfit {

/// Gives `mesh` (its vertices added, no edges or faces yet) the triangles `corners` (0-based vertex
/// indices, each triangle three distinct valid vertices), in one pass over arrays rather than one
/// `add_face` per triangle. The connectivity is the one `add_face` in triangle order would leave,
/// array for array: edges numbered by first use, each edge's first halfedge in the direction of the
/// triangle that used it first, a face's halfedge its third side, a vertex's halfedge its boundary
/// halfedge or else its side in its last triangle. Face properties other than connectivity are
/// left default (a face's region is the caller's).
///
/// Returns false and leaves `mesh` untouched when the triangles are not a manifold surface with a
/// consistent orientation (an edge used twice in one direction or by three triangles, a triangle
/// repeated, a vertex whose triangles form more than one fan): `add_face`, triangle by triangle,
/// then says which one is wrong.
bool build_connectivity(SurfaceMesh& mesh, std::span<const std::array<std::int64_t, 3>> corners);

}  // namespace bodyfit
