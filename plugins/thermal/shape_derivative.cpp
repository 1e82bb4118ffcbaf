#include "shape_derivative.hpp"

#include "smoothing.hpp"
#include "surface_transfer.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <unordered_map>

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
  out.j = solution.objective;
  out.J = out.j + options.ell * out.area;
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

std::vector<double> band_weights(const SurfaceMesh& surface, const std::vector<double>& distance,
                                 const ThermalSolution& solution, const ObjectiveOptions& options) {
  check_inputs(surface, distance, solution, options);
  const auto points = triangle_points(options.quadrature);
  std::vector<double> weights(surface.n_vertices(), 0.0);
  for (auto f : surface.faces()) {
    if (!options.neumann.empty() && options.neumann[std::size_t(f.idx())]) continue;
    auto vs = face_vertices(surface, f);
    auto [a, b, c] = face_points(surface, f);
    // The same area formula as the Robin assembly, so that both see the same numbers.
    double area = 0.5 * OpenMesh::cross(b - a, c - a).norm();
    std::array<double, 3> D, U, P;
    for (int k = 0; k < 3; ++k) {
      auto i = std::size_t(vs[std::size_t(k)].idx());
      D[std::size_t(k)] = distance[i];
      U[std::size_t(k)] = solution.u[Eigen::Index(i)];
      P[std::size_t(k)] = solution.p[Eigen::Index(i)];
    }
    std::array<double, 3> local{};
    for (const auto& q : points) {
      const auto& l = q.barycentric;
      auto at = [&](const std::array<double, 3>& v) { return l[0] * v[0] + l[1] * v[1] + l[2] * v[2]; };
      const double dk = h_epsilon_prime(at(D), options.epsilon);
      if (dk == 0) continue;
      const double value = area * q.weight * dk * at(U) * at(P);
      for (int k = 0; k < 3; ++k) local[std::size_t(k)] += value * l[std::size_t(k)];
    }
    for (int k = 0; k < 3; ++k) weights[std::size_t(vs[std::size_t(k)].idx())] += local[std::size_t(k)];
  }
  return weights;
}

double band_derivative(const SurfaceMesh& surface, const std::vector<double>& distance, const std::vector<double>& s,
                       const ThermalSolution& solution, const ObjectiveOptions& options) {
  if (s.size() != surface.n_vertices())
    throw InputError(fmt::format("band derivative: the perturbation has {} values for {} surface vertices", s.size(),
                                 surface.n_vertices()));
  const std::vector<double> weights = band_weights(surface, distance, solution, options);
  double total = 0;
  for (std::size_t k = 0; k < s.size(); ++k) total += weights[k] * s[k];
  return total;
}

Eigen::VectorXd interface_length_load(const SurfaceMesh& surface) {
  Eigen::VectorXd b = Eigen::VectorXd::Zero(Eigen::Index(surface.n_vertices()));
  for (auto e : surface.edges()) {
    if (!surface.interface(e)) continue;
    const double half = 0.5 * surface.calc_edge_length(e);
    const auto h = surface.halfedge_handle(e, 0);
    b[surface.to_vertex_handle(h).idx()] += half;
    b[surface.from_vertex_handle(h).idx()] += half;
  }
  return b;
}

namespace {

/// Σ's edges in a uniform grid of cells of side `cell`, each edge in every cell its bounding box meets.
class InterfaceGrid {
 public:
  struct Edge {
    Vec3 a, b;
    int ia, ib;
  };
  InterfaceGrid(const SurfaceMesh& surface, double cell) : cell_(cell) {
    for (auto e : surface.edges()) {
      if (!surface.interface(e)) continue;
      const auto h = surface.halfedge_handle(e, 0);
      const auto va = surface.from_vertex_handle(h), vb = surface.to_vertex_handle(h);
      edges_.push_back({surface.point(va), surface.point(vb), va.idx(), vb.idx()});
      const auto lo = key(min(edges_.back().a, edges_.back().b)), hi = key(max(edges_.back().a, edges_.back().b));
      for (long i = lo[0]; i <= hi[0]; ++i)
        for (long j = lo[1]; j <= hi[1]; ++j)
          for (long k = lo[2]; k <= hi[2]; ++k) cells_[hash({i, j, k})].push_back(int(edges_.size() - 1));
    }
  }
  bool empty() const { return edges_.empty(); }

  /// The closest point of Σ to x within the reach: its edge and the parameter t along it (a → b);
  /// no edge when none is within the reach.
  std::pair<const Edge*, double> closest(const Vec3& x) const {
    double best = cell_ * cell_;
    std::pair<const Edge*, double> found{nullptr, 0};
    const auto c = key(x);
    for (long i = -1; i <= 1; ++i)
      for (long j = -1; j <= 1; ++j)
        for (long k = -1; k <= 1; ++k) {
          const auto it = cells_.find(hash({c[0] + i, c[1] + j, c[2] + k}));
          if (it == cells_.end()) continue;
          for (int index : it->second) {
            const Edge& e = edges_[std::size_t(index)];
            const Vec3 ab = e.b - e.a;
            const double length2 = ab.sqrnorm();
            const double t = length2 > 0 ? std::clamp(OpenMesh::dot(x - e.a, ab) / length2, 0.0, 1.0) : 0.0;
            const double d2 = (e.a + ab * t - x).sqrnorm();
            if (d2 <= best) best = d2, found = {&e, t};
          }
        }
    return found;
  }

 private:
  static Vec3 min(const Vec3& a, const Vec3& b) { return {std::min(a[0], b[0]), std::min(a[1], b[1]), std::min(a[2], b[2])}; }
  static Vec3 max(const Vec3& a, const Vec3& b) { return {std::max(a[0], b[0]), std::max(a[1], b[1]), std::max(a[2], b[2])}; }
  std::array<long, 3> key(const Vec3& x) const {
    return {long(std::floor(x[0] / cell_)), long(std::floor(x[1] / cell_)), long(std::floor(x[2] / cell_))};
  }
  static std::size_t hash(const std::array<long, 3>& k) {
    return std::size_t(k[0]) * 73856093u ^ std::size_t(k[1]) * 19349663u ^ std::size_t(k[2]) * 83492791u;
  }
  double cell_;
  std::vector<Edge> edges_;
  std::unordered_map<std::size_t, std::vector<int>> cells_;
};

}  // namespace

InterfaceProjection project_onto_interface(const SurfaceMesh& surface, const std::vector<Vec3>& points, double reach) {
  if (!(reach > 0)) throw InputError(fmt::format("interface projection: reach {} (expected > 0)", reach));
  InterfaceProjection p;
  const std::size_t n = points.size();
  p.from.assign(n, -1), p.to.assign(n, -1), p.t.assign(n, 0);
  const InterfaceGrid grid(surface, reach);
  if (grid.empty()) return p;
  for (std::size_t k = 0; k < n; ++k) {
    const auto [edge, t] = grid.closest(points[k]);
    if (edge) p.from[k] = edge->ia, p.to[k] = edge->ib, p.t[k] = t;
  }
  return p;
}

InterfaceProjection project_onto_interface(const SurfaceMesh& surface, double reach) {
  return project_onto_interface(surface, vertex_points(surface), reach);
}

Eigen::VectorXd projected_band_load(const InterfaceProjection& projection, const std::vector<double>& weights,
                                    std::size_t n_vertices) {
  const std::size_t n = projection.from.size();
  if (weights.size() != n)
    throw InputError(fmt::format("projected band load: {} weights for {} projected points", weights.size(), n));
  Eigen::VectorXd b = Eigen::VectorXd::Zero(Eigen::Index(n_vertices));
  for (std::size_t k = 0; k < n; ++k) {
    if (weights[k] == 0) continue;
    if (projection.from[k] < 0)
      throw InputError(fmt::format("projected band load: W = {:.3g} at vertex {}, beyond the projection's reach",
                                   weights[k], k));
    const double load = -weights[k], t = projection.t[k];
    b[projection.from[k]] += (1 - t) * load;
    b[projection.to[k]] += t * load;
  }
  return b;
}

std::vector<double> extend_from_interface(const InterfaceProjection& projection, const std::vector<double>& v) {
  if (v.size() != projection.from.size())
    throw InputError(fmt::format("interface extension: {} values for {} vertices", v.size(), projection.from.size()));
  std::vector<double> out = v;
  for (std::size_t k = 0; k < v.size(); ++k)
    if (projection.from[k] >= 0)
      out[k] = (1 - projection.t[k]) * v[std::size_t(projection.from[k])] + projection.t[k] * v[std::size_t(projection.to[k])];
  return out;
}

}  // namespace bodyfit::thermal
