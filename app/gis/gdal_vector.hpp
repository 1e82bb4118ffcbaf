#pragma once
// The vector half of the GDAL module (OGR): entries of the table in gdal_raster.cpp.
#include <bodyfit/app/vector_io.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace bodyfit::gis {

bool read_vector(const std::filesystem::path& file, const std::string& name, VectorLayer& layer, std::string& error);
bool write_polygons(const std::filesystem::path& file, const std::string& driver, const VectorLayer& layer,
                    std::string& error);
bool transform_points(const std::string& from, const std::string& to, std::vector<PlanPoint>& points,
                      std::string& error);

}  // namespace bodyfit::gis
