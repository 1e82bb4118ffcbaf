#include "gis_module.hpp"

#include "core_location.hpp"

#include <bodyfit/config.hpp>
#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <dlfcn.h>

#include <mutex>

namespace bodyfit::gis {

const Api& module_for(const std::filesystem::path& file) {
  if constexpr (!config::have_gdal)
    throw file_error(file, "GeoTIFF rasters and coordinate systems need GDAL, and bodyfit was built without GDAL "
                           "(install libgdal-dev and reconfigure; or give an ESRI ASCII grid .asc without a .prj)");
  static std::once_flag once;
  static const Api* api = nullptr;
  static std::string failure;
  std::call_once(once, [] {
    const std::filesystem::path module = core_library_directory() / config::gis_module_from_libdir;
    // Never closed: GDAL keeps its drivers registered for the life of the process.
    void* handle = dlopen(module.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* reason = dlerror();
      failure = fmt::format("cannot load bodyfit's GDAL module {}: {}", module.string(), reason ? reason : "?");
      return;
    }
    auto entry = reinterpret_cast<decltype(&bodyfit_gis_api)>(dlsym(handle, "bodyfit_gis_api"));
    const Api* table = entry ? entry() : nullptr;
    if (!table || table->version != kApiVersion) {
      failure = fmt::format("{} is not the GDAL module of this bodyfit (reinstall bodyfit)", module.string());
      return;
    }
    api = table;
  });
  if (!api) throw file_error(file, failure);
  return *api;
}

}  // namespace bodyfit::gis
