#pragma once
// Barriers of the fire model (roads, rivers, fuel breaks, lakes): lines and polygons of a vector
// layer where the fire does not spread. The rule is on the mesh, recomputed on every state from its
// vertices (the mesh changes at every remesh): R = 0 at every vertex within barrier_reach() of a
// barrier's lines or inside one of its polygons, so that the advection cannot carry the front
// across (docs/reference/fire_model.md, "Barriers", has the argument).
#include <bodyfit/mesh.hpp>
#include <bodyfit/app/plan_geometry.hpp>
#include <bodyfit/velocity_model.hpp>

#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace bodyfit::fire {

struct BarrierOptions {
  std::filesystem::path file{};  ///< any OGR vector layer: lines, polygons (points: disks of the reach)
  std::string layer{};           ///< its name in a multi-layer file ("": the first)
  double width = 0;            ///< metres; the band where R = 0 is at least this wide
};

/// The barriers' segments in plan view, bucketed on a square grid for distance queries.
class Barriers {
 public:
  Barriers() = default;
  /// The layer of `options`, in the surface's coordinate system: a layer in another projected
  /// system is an InputError naming both files and both systems; one in the DEM's own system when
  /// the case reprojected the DEM is transformed to the surface's; one without a system is taken as
  /// it is, with a warning when the surface has one.
  static Barriers read(const BarrierOptions& options, const SurfaceSource& surface);

  bool empty() const { return segments_.empty(); }
  double width() const { return width_; }
  std::size_t segment_count() const { return segments_.size(); }
  /// Whether (x, y) is within `reach` of a barrier's line (a polygon's boundary included) or
  /// inside one of its polygons.
  bool blocks(double x, double y, double reach) const;

 private:
  struct Segment {
    PlanPoint a, b;
    int polygon = -1;  ///< the polygon whose ring it is on, -1 for a line
  };
  void add_geometry(const PlanGeometry& geometry);
  void build_grid(double cell) const;
  bool inside_polygon(double x, double y) const;

  std::vector<Segment> segments_;
  int polygon_count_ = 0;
  double width_ = 0;
  // The grid is sized to the reach of the first query, and resized when the reach changes much.
  mutable double cell_ = 0;
  mutable double x0_ = 0, y0_ = 0;
  mutable long nx_ = 0, ny_ = 0;
  mutable std::vector<std::vector<int>> cells_;
  mutable std::vector<char> parity_;
};

/// The half-width of the band of vertices where a barrier stops the fire on a mesh whose longest
/// plan-view edge is `longest_edge`: max(width / 2, 2·longest_edge). Why 2: see barriers.cpp.
double barrier_reach(const Barriers& barriers, double longest_edge);

/// The longest edge of `mesh` in plan view (x, y).
double longest_plan_edge(const SurfaceMesh& mesh);

/// stopped[v] = 1 at the vertices `active` (every vertex when empty) that a barrier blocks at
/// `reach`, 0 at the other active ones; sized to the mesh.
void mark_barrier_vertices(const SurfaceMesh& mesh, const Barriers& barriers, double reach,
                           std::span<const int> active, std::vector<char>& stopped);

}  // namespace bodyfit::fire
