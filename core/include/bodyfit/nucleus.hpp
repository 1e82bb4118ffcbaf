#pragma once
// A new component of G that a step creates where no front is (VelocityModel::nuclei): a level set
// advected along characteristics only moves the fronts it has, so a model that wants a new
// component (topological nucleation) names it, and the driver adds it to φ^{n+1} before the cut.
#include <bodyfit/mesh.hpp>

namespace bodyfit {

/// The geodesic disk of `radius` around vertex `vertex` of T^n.
struct Nucleus {
  int vertex = -1;
  double radius = 0;
};

/// ψ with ψ < 0 exactly on the nucleus's disk: |x − x_c| − ρ at the vertices reached from the
/// centre along edges within 2ρ + 2 edges (the sheet of S the centre lies on, never a facing one
/// across a thin wall), +∞ elsewhere. φ ← min(φ, ψ) adds the disk to G. InputError when the vertex
/// is not one of the mesh's or the radius is not positive and finite.
ScalarField nucleus_level_set(const SurfaceMesh& mesh, const Nucleus& nucleus);

}  // namespace bodyfit
