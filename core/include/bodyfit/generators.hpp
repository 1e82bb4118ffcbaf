#pragma once
// Mesh generators: geodesic spheres, flat squares, procedural terrains and terrains from DEM rasters.
#include <bodyfit/mesh.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace bodyfit {

struct SphereOptions {
  std::size_t faces = 20480;  ///< target face count (≥ 20); the result is within ±10 %
  double radius = 1.0;
  Vec3 center{0, 0, 0};
};
/// Sphere of about `faces` triangles (within ±10 %), all vertices exactly on the sphere, minimum
/// triangle quality ≥ 0.7, outward orientation. The closest geodesic count is used: class I
/// (subdivided icosahedron, frequency k, 20k² faces, exact for 20k²) or Goldberg–Coxeter class II/III
/// (20(a² + ab + b²) faces); counts with no geodesic sphere within 10 % (some below 300) get a
/// Delaunay triangulation of N/2 + 2 points spread by Coulomb repulsion.
SurfaceMesh make_sphere(const SphereOptions& options = {});

struct PlaneOptions {
  double size = 2;  ///< side of the square [-size/2, size/2]² at z = 0
  double h = 0.05;  ///< target edge length
};
/// A flat open square triangulated with rows of near-equilateral triangles of edge ≈ h (odd rows
/// shifted by half a cell; the end cells of those rows are the worst triangles, quality > 0.5):
/// one boundary loop, normals +z, region label 2. Throws InputError for a non-positive size or h.
SurfaceMesh make_plane(const PlaneOptions& options = {});

/// A raster of heights: rows from north (top) to south, like an ESRI ASCII grid.
struct HeightGrid {
  std::size_t cols = 0, rows = 0;
  double x_origin = 0, y_origin = 0;  ///< lower-left corner of the lower-left cell (metres)
  double cell_size = 1;               ///< metres
  double nodata = -9999;
  std::vector<double> heights;        ///< rows × cols, row 0 is the northernmost
  /// The coordinate system as WKT: a GeoTIFF's, or the .prj beside an .asc (written beside it too);
  /// "" when unknown. read_dem refuses a geographic one (degrees are not metres).
  std::string crs;
  double at(std::size_t row, std::size_t col) const { return heights[row * cols + col]; }
  /// Whether the cell holds data (neither NaN nor the NODATA value).
  bool valid(std::size_t row, std::size_t col) const;
  /// Bilinear interpolation at (x, y), cell-centre registered; clamps outside the grid. NODATA
  /// cells take no part (the weights of the valid ones are renormalised); NaN when the four
  /// cells around (x, y) are all NODATA.
  double sample(double x, double y) const;
};

/// The NODATA cells of a raster (NaN or the NODATA value).
std::size_t count_nodata(const HeightGrid& grid);
/// Gives every NODATA cell the value of its nearest valid cell (breadth-first over the
/// 8-neighbourhood from all valid cells at once, ties by scan order); returns how many it filled.
/// A raster without any valid cell is left as it is.
std::size_t fill_nodata(HeightGrid& grid);

/// What read_dem does with a raster in degrees (a geographic coordinate system).
enum class Reprojection {
  none,  ///< refuse it, naming the UTM zone to project it to
  utm,   ///< warp it to the WGS 84 / UTM zone of its centre (GDAL's warper, bilinear, NODATA kept)
};
/// How a warped raster takes its values from the source's cells.
enum class Resampling {
  bilinear,  ///< heights, wind components
  nearest,   ///< codes (fuel classes): no value that is in no source cell
};
struct DemReadOptions {
  Reprojection reproject = Reprojection::none;
  /// With reproject = utm: the projected system to warp to (WKT with an EPSG code, e.g. that of the
  /// case's surface), instead of the UTM zone of the raster's centre.
  std::string target_crs{};
  Resampling resampling = Resampling::bilinear;
};

/// ESRI ASCII grid (.asc) as a terrain: NODATA kept, some data and plausible heights required.
/// Errors name the file and line.
HeightGrid read_esri_ascii(const std::filesystem::path& file);
/// The values of an ESRI ASCII grid as they are (NODATA as grid.nodata), without a terrain's checks: for rasters
/// of results such as arrival times, where NODATA means "never reached", not a missing height.
HeightGrid read_esri_ascii_values(const std::filesystem::path& file);
void write_esri_ascii(const std::filesystem::path& file, const HeightGrid& grid);
/// GeoTIFF through GDAL; throws InputError when bodyfit was built without GDAL.
HeightGrid read_geotiff(const std::filesystem::path& file);
/// Dispatch on extension (.asc, .tif/.tiff); NODATA cells are kept as they are (a raster whose
/// cells are all NODATA is an error). A geographic raster is refused, or reprojected on request.
HeightGrid read_dem(const std::filesystem::path& file, const DemReadOptions& options = {});
/// The coordinate system of the terrain read_dem(file, options) makes (WKT, "" when unknown), and
/// the raster's own when read_dem reprojects it ("" otherwise).
struct DemCoordinates {
  std::string crs{};
  std::string reprojected_from{};
};
DemCoordinates dem_coordinates(const std::filesystem::path& file, const DemReadOptions& options = {});
/// An InputError naming both files when two rasters of one case have different coordinate systems
/// (an unknown one, "", matches any).
void require_same_crs(const HeightGrid& a, const std::filesystem::path& file_a, const HeightGrid& b,
                      const std::filesystem::path& file_b);

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
