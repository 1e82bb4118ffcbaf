#pragma once
// Where the fast marching starts (distance.cpp): the interface segments in the faces it crosses,
// from the zero set of a P1 level set or from the edges between two regions (optionally curved).
#include "distance_mesh.hpp"

#include <utility>
#include <vector>

namespace bodyfit::distance_detail {

/// What the initialisation needs: the sign of each vertex (−1, 0, +1) and, for every face touched
/// by the interface, the interface segments inside it.
struct Seeds {
  std::vector<signed char> sign;
  std::vector<int> zeros;                       // the vertices on the zero set (sign 0)
  std::vector<int> faces;                       // seed faces
  std::vector<int> seg_start;                   // per seed face, into segments (CSR)
  std::vector<std::pair<Vec3, Vec3>> segments;  // a point is a segment with equal ends
  std::vector<std::pair<Vec3, Vec3>> bends;     // empty, or per segment the curvature vectors at its ends
};

/// The zero set of φ in face f, appended to s as one seed face when φ vanishes there.
void add_phi_seed(const FlatMesh& m, const ScalarField& phi, int f, Seeds& s);
/// The zero set of the P1 level set φ.
Seeds seeds_from_phi(const FlatMesh& m, const ScalarField& phi);
/// The interface edges between the regions of `mesh`; with `curved`, each segment bends with the
/// interface curve's curvature at its ends (Seeds::bends).
Seeds seeds_from_region(const SurfaceMesh& mesh, const FlatMesh& m, bool curved);

}  // namespace bodyfit::distance_detail
