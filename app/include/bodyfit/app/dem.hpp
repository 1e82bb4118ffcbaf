#pragma once
// Rasters of heights and values (HeightGrid) and reading DEMs: ESRI ASCII grids parsed here, GeoTIFF
// and coordinate systems through the GDAL module.
#include <bodyfit/mesh.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace bodyfit {

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

/// Whether two rasters have the same cells: size, origin and cell size.
bool same_frame(const HeightGrid& a, const HeightGrid& b);

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
/// Errors name the file and line. As for every DEM read (GeoTIFF and landscape too), a cell holding
/// a common NODATA marker its header does not declare (−9999, −32768, −3.4e38…) is NODATA, and a
/// cell standing alone far off its neighbours (a spike or a pit) takes their median: both with a
/// warning naming the cells.
HeightGrid read_esri_ascii(const std::filesystem::path& file);
/// The values of an ESRI ASCII grid as they are (NODATA as grid.nodata), without a terrain's checks: for rasters
/// of results such as arrival times, where NODATA means "never reached", not a missing height.
HeightGrid read_esri_ascii_values(const std::filesystem::path& file);
void write_esri_ascii(const std::filesystem::path& file, const HeightGrid& grid);
/// GeoTIFF through GDAL; throws InputError when bodyfit was built without GDAL.
HeightGrid read_geotiff(const std::filesystem::path& file);
/// Dispatch on extension (.asc, .tif/.tiff, .lcp: a FARSITE landscape's elevation); NODATA cells
/// are kept as they are (a raster whose cells are all NODATA is an error). A geographic raster is
/// refused, or reprojected on request.
HeightGrid read_dem(const std::filesystem::path& file, const DemReadOptions& options = {});
/// A raster of values that are not heights (fuel codes, winds, moistures, a mask): .asc or
/// .tif/.tiff, read and reprojected as read_dem does, but with none of a terrain's screening: no
/// undeclared NODATA marker, no lone cell taken for a damaged one (a lone water cell among timber
/// is data), no range of heights. The model checks the values against what they mean.
HeightGrid read_raster(const std::filesystem::path& file, const DemReadOptions& options = {});

/// The bands of a FARSITE landscape (.lcp), in their order in the file.
enum class LandscapeBand {
  elevation = 1,
  slope,
  aspect,
  fuel,
  canopy_cover,
  canopy_height,
  canopy_base_height,
  canopy_bulk_density
};
/// A band of a FARSITE landscape through GDAL, in SI units as its header declares them: elevation
/// and canopy heights in m (from m, ft, m×10 or ft×10), canopy cover in %, bulk density in kg/m³
/// (from kg/m³, lb/ft³, kg/m³×100 or lb/ft³×1000), fuel codes as they are; NODATA kept; a unit it
/// does not know is an error naming the file and band. Reprojected like read_dem on request.
HeightGrid read_landscape_band(const std::filesystem::path& file, LandscapeBand band, const DemReadOptions& options = {});
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

}  // namespace bodyfit
