#include <bodyfit/app/raster_io.hpp>
#include <bodyfit/atomic_file.hpp>
#include <bodyfit/error.hpp>

#include "gis_module.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>

namespace bodyfit {

void write_raster(const std::filesystem::path& file, const HeightGrid& grid, const RasterMetadata& metadata) {
  if (grid.cols == 0 || grid.rows == 0 || grid.heights.size() != grid.rows * grid.cols || !(grid.cell_size > 0))
    throw InputError(fmt::format("{}: cannot write an empty or inconsistent raster", file.string()));
  const double nodata = metadata.nodata.value_or(grid.nodata);
  if (!std::isfinite(nodata)) throw InputError(fmt::format("{}: the NODATA value must be finite", file.string()));
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".asc") {
    HeightGrid out = grid;
    out.nodata = nodata;
    for (double& v : out.heights)
      if (std::isnan(v) || v == grid.nodata) v = nodata;
    write_esri_ascii(file, out);
  } else if (ext == ".tif" || ext == ".tiff") {
    const gis::Api& gis = gis::module_for(file);
    write_atomically_at(file, [&](const std::filesystem::path& temporary) {
      std::string error;
      if (!gis.write_geotiff(temporary, grid, nodata, metadata, error)) throw write_error(file, error);
    });
  } else {
    throw InputError(fmt::format("{}: unknown raster format '{}': expected .asc (ESRI ASCII grid) or .tif/.tiff "
                                 "(GeoTIFF)",
                                 file.string(), ext));
  }
}

HeightGrid read_raster_values(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".asc") return read_esri_ascii_values(file);
  if (ext != ".tif" && ext != ".tiff")
    throw file_error(file, "unknown raster format: expected .asc (ESRI ASCII grid) or .tif/.tiff (GeoTIFF)");
  HeightGrid grid;
  std::string error;
  if (!gis::module_for(file).read_raster(file, grid, error)) throw file_error(file, error);
  return grid;
}

}  // namespace bodyfit
