#include <bodyfit/app/coordinate_system.hpp>
#include <bodyfit/error.hpp>

#include "gis_module.hpp"

#include <fmt/format.h>

namespace bodyfit {

std::string crs_label(const std::string& wkt, const std::filesystem::path& file) {
  if (wkt.empty()) return "no coordinate system";
  gis::CrsInfo info;
  std::string error;
  if (!gis::module_for(file).describe_crs(wkt, info, error)) return wkt;
  return info.epsg ? fmt::format("EPSG:{} ({})", info.epsg, info.name) : info.name;
}

bool same_crs(const std::string& a, const std::string& b, const std::filesystem::path& file) {
  if (a.empty() || b.empty()) return false;
  return a == b || gis::module_for(file).same_crs(a, b);
}

bool geographic_crs(const std::string& wkt, const std::filesystem::path& file) {
  if (wkt.empty()) return false;
  gis::CrsInfo info;
  std::string error;
  return gis::module_for(file).describe_crs(wkt, info, error) && info.geographic;
}

void require_crs(const std::string& crs, const std::filesystem::path& file, const std::string& reference,
                 const std::filesystem::path& reference_file) {
  if (crs.empty() || reference.empty() || same_crs(crs, reference, file)) return;
  throw InputError(fmt::format("{} and {} have different coordinate systems ({} and {}): one case has one; "
                               "reproject the first onto the second (gdalwarp -t_srs, ogr2ogr -t_srs)",
                               file.string(), reference_file.string(), crs_label(crs, file),
                               crs_label(reference, reference_file)));
}

void transform_points(const std::string& from, const std::string& to, std::vector<PlanPoint>& points,
                      const std::filesystem::path& file) {
  std::string error;
  if (!gis::module_for(file).transform_points(from, to, points, error))
    throw file_error(file, fmt::format("cannot reproject its coordinates to {}: {}", crs_label(to, file), error));
}

}  // namespace bodyfit
