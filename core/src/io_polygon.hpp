#pragma once
// Polygons of mesh files (OBJ, OFF and PLY faces of more than three corners) as triangles. A fan
// from the first corner overlaps itself on a concave polygon (a pentagon of area 2.5 became 3.5):
// polygons are clipped ear by ear instead, in the plane of their Newell normal (a slightly
// non-planar one is triangulated in that plane).
#include <bodyfit/mesh.hpp>

#include <array>
#include <span>
#include <vector>

namespace bodyfit::io_detail {

/// The polygon with corners `corners` (in order) as triangles, indices into `corners`, turning as
/// the polygon does. Empty when its outline cannot be triangulated: it has no area, or it crosses
/// or touches itself.
std::vector<std::array<int, 3>> triangulate_polygon(std::span<const Vec3> corners);

}  // namespace bodyfit::io_detail
