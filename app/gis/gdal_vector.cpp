// Vector layers through OGR (see app/src/gis_module.hpp): ignitions in, perimeters out.
#include "gdal_vector.hpp"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <bodyfit/app/clock_time.hpp>

#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <variant>

namespace bodyfit::gis {
namespace {

PlanPath read_path(OGRGeometryH g) {
  PlanPath path;
  const int n = OGR_G_GetPointCount(g);
  path.reserve(std::size_t(n));
  for (int i = 0; i < n; ++i) path.push_back({OGR_G_GetX(g, i), OGR_G_GetY(g, i)});
  return path;
}

/// OGR's rings repeat their first point at the end; bodyfit's do not.
PlanPath read_ring(OGRGeometryH g) {
  PlanPath ring = read_path(g);
  if (ring.size() > 1 && ring.front() == ring.back()) ring.pop_back();
  return ring;
}

// Flatten a geometry (multi-parts and collections) into points, lines and polygons.
bool collect(OGRGeometryH g, PlanGeometry& out, std::string& error) {
  switch (wkbFlatten(OGR_G_GetGeometryType(g))) {
    case wkbPoint:
      if (!OGR_G_IsEmpty(g)) out.points.push_back({OGR_G_GetX(g, 0), OGR_G_GetY(g, 0)});
      return true;
    case wkbLineString:
      if (!OGR_G_IsEmpty(g)) out.lines.push_back(read_path(g));
      return true;
    case wkbPolygon: {
      PlanPolygon polygon;
      for (int i = 0, n = OGR_G_GetGeometryCount(g); i < n; ++i) polygon.rings.push_back(read_ring(OGR_G_GetGeometryRef(g, i)));
      if (!polygon.rings.empty()) out.polygons.push_back(std::move(polygon));
      return true;
    }
    case wkbMultiPoint:
    case wkbMultiLineString:
    case wkbMultiPolygon:
    case wkbGeometryCollection:
      for (int i = 0, n = OGR_G_GetGeometryCount(g); i < n; ++i)
        if (!collect(OGR_G_GetGeometryRef(g, i), out, error)) return false;
      return true;
    default: {
      // Curves (circular strings, curve polygons…): their linear approximation.
      OGRGeometryH linear = OGR_G_GetLinearGeometry(g, 0, nullptr);
      if (!linear || wkbFlatten(OGR_G_GetGeometryType(linear)) == wkbFlatten(OGR_G_GetGeometryType(g))) {
        if (linear) OGR_G_DestroyGeometry(linear);
        error = fmt::format("geometries of type {} are not supported", OGRGeometryTypeToName(OGR_G_GetGeometryType(g)));
        return false;
      }
      const bool ok = collect(linear, out, error);
      OGR_G_DestroyGeometry(linear);
      return ok;
    }
  }
}

AttributeValue read_field(OGRFeatureH feature, int i) {
  if (!OGR_F_IsFieldSetAndNotNull(feature, i)) return std::monostate{};
  switch (OGR_Fld_GetType(OGR_F_GetFieldDefnRef(feature, i))) {
    case OFTInteger:
    case OFTInteger64: return std::int64_t(OGR_F_GetFieldAsInteger64(feature, i));
    case OFTReal: return OGR_F_GetFieldAsDouble(feature, i);
    case OFTDateTime: {
      // As ISO 8601 (OGR's own text is "2026/07/14 13:00:00+00"), with the zone when it has one.
      int year = 0, month = 0, day = 0, hour = 0, minute = 0, zone = 0;
      float second = 0;
      OGR_F_GetFieldAsDateTimeEx(feature, i, &year, &month, &day, &hour, &minute, &second, &zone);
      std::string text = fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:", year, month, day, hour, minute);
      text += second == float(int(second)) ? fmt::format("{:02}", int(second)) : fmt::format("{:06.3f}", second);
      if (zone == 100) text += "Z";
      else if (zone > 1) {  // 100 + quarter hours from UTC; 0 unknown and 1 local time have no zone
        const int minutes = (zone - 100) * 15;
        text += fmt::format("{}{:02}:{:02}", minutes < 0 ? '-' : '+', std::abs(minutes) / 60, std::abs(minutes) % 60);
      }
      return text;
    }
    default: return std::string(OGR_F_GetFieldAsString(feature, i));
  }
}

struct DatasetCloser {
  GDALDatasetH d;
  ~DatasetCloser() {
    if (d) GDALClose(d);
  }
};

OGRGeometryH make_ring(const PlanPath& ring) {
  OGRGeometryH g = OGR_G_CreateGeometry(wkbLinearRing);
  for (const auto& p : ring) OGR_G_AddPoint_2D(g, p[0], p[1]);
  if (!ring.empty()) OGR_G_AddPoint_2D(g, ring.front()[0], ring.front()[1]);
  return g;
}

OGRGeometryH make_multipolygon(const std::vector<PlanPolygon>& polygons) {
  OGRGeometryH multi = OGR_G_CreateGeometry(wkbMultiPolygon);
  for (const auto& polygon : polygons) {
    OGRGeometryH g = OGR_G_CreateGeometry(wkbPolygon);
    for (const auto& ring : polygon.rings) OGR_G_AddGeometryDirectly(g, make_ring(ring));
    OGR_G_AddGeometryDirectly(multi, g);
  }
  return multi;
}

}  // namespace

bool read_vector(const std::filesystem::path& file, const std::string& name, VectorLayer& layer, std::string& error) {
  GDALAllRegister();
  CPLErrorReset();
  CPLPushErrorHandler(CPLQuietErrorHandler);
  GDALDatasetH dataset = GDALOpenEx(file.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, nullptr, nullptr, nullptr);
  CPLPopErrorHandler();
  if (!dataset) {
    error = fmt::format("cannot open as a vector layer (GDAL: {})", CPLGetLastErrorMsg());
    return false;
  }
  DatasetCloser closer{dataset};
  if (GDALDatasetGetLayerCount(dataset) < 1) {
    error = "the file has no layer";
    return false;
  }
  OGRLayerH source = name.empty() ? GDALDatasetGetLayer(dataset, 0) : GDALDatasetGetLayerByName(dataset, name.c_str());
  if (!source) {
    std::vector<std::string> names;
    for (int i = 0; i < GDALDatasetGetLayerCount(dataset); ++i)
      names.push_back(OGR_L_GetName(GDALDatasetGetLayer(dataset, i)));
    error = fmt::format("no layer named '{}' (the file has: {})", name, fmt::join(names, ", "));
    return false;
  }
  layer = VectorLayer{};
  layer.name = OGR_L_GetName(source);
  if (OGRSpatialReferenceH srs = OGR_L_GetSpatialRef(source)) {
    char* wkt = nullptr;
    if (OSRExportToWkt(srs, &wkt) == OGRERR_NONE && wkt) layer.crs = wkt;
    CPLFree(wkt);
  }
  OGR_L_ResetReading(source);
  long index = 0;
  CPLPushErrorHandler(CPLQuietErrorHandler);  // GEOS explains invalid geometries on stderr
  while (OGRFeatureH feature = OGR_L_GetNextFeature(source)) {
    ++index;
    VectorFeature out;
    bool ok = true;
    if (OGRGeometryH g = OGR_F_GetGeometryRef(feature)) {
      ok = collect(g, out.geometry, error);
      out.valid = OGR_G_IsValid(g) != 0;
    }
    for (int i = 0, n = OGR_F_GetFieldCount(feature); i < n; ++i)
      out.attributes.emplace_back(OGR_Fld_GetNameRef(OGR_F_GetFieldDefnRef(feature, i)), read_field(feature, i));
    OGR_F_Destroy(feature);
    if (!ok) {
      CPLPopErrorHandler();
      error = fmt::format("feature {}: {}", index, error);
      return false;
    }
    layer.features.push_back(std::move(out));
  }
  CPLPopErrorHandler();
  return true;
}

namespace {

/// The date-time a GeoPackage stamps on its contents (gpkg_contents.last_change, in the standard's
/// %Y-%m-%dT%H:%M:%fZ form), taken from the layer, not from the machine's clock: GDAL's GPKG
/// driver uses OGR_CURRENT_DATE, when set, instead of "now". Set for this thread while the file
/// is written, and put back as it was after.
class DeterministicDate {
 public:
  explicit DeterministicDate(std::optional<double> timestamp) {
    if (const char* before = CPLGetThreadLocalConfigOption("OGR_CURRENT_DATE", nullptr)) before_ = before;
    double whole = std::floor(timestamp.value_or(0.0));
    long milliseconds = std::lround((timestamp.value_or(0.0) - whole) * 1000);
    if (milliseconds == 1000) whole += 1, milliseconds = 0;
    std::string date = format_iso8601(whole);  // "…:SSZ"
    date.insert(date.size() - 1, fmt::format(".{:03d}", milliseconds));
    CPLSetThreadLocalConfigOption("OGR_CURRENT_DATE", date.c_str());
  }
  ~DeterministicDate() { CPLSetThreadLocalConfigOption("OGR_CURRENT_DATE", before_ ? before_->c_str() : nullptr); }
  DeterministicDate(const DeterministicDate&) = delete;
  DeterministicDate& operator=(const DeterministicDate&) = delete;

 private:
  std::optional<std::string> before_;
};

}  // namespace

bool write_polygons(const std::filesystem::path& file, const std::string& driver_name, const VectorLayer& layer,
                    std::string& error) {
  GDALAllRegister();
  GDALDriverH driver = GDALGetDriverByName(driver_name.c_str());
  if (!driver) {
    error = fmt::format("GDAL has no {} driver", driver_name);
    return false;
  }
  OGRSpatialReferenceH srs = nullptr;
  if (!layer.crs.empty()) {
    srs = OSRNewSpatialReference(nullptr);
    if (OSRSetFromUserInput(srs, layer.crs.c_str()) != OGRERR_NONE) {
      OSRDestroySpatialReference(srs);
      error = "cannot read the coordinate system to write";
      return false;
    }
    OSRSetAxisMappingStrategy(srs, OAMS_TRADITIONAL_GIS_ORDER);
  }
  struct SrsRelease {
    OGRSpatialReferenceH h;
    ~SrsRelease() {
      if (h) OSRRelease(h);
    }
  } release{srs};
  CPLErrorReset();
  CPLPushErrorHandler(CPLQuietErrorHandler);
  struct Pop {
    ~Pop() { CPLPopErrorHandler(); }
  } pop;
  auto gdal_failure = [&](const char* what) {
    error = fmt::format("{} (GDAL: {})", what, CPLGetLastErrorMsg());
    return false;
  };
  const DeterministicDate date(layer.timestamp);
  GDALDatasetH dataset = GDALCreate(driver, file.c_str(), 0, 0, 0, GDT_Unknown, nullptr);
  if (!dataset) return gdal_failure("cannot create the file");
  DatasetCloser closer{dataset};
  const std::string name = layer.name.empty() ? file.stem().string() : layer.name;
  OGRLayerH out = GDALDatasetCreateLayer(dataset, name.c_str(), srs, wkbMultiPolygon, nullptr);
  if (!out) return gdal_failure("cannot create the layer");
  const auto& first = layer.features.empty() ? std::vector<std::pair<std::string, AttributeValue>>{}
                                             : layer.features.front().attributes;
  for (const auto& [field, value] : first) {
    const OGRFieldType type = std::holds_alternative<std::int64_t>(value) ? OFTInteger64
                              : std::holds_alternative<double>(value)     ? OFTReal
                                                                          : OFTString;
    OGRFieldDefnH definition = OGR_Fld_Create(field.c_str(), type);
    const bool created = OGR_L_CreateField(out, definition, TRUE) == OGRERR_NONE;
    OGR_Fld_Destroy(definition);
    if (!created) return gdal_failure("cannot create the attribute");
  }
  // One transaction for all features (a GeoPackage commits each feature otherwise).
  if (OGR_L_StartTransaction(out) != OGRERR_NONE) return gdal_failure("cannot start writing the features");
  for (std::size_t k = 0; k < layer.features.size(); ++k) {
    const VectorFeature& feature = layer.features[k];
    OGRFeatureH f = OGR_F_Create(OGR_L_GetLayerDefn(out));
    for (std::size_t i = 0; i < feature.attributes.size() && i < first.size(); ++i) {
      const AttributeValue& value = feature.attributes[i].second;
      const int field = int(i);
      if (const auto* integer = std::get_if<std::int64_t>(&value)) OGR_F_SetFieldInteger64(f, field, *integer);
      else if (const auto* real = std::get_if<double>(&value)) OGR_F_SetFieldDouble(f, field, *real);
      else if (const auto* text = std::get_if<std::string>(&value)) OGR_F_SetFieldString(f, field, text->c_str());
      else OGR_F_SetFieldNull(f, field);
    }
    OGR_F_SetGeometryDirectly(f, make_multipolygon(feature.geometry.polygons));
    const bool created = OGR_L_CreateFeature(out, f) == OGRERR_NONE;
    OGR_F_Destroy(f);
    if (!created) return gdal_failure("cannot write a feature");
  }
  if (OGR_L_CommitTransaction(out) != OGRERR_NONE) return gdal_failure("cannot write the features");
  closer.d = nullptr;
  GDALClose(dataset);  // flushes: a full disk shows here
  if (CPLGetLastErrorType() >= CE_Failure) return gdal_failure("cannot write the file");
  return true;
}

bool transform_points(const std::string& from, const std::string& to, std::vector<PlanPoint>& points,
                      std::string& error) {
  OGRSpatialReferenceH source = OSRNewSpatialReference(nullptr), target = OSRNewSpatialReference(nullptr);
  OGRCoordinateTransformationH transform = nullptr;
  CPLErrorReset();
  CPLPushErrorHandler(CPLQuietErrorHandler);
  if (OSRSetFromUserInput(source, from.c_str()) == OGRERR_NONE && OSRSetFromUserInput(target, to.c_str()) == OGRERR_NONE) {
    // x, y as bodyfit reads them from OGR's geometries: longitude first in a geographic system.
    OSRSetAxisMappingStrategy(source, OAMS_TRADITIONAL_GIS_ORDER);
    OSRSetAxisMappingStrategy(target, OAMS_TRADITIONAL_GIS_ORDER);
    transform = OCTNewCoordinateTransformation(source, target);
  }
  bool ok = transform != nullptr;
  if (!ok) error = fmt::format("no transformation between the coordinate systems (GDAL: {})", CPLGetLastErrorMsg());
  for (std::size_t i = 0; ok && i < points.size(); ++i) {
    double x = points[i][0], y = points[i][1], z = 0;
    ok = OCTTransform(transform, 1, &x, &y, &z) != 0;
    if (ok) points[i] = {x, y};
    else error = fmt::format("cannot transform the point ({}, {}) (GDAL: {})", points[i][0], points[i][1], CPLGetLastErrorMsg());
  }
  CPLPopErrorHandler();
  if (transform) OCTDestroyCoordinateTransformation(transform);
  OSRDestroySpatialReference(source);
  OSRDestroySpatialReference(target);
  return ok;
}

}  // namespace bodyfit::gis
