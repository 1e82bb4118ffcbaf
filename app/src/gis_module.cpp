#include "gis_module.hpp"

#include <bodyfit/app/config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/shared_object.hpp>

#include <dlfcn.h>

namespace bodyfit::gis {

const Api& module_for(const std::filesystem::path& file) {
  if constexpr (!config::have_gdal)
    throw file_error(file, "GeoTIFF rasters and coordinate systems need GDAL, and bodyfit was built without GDAL "
                           "(install libgdal-dev and reconfigure; or give an ESRI ASCII grid .asc without a .prj)");
  std::string failure;
  const Api* api = module_table<Api>(core_library_directory() / config::gis_module_from_libdir, "bodyfit_gis_api",
                                     kApiVersion, RTLD_LOCAL, "GDAL module", failure);
  if (!api) throw file_error(file, failure);
  return *api;
}

}  // namespace bodyfit::gis
