#pragma once
// Coordinate systems (as WKT) in the words a GIS user reads them, and compared: the checks that keep
// the rasters and layers of one case in one system.
#include <bodyfit/app/plan_geometry.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace bodyfit {

/// A short name for messages: "EPSG:32632 (WGS 84 / UTM zone 32N)", the name alone when the system
/// has no EPSG code, "no coordinate system" for "". Through the GDAL module (`file` names the
/// input in its errors); the WKT itself when GDAL cannot read it.
std::string crs_label(const std::string& wkt, const std::filesystem::path& file = {});
/// Whether two WKT texts describe the same system (both known).
bool same_crs(const std::string& a, const std::string& b, const std::filesystem::path& file = {});
/// Whether a system measures in degrees of longitude and latitude.
bool geographic_crs(const std::string& wkt, const std::filesystem::path& file = {});
/// An InputError naming both files and both systems when `file`'s system `crs` is not the
/// `reference` system of `reference_file` (e.g. a model's raster and the case's DEM); nothing when
/// either is unknown ("").
void require_crs(const std::string& crs, const std::filesystem::path& file, const std::string& reference,
                 const std::filesystem::path& reference_file);
/// Points from the system `from` to `to` (geographic coordinates as x = longitude, y = latitude), in
/// place. InputError naming `file` when there is no transformation.
void transform_points(const std::string& from, const std::string& to, std::vector<PlanPoint>& points,
                      const std::filesystem::path& file);

}  // namespace bodyfit
