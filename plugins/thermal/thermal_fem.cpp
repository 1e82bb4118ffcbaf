#include "thermal_fem.hpp"

#include <bodyfit/error.hpp>

#include <Eigen/Dense>
#include <fmt/format.h>

#include <array>
#include <chrono>
#include <optional>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace bodyfit::thermal {

namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

std::array<Vec3, 4> tet_points(const VolumeMesh& mesh, const std::array<int, 4>& t) {
  return {mesh.points[std::size_t(t[0])], mesh.points[std::size_t(t[1])], mesh.points[std::size_t(t[2])],
          mesh.points[std::size_t(t[3])]};
}

/// Gradients of the four barycentric coordinates and the volume: with J = [b − a, c − a, d − a],
/// the rows of J⁻¹ are ∇λ_1..3 and ∇λ_0 = −Σ.
double tet_gradients(const std::array<Vec3, 4>& p, std::array<Eigen::Vector3d, 4>& grad) {
  Eigen::Matrix3d J;
  for (int k = 0; k < 3; ++k)
    for (int r = 0; r < 3; ++r) J(r, k) = p[std::size_t(k + 1)][r] - p[0][r];
  double det = J.determinant();
  Eigen::Matrix3d inv = J.inverse();
  grad[1] = inv.row(0).transpose();
  grad[2] = inv.row(1).transpose();
  grad[3] = inv.row(2).transpose();
  grad[0] = -(grad[1] + grad[2] + grad[3]);
  return det / 6;
}

double triangle_area(const Vec3& a, const Vec3& b, const Vec3& c) { return 0.5 * OpenMesh::cross(b - a, c - a).norm(); }

void check_mask(const VolumeMesh& mesh, const FaceMask& mask, const char* what) {
  if (!mask.empty() && mask.size() != mesh.boundary_faces.size())
    throw InputError(fmt::format("thermal model: {} has {} entries for {} surface faces", what, mask.size(),
                                 mesh.boundary_faces.size()));
}

bool flagged(const FaceMask& mask, int surface_face) { return !mask.empty() && mask[std::size_t(surface_face)]; }

SparseMatrix from_triplets(const VolumeMesh& mesh, const Triplets& triplets) {
  auto n = Eigen::Index(mesh.n_vertices());
  SparseMatrix m(n, n);
  m.setFromTriplets(triplets.begin(), triplets.end());  // duplicates are summed
  return m;
}

}  // namespace

// ---- assembly ------------------------------------------------------------------------------------

SparseMatrix assemble_stiffness(const VolumeMesh& mesh, const SpatialFunction& conductivity) {
  Triplets triplets;
  triplets.reserve(16 * mesh.n_tets());
  std::array<Eigen::Vector3d, 4> grad;
  for (const auto& t : mesh.tets) {
    auto p = tet_points(mesh, t);
    double volume = tet_gradients(p, grad);
    double gamma = 1;
    if (conductivity) {
      gamma = conductivity((p[0] + p[1] + p[2] + p[3]) * 0.25);
      if (!(gamma > 0) || !std::isfinite(gamma))
        throw InputError(fmt::format("thermal model: the conductivity is {} at ({}, {}, {}) (expected > 0)", gamma,
                                     p[0][0], p[0][1], p[0][2]));
    }
    double scale = gamma * volume;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) triplets.emplace_back(t[std::size_t(i)], t[std::size_t(j)], scale * grad[std::size_t(i)].dot(grad[std::size_t(j)]));
  }
  return from_triplets(mesh, triplets);
}

Eigen::VectorXd assemble_volume_weights(const VolumeMesh& mesh) {
  Eigen::VectorXd m = Eigen::VectorXd::Zero(Eigen::Index(mesh.n_vertices()));
  for (const auto& t : mesh.tets) {
    auto p = tet_points(mesh, t);
    double quarter = tet_volume(p[0], p[1], p[2], p[3]) / 4;
    for (int v : t) m[v] += quarter;
  }
  return m;
}

Eigen::VectorXd assemble_load(const VolumeMesh& mesh, const SpatialFunction& source) {
  if (!source) return assemble_volume_weights(mesh);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(Eigen::Index(mesh.n_vertices()));
  const auto& rule = tet_points_degree2();
  for (const auto& t : mesh.tets) {
    auto p = tet_points(mesh, t);
    double volume = tet_volume(p[0], p[1], p[2], p[3]);
    for (const auto& q : rule) {
      const auto& l = q.barycentric;
      double f = source(p[0] * l[0] + p[1] * l[1] + p[2] * l[2] + p[3] * l[3]);
      for (int i = 0; i < 4; ++i) b[t[std::size_t(i)]] += volume * q.weight * f * l[std::size_t(i)];
    }
  }
  return b;
}

SparseMatrix assemble_robin(const VolumeMesh& mesh, const std::vector<double>& field,
                            const std::function<double(double)>& coefficient, const FaceMask& skip,
                            const TriangleQuadrature& rule) {
  if (field.size() != std::size_t(mesh.n_surface_vertices))
    throw InputError(fmt::format("thermal model: the Robin field has {} values for {} surface vertices", field.size(),
                                 mesh.n_surface_vertices));
  check_mask(mesh, skip, "the Neumann face mask");
  const auto points = triangle_points(rule);
  Triplets triplets;
  triplets.reserve(9 * mesh.boundary_faces.size());
  for (std::size_t k = 0; k < mesh.boundary_faces.size(); ++k) {
    if (flagged(skip, mesh.boundary_source_face[k])) continue;
    const auto& f = mesh.boundary_faces[k];
    double area = triangle_area(mesh.points[std::size_t(f[0])], mesh.points[std::size_t(f[1])],
                                mesh.points[std::size_t(f[2])]);
    std::array<double, 3> F{field[std::size_t(f[0])], field[std::size_t(f[1])], field[std::size_t(f[2])]};
    std::array<std::array<double, 3>, 3> local{};
    for (const auto& q : points) {
      const auto& l = q.barycentric;
      double value = l[0] * F[0] + l[1] * F[1] + l[2] * F[2];
      double kappa = coefficient ? coefficient(value) : value;
      if (!(kappa >= 0) || !std::isfinite(kappa))
        throw InputError(fmt::format("thermal model: the Robin coefficient is {} for the field value {} (expected ≥ 0)",
                                     kappa, value));
      double w = area * q.weight * kappa;
      if (w == 0) continue;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) local[std::size_t(i)][std::size_t(j)] += w * l[std::size_t(i)] * l[std::size_t(j)];
    }
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (local[std::size_t(i)][std::size_t(j)] != 0)
          triplets.emplace_back(f[std::size_t(i)], f[std::size_t(j)], local[std::size_t(i)][std::size_t(j)]);
  }
  return from_triplets(mesh, triplets);
}

Eigen::VectorXd assemble_boundary_load(const VolumeMesh& mesh, const SpatialFunction& g, const FaceMask& faces,
                                       const TriangleQuadrature& rule) {
  check_mask(mesh, faces, "the boundary load face mask");
  Eigen::VectorXd b = Eigen::VectorXd::Zero(Eigen::Index(mesh.n_vertices()));
  if (!g) return b;
  const auto points = triangle_points(rule);
  for (std::size_t k = 0; k < mesh.boundary_faces.size(); ++k) {
    if (!faces.empty() && !faces[std::size_t(mesh.boundary_source_face[k])]) continue;
    const auto& f = mesh.boundary_faces[k];
    const Vec3& a = mesh.points[std::size_t(f[0])];
    const Vec3& bb = mesh.points[std::size_t(f[1])];
    const Vec3& c = mesh.points[std::size_t(f[2])];
    double area = triangle_area(a, bb, c);
    for (const auto& q : points) {
      const auto& l = q.barycentric;
      double value = area * q.weight * g(a * l[0] + bb * l[1] + c * l[2]);
      for (int i = 0; i < 3; ++i) b[f[std::size_t(i)]] += value * l[std::size_t(i)];
    }
  }
  return b;
}

// ---- the solver ----------------------------------------------------------------------------------

struct ThermalSolver::Impl {
  const VolumeMesh* mesh = nullptr;
  ThermalProblem problem;
  ThermalOptions options;
  SparseMatrix stiffness;
  Eigen::VectorXd weights;      // ∫ φ_i
  Eigen::VectorXd state_rhs;    // ∫ f φ_i + ∫_{Γ_N} g φ_i + ∫_{S\Γ_N} g_R φ_i
  FaceMask robin_skip;          // Γ_N
  double volume = 0;
  double setup_ms = 0;
  bool shortcut = false;        // p = −u/|Ω|
  std::optional<TemperatureFunctional> functional;
  SymmetricSolver solver;
  Eigen::MatrixXd previous;     // the last solution [u p], the conjugate gradient's warm start
};

ThermalSolver::ThermalSolver(const VolumeMesh& mesh, ThermalProblem problem, const ThermalOptions& options)
    : impl_(std::make_unique<Impl>()) {
  auto t0 = std::chrono::steady_clock::now();
  Impl& m = *impl_;
  m.mesh = &mesh;
  m.problem = std::move(problem);
  m.options = options;
  m.solver = SymmetricSolver(options.linear);
  if (mesh.tets.empty()) throw InputError("thermal model: the volume mesh has no tetrahedra");
  const ThermalProblem& pb = m.problem;
  check_mask(mesh, pb.neumann, "the Neumann face mask (problem.neumann)");
  std::size_t neumann_faces = 0;
  for (char c : pb.neumann) neumann_faces += c ? 1 : 0;
  if (neumann_faces == mesh.boundary_faces.size())
    throw InputError(fmt::format("thermal model: Γ_N covers all {} faces of S: without a Robin part the temperature "
                                 "is only defined up to a constant (the system is singular)",
                                 neumann_faces));
  m.robin_skip = pb.neumann;
  triangle_points(options.quadrature);  // validates the rule now rather than at the first solve

  m.stiffness = assemble_stiffness(mesh, pb.conductivity);
  m.weights = assemble_volume_weights(mesh);
  m.volume = m.weights.sum();
  m.state_rhs = pb.source ? assemble_load(mesh, pb.source) : m.weights;
  if (pb.neumann_flux && neumann_faces > 0)
    m.state_rhs += assemble_boundary_load(mesh, pb.neumann_flux, pb.neumann, options.quadrature);
  if (pb.robin_source) {
    FaceMask robin_faces(mesh.boundary_faces.size(), 1);
    for (std::size_t f = 0; f < pb.neumann.size(); ++f) robin_faces[f] = pb.neumann[f] ? 0 : 1;
    m.state_rhs += assemble_boundary_load(mesh, pb.robin_source, robin_faces, options.quadrature);
  }
  m.functional.emplace(mesh, pb.objective, m.stiffness, m.weights);
  m.shortcut = options.adjoint_shortcut && pb.objective.kind == ObjectiveKind::mean_temperature && !pb.source && !pb.robin_source && (!pb.neumann_flux || neumann_faces == 0);
  m.setup_ms = ms_since(t0);
}

ThermalSolver::~ThermalSolver() = default;
ThermalSolver::ThermalSolver(ThermalSolver&&) noexcept = default;
ThermalSolver& ThermalSolver::operator=(ThermalSolver&&) noexcept = default;

const VolumeMesh& ThermalSolver::mesh() const { return *impl_->mesh; }
const ThermalProblem& ThermalSolver::problem() const { return impl_->problem; }
const ThermalOptions& ThermalSolver::options() const { return impl_->options; }
double ThermalSolver::setup_ms() const { return impl_->setup_ms; }
const LinearSolverStats& ThermalSolver::linear_stats() const { return impl_->solver.stats(); }
const TemperatureFunctional& ThermalSolver::functional() const { return *impl_->functional; }
const Eigen::MatrixXd& ThermalSolver::warm_start() const { return impl_->previous; }
void ThermalSolver::set_warm_start(Eigen::MatrixXd guess) { impl_->previous = std::move(guess); }
void ThermalSolver::set_robin_coefficient(std::function<double(double)> coefficient) {
  impl_->problem.robin_coefficient = std::move(coefficient);
}

ThermalSolution ThermalSolver::solve() { return solve(impl_->problem.robin_field); }

ThermalSolution ThermalSolver::solve(const std::vector<double>& robin_field) {
  Impl& m = *impl_;
  const VolumeMesh& mesh = *m.mesh;
  ThermalSolution out;
  out.volume = m.volume;
  out.timings.setup_ms = m.setup_ms;

  auto t0 = std::chrono::steady_clock::now();
  SparseMatrix robin =
      assemble_robin(mesh, robin_field, m.problem.robin_coefficient, m.robin_skip, m.options.quadrature);
  // ∫_{S\Γ_N} κ = 1ᵀR1: zero means no Robin term anywhere, and K alone is singular (K·1 = 0).
  double robin_total = robin.sum();
  if (!(robin_total > 0))
    throw InputError(fmt::format("thermal model: the Robin coefficient vanishes on all of S \\ Γ_N (∫κ = {:.3g}): the "
                                 "temperature is only defined up to a constant (the system is singular)",
                                 robin_total));
  SparseMatrix a = m.stiffness + robin;
  out.timings.assembly_ms = ms_since(t0);

  m.solver.factorize(a);
  const auto& stats = m.solver.stats();
  out.timings.analysis_ms = stats.analysis_ms;
  out.timings.factorization_ms = stats.factorization_ms;

  // A linear j: state and adjoint in one call (CHOLMOD solves both columns together). Otherwise the
  // adjoint's right-hand side −j′(u) needs u first: two calls on the same factorisation.
  const TemperatureFunctional& j = *m.functional;
  const bool together = m.shortcut || j.linear();
  Eigen::MatrixXd rhs(a.rows(), together && !m.shortcut ? 2 : 1);
  rhs.col(0) = m.state_rhs;
  if (rhs.cols() == 2) rhs.col(1) = -j.gradient(m.state_rhs);  // j′ of a linear j: any argument
  const bool warm = m.options.warm_start && m.options.linear.solver == LinearSolver::conjugate_gradient;
  auto guess = [&](Eigen::Index first, Eigen::Index count) {
    return warm && m.previous.cols() >= first + count ? Eigen::MatrixXd(m.previous.middleCols(first, count))
                                                       : Eigen::MatrixXd();
  };
  Eigen::MatrixXd x = m.solver.solve(rhs, guess(0, rhs.cols()));
  out.timings.solve_ms = m.solver.stats().solve_ms;
  out.timings.cg_iterations = m.solver.stats().cg_iterations;
  out.u = x.col(0);
  if (m.shortcut) {
    out.p = -out.u / m.volume;
  } else if (together) {
    out.p = x.col(1);
  } else {
    const Eigen::MatrixXd adjoint_rhs = -j.gradient(out.u);
    const Eigen::MatrixXd p = m.solver.solve(adjoint_rhs, guess(1, 1));
    out.timings.solve_ms += m.solver.stats().solve_ms;
    out.timings.cg_iterations = std::max(out.timings.cg_iterations, m.solver.stats().cg_iterations);
    out.p = p.col(0);
  }
  if (warm) {
    m.previous.resize(out.u.size(), 2);
    m.previous.col(0) = out.u;
    m.previous.col(1) = out.p;
  }
  out.mean_temperature = m.weights.dot(out.u) / m.volume;
  out.objective = j.value(out.u);
  return out;
}

ThermalSolution solve_thermal(const VolumeMesh& mesh, const ThermalProblem& problem, const ThermalOptions& options) {
  return ThermalSolver(mesh, problem, options).solve();
}

}  // namespace bodyfit::thermal
