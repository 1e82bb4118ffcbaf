#pragma once
// Geometry in plan view (x, y): the points, lines and polygons of GIS layers, their areas and
// lengths, and the outline of a mesh region as polygons (a terrain seen from above).
#include <bodyfit/mesh.hpp>

#include <array>
#include <vector>

namespace bodyfit {

using PlanPoint = std::array<double, 2>;
/// An open path, or a ring when it is a polygon's (not closed: the last point is not the first).
using PlanPath = std::vector<PlanPoint>;

/// rings[0] is the outer ring, the others its holes. region_outline orients outer rings
/// counter-clockwise and holes clockwise (the OGC/GeoJSON convention).
struct PlanPolygon {
  std::vector<PlanPath> rings{};
};

/// Points, lines and polygons together: one feature of a vector layer (its multi-parts flattened).
struct PlanGeometry {
  std::vector<PlanPoint> points{};
  std::vector<PlanPath> lines{};
  std::vector<PlanPolygon> polygons{};
  bool empty() const { return points.empty() && lines.empty() && polygons.empty(); }
};

/// Shoelace area of a ring: positive when counter-clockwise.
double signed_ring_area(const PlanPath& ring);
/// Area of a polygon: |outer| − Σ|holes|.
double polygon_area(const PlanPolygon& polygon);
/// Length of a path; closed = true adds the edge from its last point to its first (a ring).
double path_length(const PlanPath& path, bool closed);
/// Length of every ring of a polygon.
double polygon_perimeter(const PlanPolygon& polygon);
/// Whether (x, y) is inside the ring (even-odd rule; points on the ring may go either way).
bool inside_ring(const PlanPath& ring, double x, double y);
/// Distance from (x, y) to the segment ab (a point when a = b).
double distance_to_segment(const PlanPoint& a, const PlanPoint& b, double x, double y);
/// Distance from (x, y) to a path (closed: to the ring). A single point is a path too.
double distance_to_path(const PlanPath& path, double x, double y, bool closed);
/// Signed distance to a polygon's boundary: negative inside (inside the outer ring, outside the holes).
double signed_distance_to_polygon(const PlanPolygon& polygon, double x, double y);

/// The faces labelled `region` seen from above: the boundary of their union, as polygons with
/// holes. Each boundary loop of the region is traced with the region on its left; at a vertex where
/// the region touches itself the loops separate (two parts meeting at a point stay two polygons).
/// Loops of positive signed area are outer rings (counter-clockwise), the others holes (clockwise),
/// each given to the smallest outer ring that contains it. Meant for height fields (terrains), whose
/// projection is one-to-one; coordinates are the vertices' x and y.
std::vector<PlanPolygon> region_outline(const SurfaceMesh& mesh, int region = kInside);
/// Which cells of a grid have their centre inside the polygons (even-odd over every ring, so holes
/// are out): cell-centred, `cols` × `rows` cells of `cell_size`, (x_origin, y_origin) the lower-left
/// corner, rows from north (row 0) to south, as GridField. One scanline per row.
std::vector<bool> cells_inside(const std::vector<PlanPolygon>& polygons, std::size_t cols, std::size_t rows,
                               double x_origin, double y_origin, double cell_size);
/// Σ over the faces labelled `region` of their projected (x, y) areas.
double region_plan_area(const SurfaceMesh& mesh, int region = kInside);

}  // namespace bodyfit
