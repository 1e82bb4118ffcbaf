#include <bodyfit/shared_object.hpp>

#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <dlfcn.h>

#include <system_error>

namespace bodyfit {

std::filesystem::path library_directory_of(const void* address) {
  Dl_info info;
  if (!dladdr(address, &info) || !info.dli_fname) return {};
  std::error_code ec;
  std::filesystem::path library = std::filesystem::weakly_canonical(std::filesystem::path(info.dli_fname), ec);
  if (ec) return {};
  return library.parent_path();
}

std::filesystem::path core_library_directory() {
  static const char anchor = 0;  // an object of this library: dladdr names the file it came from
  return library_directory_of(&anchor);
}

void* open_shared_object(const std::filesystem::path& file, int flags, std::string_view what) {
  dlerror();
  void* handle = dlopen(file.c_str(), RTLD_NOW | flags);
  if (!handle) {
    const char* reason = dlerror();
    throw file_error(file, fmt::format("cannot load {}: {}", what, reason ? reason : "unknown dynamic-loader error"));
  }
  return handle;
}

void* shared_object_symbol(void* handle, const char* symbol) {
  dlerror();
  return dlsym(handle, symbol);
}

namespace detail {

void* module_entry(const std::filesystem::path& file, const char* entry, int flags, std::string_view what,
                   std::string& failure) {
  void* handle = dlopen(file.c_str(), RTLD_NOW | flags);
  if (!handle) {
    const char* reason = dlerror();
    failure = fmt::format("cannot load bodyfit's {} {}: {}", what, file.string(), reason ? reason : "?");
    return nullptr;
  }
  void* function = shared_object_symbol(handle, entry);
  if (!function) failure = foreign_module(file, what);
  return function;
}

std::string foreign_module(const std::filesystem::path& file, std::string_view what) {
  return fmt::format("{} is not the {} of this bodyfit (reinstall bodyfit)", file.string(), what);
}

}  // namespace detail
}  // namespace bodyfit
