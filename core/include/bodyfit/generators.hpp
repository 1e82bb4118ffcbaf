#pragma once
// Mesh generators: geodesic spheres, flat squares, procedural terrains and terrains from DEM rasters.
#include <bodyfit/mesh.hpp>

#include <cstdint>
#include <filesystem>
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
  /// Bilinear interpolation at (x, y), cell-centre registered; clamps outside the grid.
  double sample(double x, double y) const;
};

/// ESRI ASCII grid (.asc). Errors name the file and line.
HeightGrid read_esri_ascii(const std::filesystem::path& file);
/// The values of an ESRI ASCII grid as they are, NODATA cells kept (as grid.nodata): for rasters
/// of results such as arrival times, where NODATA means "never reached", not a missing height.
HeightGrid read_esri_ascii_values(const std::filesystem::path& file);
void write_esri_ascii(const std::filesystem::path& file, const HeightGrid& grid);
/// GeoTIFF through GDAL; throws InputError when bodyfit was built without GDAL.
HeightGrid read_geotiff(const std::filesystem::path& file);
/// Dispatch on extension (.asc, .tif/.tiff).
HeightGrid read_dem(const std::filesystem::path& file);
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
/// Terrain from a DEM raster at edge length h (0: the raster's cell size).
SurfaceMesh make_terrain_from_grid(const HeightGrid& grid, double h = 0);

}  // namespace bodyfit
