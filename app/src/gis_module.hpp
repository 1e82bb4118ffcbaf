#pragma once
// Everything bodyfit does through GDAL lives in a module loaded on first use (app/gis/,
// libbodyfit_gis.so in <libdir>/bodyfit/ beside libbodyfit_core): linked into the core, GDAL made
// every command map its ~110 libraries at start (0.1 s of each `bodyfit distance` or `remesh`
// call, which never reads a raster). The module is part of bodyfit, built with it from the same
// sources and headers, so C++ types cross the boundary; the table of entry points grows as the
// GIS functions do, under one exported symbol.
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/app/raster_io.hpp>
#include <bodyfit/app/vector_io.hpp>

#include <cstdint>
#include <filesystem>
#include <string>

namespace bodyfit::gis {

inline constexpr std::uint32_t kApiVersion = 5;

/// What bodyfit needs to know of a coordinate system.
struct CrsInfo {
  std::string name;          ///< e.g. "WGS 84 / UTM zone 32N"
  bool geographic = false;   ///< longitude/latitude in degrees
  double metres_per_unit = 1;  ///< of a projected system's linear unit
  int epsg = 0;              ///< its EPSG code when it has one
};

/// The module's entry points.
struct Api {
  std::uint32_t version = kApiVersion;
  /// Band 1 of a north-up raster with square cells into `grid` (NODATA cells as they are, its
  /// coordinate system as WKT in grid.crs); false with `error` set when GDAL cannot read the file.
  bool (*read_raster)(const std::filesystem::path& file, HeightGrid& grid, std::string& error) = nullptr;
  /// A coordinate system given as WKT (ESRI's .prj dialect included); false with `error` set when
  /// it cannot be understood.
  bool (*describe_crs)(const std::string& wkt, CrsInfo& info, std::string& error) = nullptr;
  /// Whether two WKT texts describe the same coordinate system.
  bool (*same_crs)(const std::string& a, const std::string& b) = nullptr;
  /// `grid` as a GeoTIFF at `file` (created there: the caller makes it atomic), with the CRS of
  /// grid.crs, the NODATA value `nodata` (NaN cells and grid.nodata cells become it) and the
  /// metadata; false with `error` set when GDAL cannot write it. (version 2)
  bool (*write_geotiff)(const std::filesystem::path& file, const HeightGrid& grid, double nodata,
                        const RasterMetadata& metadata, std::string& error) = nullptr;
  /// The layer named `name` of a vector file (OGR; "" the first), each feature's validity by
  /// OGR_G_IsValid; false with `error` set when OGR cannot read it or has no such layer. (version 4)
  bool (*read_vector)(const std::filesystem::path& file, const std::string& name, VectorLayer& layer,
                      std::string& error) = nullptr;
  /// A layer of MultiPolygons created at `file` with the OGR driver `driver` ("GPKG", "GeoJSON");
  /// false with `error` set on failure. (version 2)
  bool (*write_polygons)(const std::filesystem::path& file, const std::string& driver, const VectorLayer& layer,
                         std::string& error) = nullptr;
  /// `grid` (its coordinate system in grid.crs) warped to EPSG:`epsg` into `out` with GDAL's warper:
  /// bilinear or nearest over valid cells, NODATA kept (cells outside the source too), square cells
  /// of `cell_size` (0: GDAL's suggested size rounded to two significant figures) on a lattice
  /// aligned with multiples of the cell size; out.crs is the target's WKT. False with `error` set on
  /// failure. (version 3; the resampling since 4)
  bool (*warp_raster)(const HeightGrid& grid, int epsg, double cell_size, Resampling resampling, HeightGrid& out,
                      std::string& error) = nullptr;
  /// Points (x, y; longitude, latitude in a geographic system) from the system `from` to `to` (both
  /// WKT), in place; false with `error` set when there is no transformation or a point fails. (version 4)
  bool (*transform_points)(const std::string& from, const std::string& to, std::vector<PlanPoint>& points,
                           std::string& error) = nullptr;
  /// Band `band` (from 1) of a raster, as read_raster reads band 1, and the unit its metadata
  /// declares in `unit` (a FARSITE landscape's "<BAND>_UNIT_NAME", else the band's unit type; ""
  /// when none); false with `error` set when GDAL cannot read it or there is no such band. (version 5)
  bool (*read_raster_band)(const std::filesystem::path& file, int band, HeightGrid& grid, std::string& unit,
                           std::string& error) = nullptr;
};

/// The module, loaded on the first call. An InputError naming `file` when bodyfit was built
/// without GDAL or when the module cannot be loaded (with dlopen's reason).
const Api& module_for(const std::filesystem::path& file);

}  // namespace bodyfit::gis

/// Defined by the module: its table of entry points.
extern "C" const bodyfit::gis::Api* bodyfit_gis_api();
