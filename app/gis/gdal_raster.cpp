// The GDAL module (see app/src/gis_module.hpp): rasters and coordinate systems through GDAL/OSR.
#include "gis_module.hpp"
#include "gdal_vector.hpp"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <gdal.h>
#include <gdal_alg.h>
#include <gdalwarper.h>
#include <ogr_srs_api.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

namespace bodyfit::gis {
namespace {

bool read_raster_band(const std::filesystem::path& file, int band_number, HeightGrid& grid, std::string& unit,
                      std::string& error) {
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
  if (band_number < 1 || band_number > GDALGetRasterCount(dataset))
    return fail(fmt::format("the raster has {} band(s), not a band {}", GDALGetRasterCount(dataset), band_number));
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
  GDALRasterBandH band = GDALGetRasterBand(dataset, band_number);
  // The unit: a FARSITE landscape names it in "<BAND>_UNIT_NAME" metadata, others in the unit type.
  unit.clear();
  if (char** items = GDALGetMetadata(band, nullptr))
    for (int i = 0; items[i]; ++i) {
      const std::string item = items[i];
      const std::size_t equals = item.find('=');
      if (equals != std::string::npos && item.substr(0, equals).ends_with("_UNIT_NAME")) unit = item.substr(equals + 1);
    }
  if (unit.empty())
    if (const char* type = GDALGetRasterUnitType(band)) unit = type;
  int has_nodata = 0;
  const double nodata = GDALGetRasterNoDataValue(band, &has_nodata);
  if (has_nodata) grid.nodata = nodata;
  grid.heights.resize(grid.rows * grid.cols);
  if (GDALRasterIO(band, GF_Read, 0, 0, int(grid.cols), int(grid.rows), grid.heights.data(), int(grid.cols),
                   int(grid.rows), GDT_Float64, 0, 0) != CE_None)
    return fail(fmt::format("cannot read band {} (GDAL: {})", band_number, CPLGetLastErrorMsg()));
  if (gt[5] > 0)  // south-up raster: store north first like an ESRI grid
    for (std::size_t r = 0; r < grid.rows / 2; ++r)
      std::swap_ranges(grid.heights.begin() + long(r * grid.cols), grid.heights.begin() + long((r + 1) * grid.cols),
                       grid.heights.begin() + long((grid.rows - 1 - r) * grid.cols));
  if (const char* wkt = GDALGetProjectionRef(dataset)) grid.crs = wkt;
  return true;
}

bool read_raster(const std::filesystem::path& file, HeightGrid& grid, std::string& error) {
  std::string unit;
  return read_raster_band(file, 1, grid, unit, error);
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
  const char* authority = OSRGetAuthorityName(srs.h, nullptr);
  const char* code = OSRGetAuthorityCode(srs.h, nullptr);
  if (authority && code && std::string(authority) == "EPSG") {
    info.epsg = std::atoi(code);
  } else {
    // An ESRI .prj carries no authority: the EPSG system PROJ finds equivalent, when it is sure.
    int count = 0;
    int* confidence = nullptr;
    OGRSpatialReferenceH* matches = OSRFindMatches(srs.h, nullptr, &count, &confidence);
    if (matches && count > 0 && confidence && confidence[0] >= 90) {
      const char* match_authority = OSRGetAuthorityName(matches[0], nullptr);
      const char* match_code = OSRGetAuthorityCode(matches[0], nullptr);
      if (match_authority && match_code && std::string(match_authority) == "EPSG") info.epsg = std::atoi(match_code);
    }
    if (matches) OSRFreeSRSArray(matches);
    CPLFree(confidence);
  }
  CPLPopErrorHandler();
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

/// A GDAL dataset, closed at the end of the scope.
struct Dataset {
  GDALDatasetH h = nullptr;
  ~Dataset() {
    if (h) GDALClose(h);
  }
};

/// x rounded to two significant figures (a cell size of 187.3 m becomes 190 m).
double two_significant(double x) {
  const double unit = std::pow(10.0, std::floor(std::log10(x)) - 1);
  return std::round(x / unit) * unit;
}

bool warp_raster(const HeightGrid& in, int epsg, double cell_size, Resampling resampling, HeightGrid& out,
                 std::string& error) {
  auto fail = [&](std::string what) {
    error = fmt::format("{} (GDAL: {})", what, CPLGetLastErrorMsg());
    return false;
  };
  GDALAllRegister();
  GDALDriverH mem = GDALGetDriverByName("MEM");
  if (!mem) return fail("GDAL has no in-memory driver");
  // The source: the grid as it was read, NaN cells marked with the NODATA value.
  Dataset source{GDALCreate(mem, "", int(in.cols), int(in.rows), 1, GDT_Float64, nullptr)};
  if (!source.h) return fail("cannot create an in-memory raster");
  double source_transform[6] = {in.x_origin, in.cell_size, 0, in.y_origin + double(in.rows) * in.cell_size, 0,
                                -in.cell_size};
  GDALSetGeoTransform(source.h, source_transform);
  if (GDALSetProjection(source.h, in.crs.c_str()) != CE_None) return fail("cannot use the raster's coordinate system");
  std::vector<double> values = in.heights;
  for (double& value : values)
    if (std::isnan(value)) value = in.nodata;
  GDALRasterBandH source_band = GDALGetRasterBand(source.h, 1);
  GDALSetRasterNoDataValue(source_band, in.nodata);
  if (GDALRasterIO(source_band, GF_Write, 0, 0, int(in.cols), int(in.rows), values.data(), int(in.cols), int(in.rows),
                   GDT_Float64, 0, 0) != CE_None)
    return fail("cannot fill an in-memory raster");

  Srs target;
  if (OSRImportFromEPSG(target.h, epsg) != OGRERR_NONE) return fail(fmt::format("unknown EPSG code {}", epsg));
  char* target_text = nullptr;
  OSRExportToWkt(target.h, &target_text);
  const std::string target_wkt = target_text ? target_text : "";
  CPLFree(target_text);

  // The target lattice: GDAL's suggested cell size rounded; the extent of the source's outline
  // (sampled every 1/64 of each side: GDAL's suggested extent is rounded to whole cells, and may
  // cut a corner off), its corners snapped outward to multiples of the cell.
  void* suggest = GDALCreateGenImgProjTransformer(source.h, in.crs.c_str(), nullptr, target_wkt.c_str(), FALSE, 0, 1);
  if (!suggest) return fail("no transformation between the coordinate systems");
  double suggested[6];
  int suggested_cols = 0, suggested_rows = 0;
  const CPLErr suggested_ok =
      GDALSuggestedWarpOutput(source.h, GDALGenImgProjTransform, suggest, suggested, &suggested_cols, &suggested_rows);
  constexpr int kSamples = 64;
  std::vector<double> xs, ys, zs;
  for (int i = 0; i <= kSamples; ++i) {
    const double t = double(i) / kSamples, along_x = t * double(in.cols), along_y = t * double(in.rows);
    for (auto [px, py] : {std::pair{along_x, 0.0}, std::pair{along_x, double(in.rows)}, std::pair{0.0, along_y},
                          std::pair{double(in.cols), along_y}})
      xs.push_back(px), ys.push_back(py);
  }
  zs.assign(xs.size(), 0.0);
  std::vector<int> transformed(xs.size(), 0);
  GDALGenImgProjTransform(suggest, FALSE, int(xs.size()), xs.data(), ys.data(), zs.data(), transformed.data());
  GDALDestroyGenImgProjTransformer(suggest);
  if (suggested_ok != CE_None) return fail("cannot find the raster's extent in the target system");
  double west = HUGE_VAL, south = HUGE_VAL, east = -HUGE_VAL, north = -HUGE_VAL;
  for (std::size_t i = 0; i < xs.size(); ++i)
    if (transformed[i]) {
      west = std::min(west, xs[i]), east = std::max(east, xs[i]);
      south = std::min(south, ys[i]), north = std::max(north, ys[i]);
    }
  if (!(west < east && south < north)) return fail("cannot transform the raster's outline to the target system");
  const double cell = cell_size > 0 ? cell_size : two_significant(suggested[1]);
  out = HeightGrid{};
  out.cell_size = cell;
  out.x_origin = std::floor(west / cell) * cell;
  out.y_origin = std::floor(south / cell) * cell;
  out.cols = std::size_t(std::ceil((east - out.x_origin) / cell));
  out.rows = std::size_t(std::ceil((north - out.y_origin) / cell));
  out.nodata = in.nodata;
  out.crs = target_wkt;
  if (double(out.cols) * double(out.rows) > 4e8) return fail("the reprojected raster would be too large");

  Dataset target_data{GDALCreate(mem, "", int(out.cols), int(out.rows), 1, GDT_Float64, nullptr)};
  if (!target_data.h) return fail("cannot create an in-memory raster");
  double target_transform[6] = {out.x_origin, cell, 0, out.y_origin + double(out.rows) * cell, 0, -cell};
  GDALSetGeoTransform(target_data.h, target_transform);
  GDALSetProjection(target_data.h, target_wkt.c_str());
  GDALRasterBandH target_band = GDALGetRasterBand(target_data.h, 1);
  GDALSetRasterNoDataValue(target_band, out.nodata);

  GDALWarpOptions* options = GDALCreateWarpOptions();
  options->hSrcDS = source.h;
  options->hDstDS = target_data.h;
  options->nBandCount = 1;
  options->panSrcBands = static_cast<int*>(CPLMalloc(sizeof(int)));
  options->panDstBands = static_cast<int*>(CPLMalloc(sizeof(int)));
  options->panSrcBands[0] = options->panDstBands[0] = 1;
  options->padfSrcNoDataReal = static_cast<double*>(CPLMalloc(sizeof(double)));
  options->padfDstNoDataReal = static_cast<double*>(CPLMalloc(sizeof(double)));
  options->padfSrcNoDataReal[0] = options->padfDstNoDataReal[0] = in.nodata;
  options->eResampleAlg = resampling == Resampling::nearest ? GRA_NearestNeighbour : GRA_Bilinear;
  options->papszWarpOptions = CSLSetNameValue(options->papszWarpOptions, "INIT_DEST", "NO_DATA");
  options->pTransformerArg =
      GDALCreateGenImgProjTransformer(source.h, in.crs.c_str(), target_data.h, target_wkt.c_str(), FALSE, 0, 1);
  options->pfnTransformer = GDALGenImgProjTransform;
  bool warped = false;
  if (options->pTransformerArg) {
    GDALWarpOperationH operation = GDALCreateWarpOperation(options);
    if (operation) {
      warped = GDALChunkAndWarpImage(operation, 0, 0, int(out.cols), int(out.rows)) == CE_None;
      GDALDestroyWarpOperation(operation);
    }
    GDALDestroyGenImgProjTransformer(options->pTransformerArg);
  }
  GDALDestroyWarpOptions(options);
  if (!warped) return fail("the warp failed");
  out.heights.resize(out.rows * out.cols);
  if (GDALRasterIO(target_band, GF_Read, 0, 0, int(out.cols), int(out.rows), out.heights.data(), int(out.cols),
                   int(out.rows), GDT_Float64, 0, 0) != CE_None)
    return fail("cannot read the warped raster");
  return true;
}

const Api kApi{.version = kApiVersion,
               .read_raster = read_raster,
               .describe_crs = describe_crs,
               .same_crs = same_crs,
               .write_geotiff = write_geotiff,
               .read_vector = read_vector,
               .write_polygons = write_polygons,
               .warp_raster = warp_raster,
               .transform_points = transform_points,
               .read_raster_band = read_raster_band};

}  // namespace
}  // namespace bodyfit::gis

extern "C" __attribute__((visibility("default"))) const bodyfit::gis::Api* bodyfit_gis_api() {
  return &bodyfit::gis::kApi;
}
