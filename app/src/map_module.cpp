#include "map_module.hpp"

#include <bodyfit/app/config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/shared_object.hpp>

#include <dlfcn.h>

namespace bodyfit::map_module {

const Api& module_for(const std::filesystem::path& file) {
  if constexpr (!config::have_cairo)
    throw file_error(file, "maps are drawn with Cairo, and bodyfit was built without Cairo "
                           "(install libcairo2-dev and reconfigure)");
  std::string failure;
  const Api* api = module_table<Api>(core_library_directory() / config::map_module_from_libdir, "bodyfit_map_api",
                                     kApiVersion, RTLD_LOCAL, "map module", failure);
  if (!api) throw file_error(file, failure);
  return *api;
}

}  // namespace bodyfit::map_module
