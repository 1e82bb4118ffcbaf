#pragma once
// Vector layers (GeoPackage, GeoJSON, Shapefile… through the GDAL module's OGR): ignitions read
// from them, fire perimeters written to them, with their coordinate system and attributes.
#include <bodyfit/app/plan_geometry.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace bodyfit {

/// A feature's attribute: null, integer, real or text (dates as text).
using AttributeValue = std::variant<std::monostate, std::int64_t, double, std::string>;

struct VectorFeature {
  PlanGeometry geometry{};
  std::vector<std::pair<std::string, AttributeValue>> attributes{};
  /// Read: whether OGR (GEOS) finds the geometry valid (OGC simple features).
  bool valid = true;
  /// The attribute named `name` (null when the feature has none).
  const AttributeValue& attribute(const std::string& name) const;
};

struct VectorLayer {
  std::string name{};  ///< the layer's name (a GeoPackage's table)
  std::string crs{};   ///< WKT ("" when unknown)
  std::vector<VectorFeature> features{};
  /// Written: the time a GeoPackage records as its last change (gpkg_contents.last_change), s since
  /// 1970-01-01T00:00:00Z; none: that epoch itself. Never the clock of the writing machine, so the
  /// same layer gives the same bytes (a resumed run's file equals an uninterrupted run's).
  std::optional<double> timestamp{};
};

/// A layer of a vector file (any format OGR reads: .geojson, .shp, .gpkg…): the one named `name`,
/// or the first ("" ). Curves are linearised, z is dropped. Throws InputError naming the file when
/// OGR cannot read it, it has no such layer, or bodyfit was built without GDAL.
VectorLayer read_vector_layer(const std::filesystem::path& file, const std::string& name = "");

/// The layer in the surface's coordinate system, as every layer of a case is taken: in place when
/// the case reprojected its DEM and the layer is in the DEM's geographic system (degrees), as is
/// when it is in the surface's (a warning when the layer has none: its coordinates are taken as
/// the surface's); otherwise an InputError naming the file, its system and the surface's.
void to_surface_crs(VectorLayer& layer, const std::filesystem::path& file, const std::string& surface_crs,
                    const std::string& reprojected_from, const std::filesystem::path& surface_file);

/// Write a layer of polygons (each feature a MultiPolygon; every feature has the attributes of the
/// first, in its order and types) as a GeoPackage (.gpkg) or GeoJSON (.geojson/.json), with its
/// CRS, atomically. Throws InputError for another extension or features that are not polygons,
/// IoError when the file cannot be written.
void write_polygon_layer(const std::filesystem::path& file, const VectorLayer& layer);

}  // namespace bodyfit
