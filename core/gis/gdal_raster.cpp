// The GDAL module (see core/src/gis_module.hpp): rasters read through GDAL.
#include "gis_module.hpp"

#include <cpl_error.h>
#include <gdal.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace bodyfit::gis {
namespace {

bool read_raster(const std::filesystem::path& file, HeightGrid& grid, std::string& error) {
  GDALAllRegister();
  CPLPushErrorHandler(CPLQuietErrorHandler);
  GDALDatasetH dataset = GDALOpen(file.string().c_str(), GA_ReadOnly);
  CPLPopErrorHandler();
  if (!dataset) {
    error = fmt::format("cannot open as a raster (GDAL: {})", CPLGetLastErrorMsg());
    return false;
  }
  struct Closer {
    GDALDatasetH d;
    ~Closer() { GDALClose(d); }
  } closer{dataset};
  auto fail = [&](std::string what) {
    error = std::move(what);
    return false;
  };
  if (GDALGetRasterCount(dataset) < 1) return fail("the raster has no band");
  double gt[6];
  if (GDALGetGeoTransform(dataset, gt) != CE_None) return fail("the raster has no georeferencing (geotransform)");
  if (gt[2] != 0 || gt[4] != 0) return fail("rotated rasters are not supported");
  if (std::abs(std::abs(gt[1]) - std::abs(gt[5])) > 1e-9 * std::abs(gt[1]) || gt[1] <= 0)
    return fail(fmt::format("non-square or mirrored cells ({} × {}) are not supported", gt[1], gt[5]));
  grid = HeightGrid{};
  grid.cols = std::size_t(GDALGetRasterXSize(dataset));
  grid.rows = std::size_t(GDALGetRasterYSize(dataset));
  grid.cell_size = gt[1];
  grid.x_origin = gt[0];
  grid.y_origin = gt[5] < 0 ? gt[3] + double(grid.rows) * gt[5] : gt[3];
  GDALRasterBandH band = GDALGetRasterBand(dataset, 1);
  int has_nodata = 0;
  const double nodata = GDALGetRasterNoDataValue(band, &has_nodata);
  if (has_nodata) grid.nodata = nodata;
  grid.heights.resize(grid.rows * grid.cols);
  if (GDALRasterIO(band, GF_Read, 0, 0, int(grid.cols), int(grid.rows), grid.heights.data(), int(grid.cols),
                   int(grid.rows), GDT_Float64, 0, 0) != CE_None)
    return fail(fmt::format("cannot read band 1 (GDAL: {})", CPLGetLastErrorMsg()));
  if (gt[5] > 0)  // south-up raster: store north first like an ESRI grid
    for (std::size_t r = 0; r < grid.rows / 2; ++r)
      std::swap_ranges(grid.heights.begin() + long(r * grid.cols), grid.heights.begin() + long((r + 1) * grid.cols),
                       grid.heights.begin() + long((grid.rows - 1 - r) * grid.cols));
  return true;
}

const Api kApi{.version = kApiVersion, .read_raster = read_raster};

}  // namespace
}  // namespace bodyfit::gis

extern "C" __attribute__((visibility("default"))) const bodyfit::gis::Api* bodyfit_gis_api() {
  return &bodyfit::gis::kApi;
}
