#pragma once
// The objective J_ε(G) = j(u_ε) + ℓ|G| (the paper's (4.13) for j = T, the mean temperature) and its
// shape derivative in band form:
//
//   J′_ε(G)(θ) = ∫_S w (θ·n_Σ)∘π_Σ ds + ℓ ∫_Σ θ·n_Σ dℓ,    w = −(1/ε²) h′(d_G/ε) u p,
//
// u, p the state and adjoint of thermal_fem.hpp with κ = h_ε(d_G), d_G the signed distance to G on S
// (negative inside), π_Σ the projection onto Σ = ∂G. Derivation (docs/validation/thermal_solvers.md): only
// h_ε depends on G in the Lagrangian, and d_G′(θ) = −(θ·n_Σ)∘π_Σ. w ≤ 0 (h′ ≤ 0, u > 0, p < 0 for
// f ≥ 0): growing G lowers T. The paper's printed (4.17) has the opposite sign and one more 1/ε.
//
// The velocity regularisation (H¹ on S) is not here: the core's H1Smoother does it.
#include "quadrature.hpp"
#include "thermal_fem.hpp"

#include <bodyfit/mesh.hpp>

#include <Eigen/Core>

#include <vector>

namespace bodyfit::thermal {

struct ObjectiveOptions {
  double epsilon = 0;  ///< ε > 0 of h_ε (a length; required, InputError otherwise)
  double ell = 0;      ///< ℓ ≥ 0, the weight of the area of G
  /// Must be the quadrature of the solve (ThermalOptions::quadrature) for band_derivative to be the
  /// exact derivative of the discrete J.
  TriangleQuadrature quadrature{};
  FaceMask neumann{};  ///< Γ_N (no Robin term there), per surface face; empty: Γ_N = ∅
};

struct ThermalObjective {
  double J = 0;     ///< j + ℓ·area
  double j = 0;     ///< the functional j(u) (objective.hpp; T for the mean temperature)
  double T = 0;     ///< mean temperature (1/|Ω|)∫_Ω u
  double area = 0;  ///< |G|: area of the faces labelled inside
  /// w at the surface vertices: −(1/ε²) h′(d/ε) u p (0 on vertices whose faces are all in Γ_N).
  std::vector<double> density;
};

/// J_ε, T_ε, |G| and the shape-gradient density w at the vertices of `surface` (the skin the
/// solution was computed on). `distance` is d_G at the surface vertices.
ThermalObjective thermal_objective(const SurfaceMesh& surface, const std::vector<double>& distance,
                                   const ThermalSolution& solution, const ObjectiveOptions& options);

/// w_i = −(1/ε²) h′(d_i/ε) u_i p_i for the first distance.size() entries of u and p.
std::vector<double> shape_gradient_density(const std::vector<double>& distance, const Eigen::VectorXd& u,
                                           const Eigen::VectorXd& p, double epsilon);

/// The derivative of the discrete T_ε when d_G moves to d_G + δ·s (s a P1 field on S):
///   dT/dδ = ∫_{S\Γ_N} (dh_ε/dd)(d) s u p ds  = pᵀ (dR/dδ) u,
/// integrated with the quadrature of the Robin assembly, so it is exact for the discrete problem
/// (G's labels, hence ℓ|G|, do not change with d). For s = −(θ·n_Σ)∘π_Σ this is ∫_S w (θ·n_Σ)∘π_Σ.
double band_derivative(const SurfaceMesh& surface, const std::vector<double>& distance,
                       const std::vector<double>& s, const ThermalSolution& solution, const ObjectiveOptions& options);

/// b_Σ = ∫_Σ φ_i dℓ: half of each interface edge's length to each of its ends (the load of
/// ∫_Σ θ·n, the derivative of |G|).
Eigen::VectorXd interface_length_load(const SurfaceMesh& surface);

/// π_Σ, the closest point of Σ's edges, at the vertices within `reach` of Σ: the two ends of the
/// closest interface edge and the parameter t of the point along it (from `from` to `to`); `from`
/// is −1 at the vertices beyond reach, and everywhere when S has no interface.
struct InterfaceProjection {
  std::vector<int> from, to;
  std::vector<double> t;
};
InterfaceProjection project_onto_interface(const SurfaceMesh& surface, double reach);
/// The same for any points (those of another mesh of S): `from` and `to` index surface's vertices.
InterfaceProjection project_onto_interface(const SurfaceMesh& surface, const std::vector<Vec3>& points, double reach);

/// W_k = ∫_{S\Γ_N} (dh_ε/dd)(d) u p φ_k with the quadrature of the Robin assembly: the gradient of
/// the discrete T_ε with respect to d at the vertices, band_derivative(s) = Σ_k W_k s_k. −W_k is the
/// vertex's share of ∫ w (W_k ≈ −m_k w_k with the lumped mass m_k).
std::vector<double> band_weights(const SurfaceMesh& surface, const std::vector<double>& distance,
                                 const ThermalSolution& solution, const ObjectiveOptions& options);

/// The band's derivative carried onto Σ along the normals: b_i = −Σ_k W_k φ_i(π_Σ(x_k)). Then bᵀv is
/// the derivative of the discrete T_ε when d moves by −v∘π_Σ at the vertices — what a step of the
/// pipeline does: it redistances from the moved Σ, so d moves by −v∘π_Σ, not by −v at each point of
/// the band (the two differ wherever v varies across the band). InputError when W ≠ 0 at a vertex
/// beyond the projection's reach (the reach must exceed the band's ε).
/// `n_vertices`: the vertices of the surface whose Σ the projection is onto (the load's size).
Eigen::VectorXd projected_band_load(const InterfaceProjection& projection, const std::vector<double>& weights,
                                    std::size_t n_vertices);

/// v∘π_Σ at the projected vertices, v elsewhere: the normal speed constant along Σ's normals, so
/// that a step moves each point of Σ by its own v·Δt (a semi-Lagrangian step samples the speed
/// at the front's new position, off Σ, where an H¹ speed with a line load has a kink).
std::vector<double> extend_from_interface(const InterfaceProjection& projection, const std::vector<double>& v);

}  // namespace bodyfit::thermal
