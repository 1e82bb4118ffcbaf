#pragma once
// Whether a surface is a height field: the graph of a function over a plane (a landscape z(x, y), a
// shallow cap), which no two of its faces can cross.
#include <bodyfit/mesh.hpp>

namespace bodyfit {

/// Whether `mesh` is a height field over the plane normal to its mean normal d (the faces' normals
/// summed by area): every face facing d (its normal within 84° of it), and the surface's boundary
/// one loop whose shadow on that plane is a simple polygon. Then the projection along d is one to
/// one (each point of the plane has as many points of the surface over it as the shadow of the
/// boundary winds around it, at most one), so faces that share no vertex lie over disjoint parts of
/// the plane and no two faces cross. False when it cannot tell: a closed surface, several
/// boundaries, a face seen edge-on or from behind, a shadow of the boundary that touches itself
/// within 1e-9 of its size. One sweep over the faces and one over the boundary.
bool is_height_field(const SurfaceMesh& mesh);

}  // namespace bodyfit
