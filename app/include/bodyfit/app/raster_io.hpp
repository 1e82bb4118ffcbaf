#pragma once
// Rasters written for GIS users: an ESRI ASCII grid with its .prj, or a GeoTIFF (through the GDAL
// module) that carries its coordinate system, NODATA value, units and description, so QGIS or
// gdal_contour can use it with no further step.
#include <bodyfit/app/terrain.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace bodyfit {

/// What a raster's values are, for its readers. Every member has a default, so designated
/// initializers may name any subset ({.units = "s"}) without -Wmissing-field-initializers.
struct RasterMetadata {
  std::string units{};      ///< of the values, e.g. "s" or "m/s" ("" when none)
  std::string description{};  ///< e.g. "fire arrival time, seconds after 2026-07-14T13:00:00Z"
  /// The NODATA value written (cells that are NaN or equal grid.nodata become it); default grid.nodata.
  std::optional<double> nodata{};
  /// Further KEY=value items of the GeoTIFF's metadata (e.g. {"START_TIME", "2026-07-14T13:00:00Z"});
  /// an ESRI grid has no place for them.
  std::vector<std::pair<std::string, std::string>> items{};
};

/// Write `grid` to `file`, in the format its extension names: `.asc` an ESRI ASCII grid (and a
/// .prj beside it when grid.crs is known), `.tif`/`.tiff` a GeoTIFF through GDAL (64-bit floats,
/// DEFLATE-compressed, the CRS, NODATA, units and description in its tags and metadata). Written
/// atomically (a temporary beside it, then renamed): `file` is never left half-written. Throws
/// InputError for another extension, an inconsistent grid or a bodyfit built without GDAL (.tif),
/// IoError when the file cannot be written.
void write_raster(const std::filesystem::path& file, const HeightGrid& grid, const RasterMetadata& metadata = {});

/// A raster of values as written by write_raster (`.asc` + its .prj, or a GeoTIFF through GDAL),
/// NODATA cells kept as grid.nodata, without a terrain's checks: for results such as arrival times,
/// where NODATA means "never reached". InputError naming the file when it cannot be read.
HeightGrid read_raster_values(const std::filesystem::path& file);

}  // namespace bodyfit
