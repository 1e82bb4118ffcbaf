#pragma once
// The Cairo drawing of maps lives in a module loaded on first use (app/map/, libbodyfit_map.so in
// <libdir>/bodyfit/ beside libbodyfit_core), like the GDAL module (gis_module.hpp): linked into the
// core, Cairo and its ~30 libraries would be mapped by every command. The module is built with
// bodyfit from the same headers, so C++ types cross the boundary, under one exported symbol.
#include <bodyfit/app/map.hpp>

#include <cstdint>
#include <filesystem>
#include <string>

namespace bodyfit::map_module {

inline constexpr std::uint32_t kApiVersion = 2;  // 2: MapLayers::burnt_at

/// The module's entry points.
struct Api {
  std::uint32_t version = kApiVersion;
  /// The map as the bytes of a PNG file in `png`; false with `error` set when Cairo fails.
  bool (*draw_png)(const SurfaceMesh& mesh, const MapLayers& layers, const MapOptions& options, std::string& png,
                   std::string& error) = nullptr;
};

/// The module, loaded on the first call. An InputError naming `file` when bodyfit was built
/// without Cairo or when the module cannot be loaded (with dlopen's reason).
const Api& module_for(const std::filesystem::path& file);

}  // namespace bodyfit::map_module

/// Defined by the module: its table of entry points.
extern "C" const bodyfit::map_module::Api* bodyfit_map_api();
