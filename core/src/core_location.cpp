#include "core_location.hpp"

#include <dlfcn.h>

#include <system_error>

namespace bodyfit {

std::filesystem::path core_library_directory() {
  static const char anchor = 0;  // an object of this library: dladdr names the file it came from
  Dl_info info;
  if (!dladdr(&anchor, &info) || !info.dli_fname) return {};
  std::error_code ec;
  std::filesystem::path library = std::filesystem::weakly_canonical(std::filesystem::path(info.dli_fname), ec);
  if (ec) return {};
  return library.parent_path();
}

}  // namespace bodyfit
