#pragma once
// Self-intersections of a triangulated surface: pairs of faces that meet other than along their
// shared vertices and edges (a uniform grid of cells about twice the mean edge: about linear).
#include <bodyfit/mesh.hpp>

#include <cstddef>
#include <limits>
#include <span>
#include <utility>
#include <vector>

namespace bodyfit {

/// The intersecting pairs of faces (face indices, lower first, sorted; deleted faces are not looked
/// at), at most `limit` of them. Two
/// faces sharing a vertex intersect when they overlap beyond it; sharing an edge, when folded flat
/// onto each other. Tolerance 1e-10 of the bounding box's diagonal.
std::vector<std::pair<int, int>> self_intersections(const SurfaceMesh& surface,
                                                    std::size_t limit = std::numeric_limits<std::size_t>::max());

/// The same, among the pairs with at least one of `faces` (face indices, in any order, repeats
/// allowed): the crossings near a change, at the cost of those faces' neighbourhoods rather than
/// the whole surface's grid.
std::vector<std::pair<int, int>> self_intersections_near(const SurfaceMesh& surface, std::span<const int> faces,
                                                         std::size_t limit = std::numeric_limits<std::size_t>::max());

}  // namespace bodyfit
