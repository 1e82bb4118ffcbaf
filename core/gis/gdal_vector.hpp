#pragma once
// The vector half of the GDAL module (OGR): entries of the table in gdal_raster.cpp.
#include <bodyfit/vector_io.hpp>

#include <filesystem>
#include <string>

namespace bodyfit::gis {

bool read_vector(const std::filesystem::path& file, VectorLayer& layer, std::string& error);
bool write_polygons(const std::filesystem::path& file, const std::string& driver, const VectorLayer& layer,
                    std::string& error);

}  // namespace bodyfit::gis
