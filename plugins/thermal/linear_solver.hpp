#pragma once
// Sparse symmetric positive definite solves: factor once, solve many right-hand sides; factor again
// a matrix with the same pattern (a new Robin coefficient) without redoing the symbolic analysis.
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <string_view>

namespace bodyfit::thermal {

enum class LinearSolver {
  cholmod_supernodal,  ///< CHOLMOD supernodal LLᵀ (BLAS-3 on dense blocks; GPL module)
  cholmod_simplicial,  ///< CHOLMOD simplicial LDLᵀ (no BLAS; LGPL module)
  eigen_simplicial,    ///< Eigen's SimplicialLDLT with AMD (permissive licence)
  conjugate_gradient,  ///< Eigen's ConjugateGradient with an IncompleteCholesky preconditioner
};

/// "cholmod_supernodal", "cholmod_simplicial", "eigen_simplicial", "conjugate_gradient".
std::string_view to_string(LinearSolver solver);
/// The inverse of to_string; InputError listing the valid names otherwise.
LinearSolver linear_solver_from_string(std::string_view name);

struct LinearSolverOptions {
  /// The conjugate gradient: per solve of the optimisation loop (state + adjoint), 1.4-2.2× faster
  /// than CHOLMOD's supernodal factorisation with OpenBLAS from 17k to 290k tetrahedra, 3.3× for the
  /// first solve at 290k, on one core each (docs/validation/thermal_solvers.md).
  LinearSolver solver = LinearSolver::conjugate_gradient;
  double cg_tolerance = 1e-10;  ///< conjugate gradient: relative residual |b − Ax|/|b|
  int cg_max_iterations = 0;    ///< conjugate gradient: 0 = the matrix size
  /// Conjugate gradient: when its preconditioner fails or it does not converge, warn and use
  /// CHOLMOD's supernodal factorisation from then on (else: InputError).
  bool fallback_to_cholmod = true;
};

struct LinearSolverStats {
  double analysis_ms = 0;       ///< last symbolic analysis (ordering), 0 when reused
  double factorization_ms = 0;  ///< last numeric factorisation (IC preconditioner for the CG)
  double solve_ms = 0;          ///< last solve call (all its right-hand sides)
  int analyses = 0;             ///< symbolic analyses done so far
  int cg_iterations = 0;        ///< last solve, largest over its right-hand sides
  double cg_error = 0;          ///< last solve, Eigen's estimate of the relative residual
  double factor_nonzeros = 0;   ///< CHOLMOD: nonzeros of L from the last analysis (0 otherwise)
  double factor_flops = 0;      ///< CHOLMOD: flops of one factorisation from the last analysis
  std::string_view ordering;    ///< CHOLMOD: the fill-reducing ordering it chose ("amd", "metis", …)
  bool fell_back = false;       ///< the conjugate gradient failed and CHOLMOD took over
};

class SymmetricSolver {
 public:
  explicit SymmetricSolver(const LinearSolverOptions& options = {});
  ~SymmetricSolver();
  SymmetricSolver(SymmetricSolver&&) noexcept;
  SymmetricSolver& operator=(SymmetricSolver&&) noexcept;

  /// Factor the symmetric positive definite `matrix` (both triangles stored). The symbolic
  /// analysis is redone only when the sparsity pattern differs from the previous call's. Throws
  /// InputError when the factorisation fails (the matrix is not positive definite).
  void factorize(const Eigen::SparseMatrix<double>& matrix);
  /// Solve for every column of `rhs` (one call: CHOLMOD solves them together).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs);
  /// The same, starting the conjugate gradient from `guess` (same shape as rhs; the direct solvers
  /// ignore it). The optimisation loop's previous solution is a good guess.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs, const Eigen::MatrixXd& guess);

  /// The options in force (the solver changes when the conjugate gradient falls back).
  const LinearSolverOptions& options() const;
  const LinearSolverStats& stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace bodyfit::thermal
