#pragma once
// The paper's sharp problem (4.12) on the body-fitted volume mesh: the part is held at u = 0 on G
// itself, not through the smoothed Robin term h_ε(d_G) of (4.14):
//
//   −div(γ∇u) = f in Ω,   u = 0 on G,   γ∂u/∂n = g on Γ_N,   γ∂u/∂n = 0 on the rest of S,
//
// and T(G) = (1/|Ω|)∫_Ω u (or the problem's functional j(u), objective.hpp), the objective T_ε approximates (T_ε → T as ε → 0). The volume mesh
// keeps S's faces, so G is a set of its boundary faces and the condition is imposed exactly at
// their vertices.
#include "thermal_fem.hpp"

namespace bodyfit::thermal {

struct SharpSolution {
  Eigen::VectorXd u;            ///< at every volume vertex (0 at G's)
  double volume = 0;            ///< |Ω|
  double mean_temperature = 0;  ///< T(G)
  double objective = 0;         ///< j(u) of the problem's objective (= T(G) for the mean temperature)
  double ms = 0;                ///< assembly and solve
};

/// The sharp problem with `problem`'s conductivity, source and Neumann data (its Robin terms are not
/// used); `dirichlet` flags G's faces (per surface face). InputError when G has no face (the pure
/// Neumann problem has no solution for a source), or when it flags a face of Γ_N.
SharpSolution solve_sharp(const VolumeMesh& mesh, const ThermalProblem& problem, const FaceMask& dirichlet,
                          const LinearSolverOptions& linear = {});

}  // namespace bodyfit::thermal
