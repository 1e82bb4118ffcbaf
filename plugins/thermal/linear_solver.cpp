#include "linear_solver.hpp"

#include <bodyfit/error.hpp>

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

namespace bodyfit::thermal {

namespace {

using Sparse = Eigen::SparseMatrix<double>;
using Supernodal = Eigen::CholmodSupernodalLLT<Sparse, Eigen::Lower>;
using Simplicial = Eigen::CholmodSimplicialLDLT<Sparse, Eigen::Lower>;
using EigenLDLT = Eigen::SimplicialLDLT<Sparse, Eigen::Lower, Eigen::AMDOrdering<int>>;
using CG = Eigen::ConjugateGradient<Sparse, Eigen::Lower | Eigen::Upper,
                                    Eigen::IncompleteCholesky<double, Eigen::Lower, Eigen::AMDOrdering<int>>>;

constexpr std::array<std::pair<LinearSolver, std::string_view>, 4> kNames{{
    {LinearSolver::cholmod_supernodal, "cholmod_supernodal"},
    {LinearSolver::cholmod_simplicial, "cholmod_simplicial"},
    {LinearSolver::eigen_simplicial, "eigen_simplicial"},
    {LinearSolver::conjugate_gradient, "conjugate_gradient"},
}};

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

std::string_view ordering_name(int ordering) {
  switch (ordering) {
    case CHOLMOD_NATURAL: return "natural";
    case CHOLMOD_GIVEN: return "given";
    case CHOLMOD_AMD: return "amd";
    case CHOLMOD_METIS: return "metis";
    case CHOLMOD_NESDIS: return "nesdis";
    case CHOLMOD_COLAMD: return "colamd";
    default: return "other";
  }
}

bool same_pattern(const Sparse& a, const std::vector<int>& outer, const std::vector<int>& inner) {
  if (std::size_t(a.outerSize() + 1) != outer.size() || std::size_t(a.nonZeros()) != inner.size()) return false;
  return std::equal(outer.begin(), outer.end(), a.outerIndexPtr()) &&
         std::equal(inner.begin(), inner.end(), a.innerIndexPtr());
}

}  // namespace

std::string_view to_string(LinearSolver solver) {
  for (const auto& [value, name] : kNames)
    if (value == solver) return name;
  return "unknown";
}

LinearSolver linear_solver_from_string(std::string_view name) {
  for (const auto& [value, known] : kNames)
    if (known == name) return value;
  throw InputError(fmt::format("unknown linear solver '{}' (expected cholmod_supernodal, cholmod_simplicial, "
                               "eigen_simplicial or conjugate_gradient)",
                               name));
}

struct SymmetricSolver::Impl {
  LinearSolverOptions options;
  LinearSolverStats stats;
  // The Eigen/CHOLMOD objects are neither copyable nor movable: held by pointer.
  std::variant<std::monostate, std::unique_ptr<Supernodal>, std::unique_ptr<Simplicial>, std::unique_ptr<EigenLDLT>,
               std::unique_ptr<CG>>
      solver;
  std::vector<int> outer, inner;  // pattern of the last analysed matrix
  Sparse matrix;                  // the last matrix: the CG multiplies by it, a fallback factors it
  bool factored = false;

  /// Factor `matrix` with the current solver (analysing its pattern first when asked).
  void factor(bool analyse) {
    switch (options.solver) {
      case LinearSolver::cholmod_supernodal: run(get<Supernodal>(analyse), matrix, analyse); break;
      case LinearSolver::cholmod_simplicial: run(get<Simplicial>(analyse), matrix, analyse); break;
      case LinearSolver::eigen_simplicial: run(get<EigenLDLT>(analyse), matrix, analyse); break;
      case LinearSolver::conjugate_gradient: {
        auto& cg = get<CG>(analyse);
        cg.setTolerance(options.cg_tolerance);
        cg.setMaxIterations(options.cg_max_iterations > 0 ? options.cg_max_iterations : int(matrix.rows()));
        run(cg, matrix, analyse);  // the IC preconditioner is the "factorisation"
        break;
      }
    }
  }

  /// The conjugate gradient failed: CHOLMOD's supernodal factorisation from now on.
  void fall_back(const std::string& why) {
    spdlog::warn("{}: falling back to CHOLMOD's supernodal factorisation", why);
    options.solver = LinearSolver::cholmod_supernodal;
    stats.fell_back = true;
    factor(true);
  }

  /// The solver of type S, created (and then to be analysed) when the current one is another.
  template <class S>
  S& get(bool& analyse) {
    if (!std::holds_alternative<std::unique_ptr<S>>(solver)) solver = std::make_unique<S>(), analyse = true;
    return *std::get<std::unique_ptr<S>>(solver);
  }

  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs, const Eigen::MatrixXd& guess) {
    bool warm = guess.rows() == rhs.rows() && guess.cols() == rhs.cols();
    Eigen::MatrixXd x;
    stats.cg_iterations = 0;
    stats.cg_error = 0;
    std::visit(
        [&](auto& s) {
          using T = std::decay_t<decltype(s)>;
          if constexpr (std::is_same_v<T, std::monostate>) {
            throw std::logic_error("SymmetricSolver: no solver");
          } else if constexpr (std::is_same_v<T, std::unique_ptr<CG>>) {
            // Column by column, to report the worst convergence.
            x.resize(rhs.rows(), rhs.cols());
            for (Eigen::Index c = 0; c < rhs.cols(); ++c) {
              x.col(c) = warm ? Eigen::VectorXd(s->solveWithGuess(rhs.col(c), guess.col(c)))
                              : Eigen::VectorXd(s->solve(rhs.col(c)));
              stats.cg_iterations = std::max(stats.cg_iterations, int(s->iterations()));
              stats.cg_error = std::max(stats.cg_error, double(s->error()));
              if (s->info() != Eigen::Success)
                throw InputError(fmt::format("thermal model: the conjugate gradient did not reach the relative "
                                             "residual {:.1e} in {} iterations ({:.2e})",
                                             options.cg_tolerance, s->maxIterations(), double(s->error())));
            }
          } else {
            x = s->solve(rhs);
            if (s->info() != Eigen::Success) throw InputError("thermal model: the sparse solve failed");
          }
        },
        solver);
    return x;
  }

  template <class S>
  void run(S& s, const Sparse& a, bool analyse) {
    auto t0 = std::chrono::steady_clock::now();
    if (analyse) {
      s.analyzePattern(a);
      stats.analysis_ms = ms_since(t0);
      ++stats.analyses;
      if constexpr (std::is_base_of_v<Eigen::CholmodBase<Sparse, Eigen::Lower, S>, S>) {
        const cholmod_common& c = s.cholmod();
        stats.factor_nonzeros = c.lnz;
        stats.factor_flops = c.fl;
        stats.ordering = ordering_name(c.method[c.selected].ordering);
      }
    } else {
      stats.analysis_ms = 0;
    }
    auto t1 = std::chrono::steady_clock::now();
    s.factorize(a);
    stats.factorization_ms = ms_since(t1);
    if (s.info() != Eigen::Success)
      throw InputError(fmt::format("thermal model: the {} factorisation failed: the matrix is not positive definite "
                                   "(a negative Robin coefficient or conductivity?)",
                                   to_string(options.solver)));
  }
};

SymmetricSolver::SymmetricSolver(const LinearSolverOptions& options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  if (!(options.cg_tolerance > 0))
    throw InputError(fmt::format("linear solver: cg_tolerance = {} (expected > 0)", options.cg_tolerance));
}
SymmetricSolver::~SymmetricSolver() = default;
SymmetricSolver::SymmetricSolver(SymmetricSolver&&) noexcept = default;
SymmetricSolver& SymmetricSolver::operator=(SymmetricSolver&&) noexcept = default;

const LinearSolverOptions& SymmetricSolver::options() const { return impl_->options; }
const LinearSolverStats& SymmetricSolver::stats() const { return impl_->stats; }

void SymmetricSolver::factorize(const Eigen::SparseMatrix<double>& matrix) {
  Impl& m = *impl_;
  if (matrix.rows() != matrix.cols() || matrix.rows() == 0)
    throw std::invalid_argument(fmt::format("SymmetricSolver: a {}×{} matrix", matrix.rows(), matrix.cols()));
  m.matrix = matrix;
  m.matrix.makeCompressed();
  bool analyse = !m.factored || !same_pattern(m.matrix, m.outer, m.inner);
  m.factored = false;
  if (analyse) {
    m.outer.assign(m.matrix.outerIndexPtr(), m.matrix.outerIndexPtr() + m.matrix.outerSize() + 1);
    m.inner.assign(m.matrix.innerIndexPtr(), m.matrix.innerIndexPtr() + m.matrix.nonZeros());
  }
  try {
    m.factor(analyse);
  } catch (const InputError& e) {
    if (m.options.solver != LinearSolver::conjugate_gradient || !m.options.fallback_to_cholmod) throw;
    m.fall_back(e.what());
  }
  m.factored = true;
}

Eigen::MatrixXd SymmetricSolver::solve(const Eigen::MatrixXd& rhs) { return solve(rhs, Eigen::MatrixXd()); }

Eigen::MatrixXd SymmetricSolver::solve(const Eigen::MatrixXd& rhs, const Eigen::MatrixXd& guess) {
  Impl& m = *impl_;
  if (!m.factored) throw std::logic_error("SymmetricSolver::solve before a successful factorize");
  auto t0 = std::chrono::steady_clock::now();
  Eigen::MatrixXd x;
  try {
    x = m.solve(rhs, guess);
  } catch (const InputError& e) {
    if (m.options.solver != LinearSolver::conjugate_gradient || !m.options.fallback_to_cholmod) throw;
    m.fall_back(e.what());
    x = m.solve(rhs, guess);
  }
  m.stats.solve_ms = ms_since(t0);
  return x;
}

}  // namespace bodyfit::thermal
