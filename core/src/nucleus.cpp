// Nuclei of G (nucleus.hpp).
#include <bodyfit/error.hpp>
#include <bodyfit/nucleus.hpp>

#include <fmt/format.h>

#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>
#include <vector>

namespace bodyfit {

ScalarField nucleus_level_set(const SurfaceMesh& mesh, const Nucleus& nucleus) {
  if (nucleus.vertex < 0 || std::size_t(nucleus.vertex) >= mesh.n_vertices())
    throw InputError(fmt::format("a nucleus of G at vertex {}: the mesh has vertices 0 to {}", nucleus.vertex,
                                 mesh.n_vertices() - 1));
  if (!(nucleus.radius > 0) || !std::isfinite(nucleus.radius))
    throw InputError(fmt::format("a nucleus of G of radius {}: the radius must be positive and finite", nucleus.radius));
  const VertexHandle centre(nucleus.vertex);
  const Vec3 c = mesh.point(centre);
  double longest = 0;
  for (auto h : mesh.voh_range(centre)) longest = std::max(longest, mesh.calc_edge_length(h));
  // Edge paths are never shorter than the geodesic, which is never shorter than the chord: every
  // vertex of the disk (and a ring beyond) is reached well within the bound, a facing sheet is not.
  const double reach = 2 * nucleus.radius + 2 * longest;

  ScalarField psi(mesh.n_vertices(), std::numeric_limits<double>::infinity());
  std::vector<double> path(mesh.n_vertices(), std::numeric_limits<double>::infinity());
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  path[std::size_t(nucleus.vertex)] = 0;
  queue.push({0.0, nucleus.vertex});
  while (!queue.empty()) {
    const auto [length, v] = queue.top();
    queue.pop();
    if (length > path[std::size_t(v)]) continue;
    const VertexHandle vh(v);
    psi[std::size_t(v)] = (mesh.point(vh) - c).norm() - nucleus.radius;
    for (auto h : mesh.voh_range(vh)) {
      const int w = mesh.to_vertex_handle(h).idx();
      const double next = length + mesh.calc_edge_length(h);
      if (next <= reach && next < path[std::size_t(w)]) {
        path[std::size_t(w)] = next;
        queue.push({next, w});
      }
    }
  }
  return psi;
}

}  // namespace bodyfit
