#include <bodyfit/app/vector_io.hpp>
#include <bodyfit/app/coordinate_system.hpp>
#include <bodyfit/atomic_file.hpp>
#include <bodyfit/error.hpp>

#include "gis_module.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>

namespace bodyfit {

const AttributeValue& VectorFeature::attribute(const std::string& name) const {
  static const AttributeValue null;
  for (const auto& [key, value] : attributes)
    if (key == name) return value;
  return null;
}

void to_surface_crs(VectorLayer& layer, const std::filesystem::path& file, const std::string& surface_crs,
                    const std::string& reprojected_from, const std::filesystem::path& surface_file) {
  if (layer.crs.empty()) {
    if (!surface_crs.empty())
      spdlog::warn("{}: no coordinate system: its coordinates are taken as the surface's ({})", file.string(),
                   crs_label(surface_crs, surface_file));
    return;
  }
  if (surface_crs.empty() || same_crs(layer.crs, surface_crs, file)) return;
  if (reprojected_from.empty() || !geographic_crs(layer.crs, file)) {
    const std::string surface = reprojected_from.empty()
                                    ? crs_label(surface_crs, surface_file)
                                    : fmt::format("{}, the system {} was reprojected to", crs_label(surface_crs, surface_file),
                                                  surface_file.string());
    throw InputError(fmt::format("{} is in {}, the surface in {}: one case has one system; reproject the layer "
                                 "(ogr2ogr -t_srs), or give it in degrees when the case reprojects its DEM",
                                 file.string(), crs_label(layer.crs, file), surface));
  }
  // The case warped its DEM from degrees to UTM: a layer in degrees follows it.
  std::vector<PlanPoint*> where;
  for (auto& feature : layer.features) {
    auto& g = feature.geometry;
    for (auto& p : g.points) where.push_back(&p);
    for (auto& line : g.lines)
      for (auto& p : line) where.push_back(&p);
    for (auto& polygon : g.polygons)
      for (auto& ring : polygon.rings)
        for (auto& p : ring) where.push_back(&p);
  }
  std::vector<PlanPoint> points;
  points.reserve(where.size());
  for (const PlanPoint* p : where) points.push_back(*p);
  transform_points(layer.crs, surface_crs, points, file);
  for (std::size_t i = 0; i < points.size(); ++i) *where[i] = points[i];
  spdlog::info("{}: reprojected from {} to {}, the surface's", file.string(), crs_label(layer.crs, file),
               crs_label(surface_crs, surface_file));
  layer.crs = surface_crs;
}

VectorLayer read_vector_layer(const std::filesystem::path& file, const std::string& name) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw file_error(file, "no such file");
  const gis::Api& gis = gis::module_for(file);
  VectorLayer layer;
  std::string error;
  if (!gis.read_vector(file, name, layer, error)) throw file_error(file, error);
  return layer;
}

void write_polygon_layer(const std::filesystem::path& file, const VectorLayer& layer) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  std::string driver;
  if (ext == ".gpkg") driver = "GPKG";
  else if (ext == ".geojson" || ext == ".json") driver = "GeoJSON";
  else
    throw InputError(fmt::format("{}: unknown vector format '{}': expected .gpkg (GeoPackage) or .geojson", file.string(),
                                 ext));
  for (std::size_t i = 0; i < layer.features.size(); ++i)
    if (!layer.features[i].geometry.points.empty() || !layer.features[i].geometry.lines.empty())
      throw InputError(fmt::format("{}: feature {} is not made of polygons", file.string(), i + 1));
  const gis::Api& gis = gis::module_for(file);
  write_atomically_at(file, [&](const std::filesystem::path& temporary) {
    std::string error;
    if (!gis.write_polygons(temporary, driver, layer, error)) throw write_error(file, error);
  });
}

}  // namespace bodyfit
