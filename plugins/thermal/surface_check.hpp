#pragma once
// Is a triangulated surface the skin of a solid? The checks TetGen needs to succeed (and that it
// would otherwise report by an exception, a wrong mesh, or an assertion that aborts the process):
// no deleted elements, every vertex used, no degenerate or duplicate vertex, closed, manifold,
// outward orientation (positive enclosed volume), no self-intersection.
#include <bodyfit/mesh.hpp>
#include <bodyfit/self_intersections.hpp>

#include <utility>
#include <vector>

namespace bodyfit::thermal {

struct SurfaceCheckOptions {
  bool self_intersections = true;  ///< the only check that is not linear in the size (still ≈ O(n))
};

/// Throws InputError naming the first violated property, e.g. "the surface is not closed
/// (12 boundary edges): the thermal model needs the skin of a solid". `what` prefixes the message.
void check_solid_surface(const SurfaceMesh& surface, const SurfaceCheckOptions& options = {},
                         const char* what = "thermal model");

/// Volume enclosed by a closed surface (divergence theorem): positive for an outward orientation.
double enclosed_volume(const SurfaceMesh& surface);

}  // namespace bodyfit::thermal
