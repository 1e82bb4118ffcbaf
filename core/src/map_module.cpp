#include "map_module.hpp"

#include "core_location.hpp"

#include <bodyfit/config.hpp>
#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <dlfcn.h>

#include <mutex>

namespace bodyfit::map_module {

const Api& module_for(const std::filesystem::path& file) {
  if constexpr (!config::have_cairo)
    throw file_error(file, "maps are drawn with Cairo, and bodyfit was built without Cairo "
                           "(install libcairo2-dev and reconfigure)");
  static std::once_flag once;
  static const Api* api = nullptr;
  static std::string failure;
  std::call_once(once, [] {
    const std::filesystem::path module = core_library_directory() / config::map_module_from_libdir;
    // Never closed: Cairo keeps font caches for the life of the process.
    void* handle = dlopen(module.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* reason = dlerror();
      failure = fmt::format("cannot load bodyfit's map module {}: {}", module.string(), reason ? reason : "?");
      return;
    }
    auto entry = reinterpret_cast<decltype(&bodyfit_map_api)>(dlsym(handle, "bodyfit_map_api"));
    const Api* table = entry ? entry() : nullptr;
    if (!table || table->version != kApiVersion) {
      failure = fmt::format("{} is not the map module of this bodyfit (reinstall bodyfit)", module.string());
      return;
    }
    api = table;
  });
  if (!api) throw file_error(file, failure);
  return *api;
}

}  // namespace bodyfit::map_module
