// Topological nucleation (nucleation.hpp).
#include "nucleation.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace bodyfit::thermal {

std::vector<double> topological_sensitivity(const SurfaceMesh& mesh, const std::vector<double>& u,
                                            const std::vector<double>& p, const BoxField& conductivity) {
  std::vector<double> g(mesh.n_vertices(), 0.0);
  for (auto v : mesh.vertices()) {
    const auto i = std::size_t(v.idx());
    g[i] = 4 * conductivity(mesh.point(v)) * u[i] * p[i];
  }
  return g;
}

std::vector<int> nucleation_sites(const SurfaceMesh& mesh, const std::vector<double>& distance,
                                  const std::vector<double>& sensitivity, const std::vector<char>& excluded,
                                  const NucleationOptions& options) {
  if (distance.size() != mesh.n_vertices() || sensitivity.size() != mesh.n_vertices() ||
      (!excluded.empty() && excluded.size() != mesh.n_vertices()))
    throw std::invalid_argument("nucleation_sites: the fields are not the mesh's (one value per vertex)");
  const double keep = options.radius + options.clearance;
  std::vector<Vec3> forbidden;  // Γ_N's vertices: a disk's centre stays `keep` away from them
  for (auto v : mesh.vertices())
    if (!excluded.empty() && excluded[std::size_t(v.idx())]) forbidden.push_back(mesh.point(v));
  std::vector<int> order;
  for (auto v : mesh.vertices()) {
    const auto i = std::size_t(v.idx());
    if (distance[i] > keep && sensitivity[i] < 0) order.push_back(v.idx());
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return sensitivity[std::size_t(a)] < sensitivity[std::size_t(b)] || (sensitivity[std::size_t(a)] == sensitivity[std::size_t(b)] && a < b);
  });
  std::vector<int> sites;
  for (int v : order) {
    if (int(sites.size()) >= options.count) break;
    const Vec3 x = mesh.point(VertexHandle(v));
    auto near = [&](const Vec3& y, double within) { return (x - y).norm() <= within; };
    if (std::any_of(forbidden.begin(), forbidden.end(), [&](const Vec3& y) { return near(y, keep); })) continue;
    if (std::any_of(sites.begin(), sites.end(),
                    [&](int s) { return near(mesh.point(VertexHandle(s)), 2 * options.radius + options.clearance); }))
      continue;
    sites.push_back(v);
  }
  return sites;
}

}  // namespace bodyfit::thermal
