#include <bodyfit/app/vector_io.hpp>
#include <bodyfit/atomic_file.hpp>
#include <bodyfit/error.hpp>

#include "gis_module.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

namespace bodyfit {

const AttributeValue& VectorFeature::attribute(const std::string& name) const {
  static const AttributeValue null;
  for (const auto& [key, value] : attributes)
    if (key == name) return value;
  return null;
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
