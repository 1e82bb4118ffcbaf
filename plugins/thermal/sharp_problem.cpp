#include "sharp_problem.hpp"

#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <chrono>
#include <vector>

namespace bodyfit::thermal {

SharpSolution solve_sharp(const VolumeMesh& mesh, const ThermalProblem& problem, const FaceMask& dirichlet,
                          const LinearSolverOptions& linear) {
  const auto start = std::chrono::steady_clock::now();
  if (dirichlet.size() != mesh.boundary_faces.size())
    throw InputError(fmt::format("thermal model: the sharp problem's G has {} face flags for {} surface faces",
                                 dirichlet.size(), mesh.boundary_faces.size()));
  // G's vertices are held at 0; every other vertex is free.
  std::vector<char> held(mesh.n_vertices(), 0);
  std::size_t faces = 0;
  for (std::size_t i = 0; i < mesh.boundary_faces.size(); ++i) {
    const int source = mesh.boundary_source_face[i];
    if (!dirichlet[std::size_t(source)]) continue;
    if (!problem.neumann.empty() && problem.neumann[std::size_t(source)])
      throw InputError(fmt::format("thermal model: face {} is both in G and in the Neumann boxes", source));
    ++faces;
    for (int v : mesh.boundary_faces[i]) held[std::size_t(v)] = 1;
  }
  if (faces == 0)
    throw InputError("thermal model: G is empty: the sharp problem (u = 0 on G, insulated elsewhere) has no "
                     "solution for a heat source");
  std::vector<int> free_index(mesh.n_vertices(), -1);
  int n_free = 0;
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v)
    if (!held[v]) free_index[v] = n_free++;

  const SparseMatrix K = assemble_stiffness(mesh, problem.conductivity);
  Eigen::VectorXd b = assemble_load(mesh, problem.source);
  if (!problem.neumann.empty() && problem.neumann_flux)
    b += assemble_boundary_load(mesh, problem.neumann_flux, problem.neumann);
  // u = 0 on G: the free rows and columns of K, the free entries of b (no lifting needed).
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(std::size_t(K.nonZeros()));
  for (Eigen::Index col = 0; col < K.outerSize(); ++col)
    for (SparseMatrix::InnerIterator it(K, col); it; ++it) {
      const int i = free_index[std::size_t(it.row())], j = free_index[std::size_t(it.col())];
      if (i >= 0 && j >= 0) triplets.emplace_back(i, j, it.value());
    }
  SparseMatrix K_free(n_free, n_free);
  K_free.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::MatrixXd b_free(n_free, 1);
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v)
    if (free_index[v] >= 0) b_free(free_index[v], 0) = b[Eigen::Index(v)];
  SymmetricSolver solver(linear);
  solver.factorize(K_free);
  const Eigen::MatrixXd u_free = solver.solve(b_free);

  SharpSolution s;
  s.u = Eigen::VectorXd::Zero(Eigen::Index(mesh.n_vertices()));
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v)
    if (free_index[v] >= 0) s.u[Eigen::Index(v)] = u_free(free_index[v], 0);
  const Eigen::VectorXd weights = assemble_volume_weights(mesh);
  s.volume = weights.sum();
  s.mean_temperature = weights.dot(s.u) / s.volume;
  s.objective = TemperatureFunctional(mesh, problem.objective, K, weights).value(s.u);
  s.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return s;
}

}  // namespace bodyfit::thermal
