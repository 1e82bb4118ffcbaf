// Where bodyfit's shared data is (shared_data.hpp).
#include <bodyfit/app/config.hpp>
#include <bodyfit/app/shared_data.hpp>
#include <bodyfit/shared_object.hpp>

#include <system_error>

namespace bodyfit {

std::filesystem::path shared_data_directory() {
  const std::filesystem::path libdir = core_library_directory();
  if (libdir.empty()) return {};
  std::error_code ec;
  const std::filesystem::path dir = std::filesystem::weakly_canonical(libdir / config::data_dir_from_libdir, ec);
  return !ec && std::filesystem::is_directory(dir / "cases", ec) ? dir : std::filesystem::path();
}

}  // namespace bodyfit
