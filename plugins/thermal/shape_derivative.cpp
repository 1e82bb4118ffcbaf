#include "shape_derivative.hpp"

#include "smoothing.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>

#include <fmt/format.h>

#include <cmath>

namespace bodyfit::thermal {

namespace {

void check_inputs(const SurfaceMesh& surface, const std::vector<double>& distance, const ThermalSolution& solution,
                  const ObjectiveOptions& options) {
  if (!(options.epsilon > 0) || !std::isfinite(options.epsilon))
    throw InputError(fmt::format("thermal objective: ε = {} (the width of the Robin transition must be positive)",
                                 options.epsilon));
  if (!(options.ell >= 0) || !std::isfinite(options.ell))
    throw InputError(fmt::format("thermal objective: ℓ = {} (expected ≥ 0)", options.ell));
  if (distance.size() != surface.n_vertices())
    throw InputError(fmt::format("thermal objective: the distance has {} values for {} surface vertices",
                                 distance.size(), surface.n_vertices()));
  if (std::size_t(solution.u.size()) < surface.n_vertices() || std::size_t(solution.p.size()) < surface.n_vertices())
    throw InputError(fmt::format("thermal objective: the solution has {} values for {} surface vertices",
                                 solution.u.size(), surface.n_vertices()));
  if (!options.neumann.empty() && options.neumann.size() != surface.n_faces())
    throw InputError(fmt::format("thermal objective: the Neumann face mask has {} entries for {} faces",
                                 options.neumann.size(), surface.n_faces()));
}

}  // namespace

std::vector<double> shape_gradient_density(const std::vector<double>& distance, const Eigen::VectorXd& u,
                                           const Eigen::VectorXd& p, double epsilon) {
  if (std::size_t(u.size()) < distance.size() || std::size_t(p.size()) < distance.size())
    throw InputError(fmt::format("shape gradient: u and p have {} and {} values for {} surface vertices", u.size(),
                                 p.size(), distance.size()));
  std::vector<double> w(distance.size());
  for (std::size_t i = 0; i < distance.size(); ++i)
    w[i] = -h_epsilon_prime(distance[i], epsilon) * u[Eigen::Index(i)] * p[Eigen::Index(i)];
  return w;
}

ThermalObjective thermal_objective(const SurfaceMesh& surface, const std::vector<double>& distance,
                                   const ThermalSolution& solution, const ObjectiveOptions& options) {
  check_inputs(surface, distance, solution, options);
  ThermalObjective out;
  out.T = solution.mean_temperature;
  for (auto f : surface.faces())
    if (surface.inside(f)) out.area += face_area(surface, f);
  out.J = out.T + options.ell * out.area;
  out.density = shape_gradient_density(distance, solution.u, solution.p, options.epsilon);
  if (!options.neumann.empty()) {
    // No Robin term on Γ_N: w lives on the vertices of S \ Γ_N only.
    std::vector<char> robin_vertex(surface.n_vertices(), 0);
    for (auto f : surface.faces())
      if (!options.neumann[std::size_t(f.idx())])
        for (auto v : surface.fv_range(f)) robin_vertex[std::size_t(v.idx())] = 1;
    for (std::size_t i = 0; i < out.density.size(); ++i)
      if (!robin_vertex[i]) out.density[i] = 0;
  }
  return out;
}

double band_derivative(const SurfaceMesh& surface, const std::vector<double>& distance, const std::vector<double>& s,
                       const ThermalSolution& solution, const ObjectiveOptions& options) {
  check_inputs(surface, distance, solution, options);
  if (s.size() != surface.n_vertices())
    throw InputError(fmt::format("band derivative: the perturbation has {} values for {} surface vertices", s.size(),
                                 surface.n_vertices()));
  const auto points = triangle_points(options.quadrature);
  double total = 0;
  for (auto f : surface.faces()) {
    if (!options.neumann.empty() && options.neumann[std::size_t(f.idx())]) continue;
    auto vs = face_vertices(surface, f);
    auto [a, b, c] = face_points(surface, f);
    // The same area formula as the Robin assembly, so that both see the same numbers.
    double area = 0.5 * OpenMesh::cross(b - a, c - a).norm();
    std::array<double, 3> D, S, U, P;
    for (int k = 0; k < 3; ++k) {
      auto i = std::size_t(vs[std::size_t(k)].idx());
      D[std::size_t(k)] = distance[i];
      S[std::size_t(k)] = s[i];
      U[std::size_t(k)] = solution.u[Eigen::Index(i)];
      P[std::size_t(k)] = solution.p[Eigen::Index(i)];
    }
    double sum = 0;
    for (const auto& q : points) {
      const auto& l = q.barycentric;
      auto at = [&](const std::array<double, 3>& v) { return l[0] * v[0] + l[1] * v[1] + l[2] * v[2]; };
      double dk = h_epsilon_prime(at(D), options.epsilon);
      if (dk != 0) sum += q.weight * dk * at(S) * at(U) * at(P);
    }
    total += area * sum;
  }
  return total;
}

}  // namespace bodyfit::thermal
