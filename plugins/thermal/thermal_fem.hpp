#pragma once
// P1 finite elements on the tetrahedra of Ω for the thermal model of the paper (4.14, 4.18):
//
//   state    −div(γ∇u) = f in Ω,        γ∂u/∂n + κu = g_R on S \ Γ_N,   γ∂u/∂n = g on Γ_N,
//   adjoint  −div(γ∇p) = −j′(u) in Ω,   γ∂p/∂n + κp = 0   on S \ Γ_N,   γ∂p/∂n = 0 on Γ_N,
//
// with κ = c(F) a function of the P1 interpolant of a field F on S (for the model: F = d_G, the
// signed distance to G, and c = h_ε). Both problems have the matrix K_γ + R_κ: one factorisation (or
// one incomplete factorisation for the conjugate gradient) serves both.
// The adjoint is that of the problem's functional j(u) (objective.hpp; the mean temperature
// T = (1/|Ω|)∫_Ω u by default): dj = pᵀ(dA)u for any change dA of the matrix (shape_derivative.hpp).
//
// Matrices and vectors are indexed by volume vertex; surface fields by surface vertex (= the first
// VolumeMesh::n_surface_vertices volume vertices); face masks by surface face.
#include "linear_solver.hpp"
#include "objective.hpp"
#include "quadrature.hpp"
#include "volume_mesh.hpp"

#include <bodyfit/mesh.hpp>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <functional>
#include <memory>
#include <vector>

namespace bodyfit::thermal {

using SparseMatrix = Eigen::SparseMatrix<double>;
/// A function of position. An empty function means the documented default (a constant).
using SpatialFunction = std::function<double(const Vec3&)>;
/// A per-surface-face flag (Γ_N membership); an empty vector means no face is flagged.
using FaceMask = std::vector<char>;

// ---- assembly ------------------------------------------------------------------------------------

/// K_ij = ∫_Ω γ ∇φ_i·∇φ_j, γ evaluated at the tetrahedra's centroids (empty: γ ≡ 1). γ must be
/// positive and finite (InputError otherwise).
SparseMatrix assemble_stiffness(const VolumeMesh& mesh, const SpatialFunction& conductivity = {});
/// ∫_Ω φ_i, exactly (|tet|/4 to each of its vertices). Its sum is |Ω|.
Eigen::VectorXd assemble_volume_weights(const VolumeMesh& mesh);
/// ∫_Ω f φ_i with the 4-point rule of degree 2; an empty f is f ≡ 1 (then = the volume weights).
Eigen::VectorXd assemble_load(const VolumeMesh& mesh, const SpatialFunction& source = {});
/// R_ij = ∫_{∂Ω} c(F) φ_i φ_j over the boundary faces not in `skip`, F the P1 interpolant of the
/// surface field `field` (size n_surface_vertices), c evaluated at the points of `rule` (empty c:
/// the identity, κ = F). c(F) must be ≥ 0 and finite (InputError otherwise).
SparseMatrix assemble_robin(const VolumeMesh& mesh, const std::vector<double>& field,
                            const std::function<double(double)>& coefficient, const FaceMask& skip = {},
                            const TriangleQuadrature& rule = {});
/// ∫_{∂Ω} g φ_i over the boundary faces in `faces` (empty: all), g evaluated at the points of `rule`.
Eigen::VectorXd assemble_boundary_load(const VolumeMesh& mesh, const SpatialFunction& g, const FaceMask& faces = {},
                                       const TriangleQuadrature& rule = {});

// ---- the problem and its solution ----------------------------------------------------------------

struct ThermalProblem {
  SpatialFunction conductivity{};  ///< γ > 0, at tetrahedron centroids; empty: 1
  SpatialFunction source{};        ///< f; empty: 1
  /// κ = robin_coefficient(F), F the P1 field robin_field on S (size n_surface_vertices). The model
  /// uses F = d_G and robin_coefficient = [ε](double d) { return h_epsilon(d, ε); }.
  std::vector<double> robin_field{};
  std::function<double(double)> robin_coefficient{};  ///< empty: the identity (κ = F)
  SpatialFunction robin_source{};  ///< g_R on S \ Γ_N (γ∂u/∂n + κu = g_R); empty: 0 (the model's case)
  FaceMask neumann{};              ///< Γ_N, per surface face; empty: Γ_N = ∅
  SpatialFunction neumann_flux{};  ///< g on Γ_N; empty: 0
  ObjectiveSpec objective{};       ///< the functional j(u) whose adjoint is solved (mean temperature)
};

struct ThermalOptions {
  LinearSolverOptions linear{};     ///< IC-preconditioned conjugate gradient by default
  TriangleQuadrature quadrature{};  ///< for the Robin and boundary terms (shape_derivative.hpp uses the same)
  /// When j is the mean temperature, f ≡ 1 (source empty) and there is no boundary source
  /// (robin_source and neumann_flux empty or Γ_N = ∅), the adjoint right-hand side is −(1/|Ω|)
  /// times the state's, so p = −u/|Ω| exactly: skip the second solve. Off by default so that the
  /// general path is the tested one.
  bool adjoint_shortcut = false;
  /// Conjugate gradient only: start each solve of ThermalSolver from the previous one's u and p
  /// (the optimisation loop moves G a little per iteration).
  bool warm_start = true;
};

struct ThermalTimings {
  double setup_ms = 0;          ///< assembly of the terms that do not depend on the Robin field (once)
  double assembly_ms = 0;       ///< this solve: Robin matrix, K + R
  double analysis_ms = 0;       ///< symbolic analysis (0 when the pattern was reused)
  double factorization_ms = 0;  ///< numeric factorisation
  double solve_ms = 0;          ///< the state and adjoint solves (one call, two right-hand sides, when j is linear)
  int cg_iterations = 0;        ///< conjugate gradient only
};

struct ThermalSolution {
  Eigen::VectorXd u;              ///< temperature at every volume vertex
  Eigen::VectorXd p;              ///< adjoint at every volume vertex
  double volume = 0;              ///< |Ω|
  double mean_temperature = 0;    ///< T = (1/|Ω|)∫_Ω u (exact for the P1 u)
  double objective = 0;           ///< j(u), the problem's functional (= T for the mean temperature)
  ThermalTimings timings;
};

/// The state and adjoint solver of one mesh and one problem, for many Robin fields: the stiffness,
/// the loads and the symbolic factorisation are computed once. `mesh` must outlive the solver.
class ThermalSolver {
 public:
  /// Assembles the fixed terms. InputError for inconsistent sizes, a Γ_N covering all of S (then
  /// no Robin term can make the problem well posed), non-positive γ.
  ThermalSolver(const VolumeMesh& mesh, ThermalProblem problem, const ThermalOptions& options = {});
  ~ThermalSolver();
  ThermalSolver(ThermalSolver&&) noexcept;
  ThermalSolver& operator=(ThermalSolver&&) noexcept;

  /// Solve with the problem's Robin field.
  ThermalSolution solve();
  /// Solve with another Robin field (e.g. the distance to a new G): only the Robin matrix is
  /// assembled again, and the factorisation reuses the symbolic analysis. InputError when κ
  /// vanishes on all of S \ Γ_N (the system is singular), before factorising.
  ThermalSolution solve(const std::vector<double>& robin_field);

  const VolumeMesh& mesh() const;
  const ThermalProblem& problem() const;
  const ThermalOptions& options() const;
  double setup_ms() const;
  /// The linear solver's statistics after the last solve (fill and flops of the factor, ordering).
  const LinearSolverStats& linear_stats() const;
  /// The conjugate gradient's warm start: the last solution [u p] (empty before the first solve),
  /// and setting it (a resumed run restores it, so that its solves start where the run's did).
  const Eigen::MatrixXd& warm_start() const;
  void set_warm_start(Eigen::MatrixXd guess);
  /// Replace κ's function of the Robin field (a new ε): the next solve uses it.
  void set_robin_coefficient(std::function<double(double)> coefficient);
  /// The functional j of the problem's objective on this mesh.
  const TemperatureFunctional& functional() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One-shot: ThermalSolver(mesh, problem, options).solve().
ThermalSolution solve_thermal(const VolumeMesh& mesh, const ThermalProblem& problem,
                              const ThermalOptions& options = {});

}  // namespace bodyfit::thermal
