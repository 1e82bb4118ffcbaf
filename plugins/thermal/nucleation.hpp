#pragma once
// Topological nucleation: what creating a new component of G — a small disk D_ρ(x) of S \ G held
// at u = 0 — does to J, and where to create one.
//
// The disk draws heat from the part. Seen from the disk, the part is the half-space under S's
// tangent plane, insulated except on the disk: the field u(x)(1 − w) with w the potential of a disk
// held at 1 in free space, whose capacity is 8ρ, half of which leaves through each side. So the
// disk draws Q = 4γ(x)ρ u(x), and the adjoint p weighs that heat in J (dJ = ∫ δβ u p for a Robin
// coefficient β added on S, taken to the limit of a Dirichlet disk):
//
//   J(G ∪ D_ρ(x)) − J(G) = 4 γ(x) ρ u(x) p(x) + O(ρ²)          (x ∈ S \ G, away from Σ and edges)
//
// For the mean temperature p = −u/|Ω|: every point lowers J, most where the part is hottest. The
// O(ρ²) term is the disk's interaction with the rest of G (it shields itself: the realised change
// is below the first-order one, by ~ρ/L relative). docs/reference/thermal_model.md has the
// derivation and its check against inserted disks.
#include "box_field.hpp"

#include <bodyfit/mesh.hpp>

#include <vector>

namespace bodyfit::thermal {

/// g(x) = 4γ(x) u(x) p(x) at the vertices: J's change per unit radius of a new disk at x.
std::vector<double> topological_sensitivity(const SurfaceMesh& mesh, const std::vector<double>& u,
                                            const std::vector<double>& p, const BoxField& conductivity);

struct NucleationOptions {
  double radius = 0;     ///< ρ of each new disk
  double clearance = 0;  ///< kept between a new disk and G, Γ_N and the other new disks
  int count = 1;         ///< disks at most
};

/// The centres of up to `count` new disks: the vertices of most negative g whose disk keeps the
/// clearance from G (d > radius + clearance), from the vertices flagged in `excluded` (Γ_N) and
/// from one another; none where g ≥ 0 (no disk lowers J there).
std::vector<int> nucleation_sites(const SurfaceMesh& mesh, const std::vector<double>& distance,
                                  const std::vector<double>& sensitivity, const std::vector<char>& excluded,
                                  const NucleationOptions& options);

}  // namespace bodyfit::thermal
