// The GDAL module (see core/src/gis_module.hpp): rasters and coordinate systems through GDAL/OSR.
#include "gis_module.hpp"
#include "gdal_vector.hpp"

#include <cpl_error.h>
#include <gdal.h>
#include <ogr_srs_api.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

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
  if (const char* wkt = GDALGetProjectionRef(dataset)) grid.crs = wkt;
  return true;
}

/// An OSR spatial reference, released at the end of the scope.
struct Srs {
  OGRSpatialReferenceH h = OSRNewSpatialReference(nullptr);
  ~Srs() { OSRDestroySpatialReference(h); }
  bool parse(const std::string& wkt) {
    CPLPushErrorHandler(CPLQuietErrorHandler);
    const bool ok = OSRSetFromUserInput(h, wkt.c_str()) == OGRERR_NONE;
    CPLPopErrorHandler();
    return ok;
  }
};

bool describe_crs(const std::string& wkt, CrsInfo& info, std::string& error) {
  Srs srs;
  if (!srs.parse(wkt)) {
    error = fmt::format("cannot read the coordinate system (GDAL: {})", CPLGetLastErrorMsg());
    return false;
  }
  info = CrsInfo{};
  if (const char* name = OSRGetName(srs.h)) info.name = name;
  info.geographic = OSRIsGeographic(srs.h) != 0;
  if (OSRIsProjected(srs.h)) info.metres_per_unit = OSRGetLinearUnits(srs.h, nullptr);
  CPLPushErrorHandler(CPLQuietErrorHandler);
  OSRAutoIdentifyEPSG(srs.h);
  CPLPopErrorHandler();
  const char* authority = OSRGetAuthorityName(srs.h, nullptr);
  const char* code = OSRGetAuthorityCode(srs.h, nullptr);
  if (authority && code && std::string(authority) == "EPSG") info.epsg = std::atoi(code);
  return true;
}

bool same_crs(const std::string& a, const std::string& b) {
  Srs x, y;
  return x.parse(a) && y.parse(b) && OSRIsSame(x.h, y.h) != 0;
}

// A GeoTIFF a GIS reads as it is: north-up, the CRS in its GeoKeys, NODATA in its tag, units and
// description on the band and in the dataset's metadata; DEFLATE with the floating-point
// predictor (arrival-time rasters shrink several times).
bool write_geotiff(const std::filesystem::path& file, const HeightGrid& grid, double nodata,
                   const RasterMetadata& metadata, std::string& error) {
  GDALAllRegister();
  GDALDriverH driver = GDALGetDriverByName("GTiff");
  if (!driver) {
    error = "GDAL has no GTiff driver";
    return false;
  }
  Srs srs;
  if (!grid.crs.empty() && !srs.parse(grid.crs)) {
    error = fmt::format("cannot read the coordinate system to write (GDAL: {})", CPLGetLastErrorMsg());
    return false;
  }
  const char* options[] = {"COMPRESS=DEFLATE", "PREDICTOR=3", "TILED=YES", nullptr};
  CPLErrorReset();
  CPLPushErrorHandler(CPLQuietErrorHandler);
  GDALDatasetH dataset = GDALCreate(driver, file.c_str(), int(grid.cols), int(grid.rows), 1, GDT_Float64,
                                    const_cast<char**>(options));
  CPLPopErrorHandler();
  if (!dataset) {
    error = fmt::format("cannot create the GeoTIFF (GDAL: {})", CPLGetLastErrorMsg());
    return false;
  }
  double gt[6] = {grid.x_origin, grid.cell_size, 0, grid.y_origin + double(grid.rows) * grid.cell_size, 0,
                  -grid.cell_size};
  GDALSetGeoTransform(dataset, gt);
  if (!grid.crs.empty()) GDALSetSpatialRef(dataset, srs.h);
  GDALRasterBandH band = GDALGetRasterBand(dataset, 1);
  GDALSetRasterNoDataValue(band, nodata);
  if (!metadata.units.empty()) {
    GDALSetRasterUnitType(band, metadata.units.c_str());
    GDALSetMetadataItem(dataset, "UNITS", metadata.units.c_str(), nullptr);
  }
  if (!metadata.description.empty()) {
    GDALSetDescription(band, metadata.description.c_str());
    GDALSetMetadataItem(dataset, "DESCRIPTION", metadata.description.c_str(), nullptr);
  }
  for (const auto& [key, value] : metadata.items) GDALSetMetadataItem(dataset, key.c_str(), value.c_str(), nullptr);
  std::vector<double> values = grid.heights;
  for (double& v : values)
    if (std::isnan(v) || v == grid.nodata) v = nodata;
  CPLPushErrorHandler(CPLQuietErrorHandler);
  bool ok = GDALRasterIO(band, GF_Write, 0, 0, int(grid.cols), int(grid.rows), values.data(), int(grid.cols),
                         int(grid.rows), GDT_Float64, 0, 0) == CE_None;
  GDALClose(dataset);  // flushes: a full disk shows here
  ok = ok && CPLGetLastErrorType() < CE_Failure;
  CPLPopErrorHandler();
  if (!ok) error = fmt::format("cannot write the GeoTIFF (GDAL: {})", CPLGetLastErrorMsg());
  return ok;
}

const Api kApi{.version = kApiVersion, .read_raster = read_raster, .describe_crs = describe_crs, .same_crs = same_crs,
                  .write_geotiff = write_geotiff,
                  .read_vector = read_vector,
                  .write_polygons = write_polygons};

}  // namespace
}  // namespace bodyfit::gis

extern "C" __attribute__((visibility("default"))) const bodyfit::gis::Api* bodyfit_gis_api() {
  return &bodyfit::gis::kApi;
}
