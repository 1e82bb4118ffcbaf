#pragma once
// Terrains: the procedural landscape and surfaces made from DEM rasters (dem.hpp).
#include <bodyfit/app/dem.hpp>
#include <bodyfit/mesh.hpp>

#include <cstdint>

namespace bodyfit {

struct TerrainOptions {
  double extent = 50000;     ///< side of the square domain, metres
  double h = 400;            ///< target edge length, metres
  std::uint64_t seed = 7;    ///< the landscape is a deterministic function of the seed
  double max_height = 2500;  ///< metres
  double feature_size = 8000;///< horizontal scale of the largest hills, metres
};
/// Procedural landscape over [0, extent]², smooth seeded noise heights ≥ 0, an open surface with
/// one boundary loop, triangulated with near-equilateral triangles of edge ≈ h.
SurfaceMesh make_terrain(const TerrainOptions& options = {});
/// The height function of the procedural landscape (the surface's exact z(x, y)).
double terrain_height(const TerrainOptions& options, double x, double y);
/// What the NODATA cells of a DEM become in its terrain.
enum class NodataMode {
  hole,  ///< no terrain: the surface covers the valid cells only, its boundary follows the mask
  fill,  ///< the nearest valid height (fill_nodata): the surface covers the whole rectangle
};
struct GridTerrainOptions {
  double h = 0;                    ///< target edge length (0: the raster's cell size)
  NodataMode nodata = NodataMode::hole;
  /// hole: connected pieces of the surface smaller than this (plan-view area, m²) are dropped;
  /// < 0: 16·h² (a square of 4 × 4 edges).
  double min_island_area = -1;
};
/// Terrain from a DEM raster: a lattice of near-equilateral triangles of edge ≈ h over the raster's
/// rectangle, heights by bilinear interpolation over valid cells. With NODATA as holes, a lattice
/// triangle is kept when its vertices, edge midpoints and centroid all lie over valid cells (closed
/// squares); then vertices where several fans of triangles meet keep only their largest fan (the
/// surface is a manifold) and pieces below min_island_area are dropped. An InputError when nothing
/// is left.
SurfaceMesh make_terrain_from_grid(const HeightGrid& grid, const GridTerrainOptions& options);
/// Terrain from a DEM raster at edge length h (0: the raster's cell size), NODATA as holes.
SurfaceMesh make_terrain_from_grid(const HeightGrid& grid, double h = 0);

}  // namespace bodyfit
