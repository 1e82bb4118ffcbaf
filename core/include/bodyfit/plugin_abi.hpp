#pragma once
// The plugin ABI: the version a plugin is built against, and the features each version brought.
//
// A plugin exports bodyfit_plugin_abi(), which returns kPluginAbi of the headers it was compiled
// with (major << 16 | minor). The loader accepts the same major and a minor up to its own; a
// feature added in a later minor of the same major (a new virtual member, appended at the end of
// VelocityModel) is used only with plugins that have it: plugin_has(abi, kAbiSomething), checked in
// plugin_loader.cpp, the one place that decides.
//
// What must match between the driver and a plugin, beyond this number: C++ types cross the
// boundary (std::string, std::vector, std::filesystem::path, toml++'s tables in Parameters, Eigen's
// matrices), so a plugin is built with the same compiler family and standard library as bodyfit,
// against the same toml++ and Eigen (Debian's packages; find_package(bodyfit) gives them).
#include <cstdint>
#include <string>
#include <string_view>

namespace bodyfit {

inline constexpr std::uint32_t kPluginAbiMajor = 3;
inline constexpr std::uint32_t kPluginAbiMinor = 4;
inline constexpr std::uint32_t kPluginAbi = (kPluginAbiMajor << 16) | kPluginAbiMinor;

/// A feature of the plugin interface and the ABI version that brought it.
struct AbiFeature {
  std::uint32_t major = kPluginAbiMajor;
  std::uint32_t minor = 0;
  std::string_view name;
};

// The features of ABI 3.0 (every 3.x plugin has them).
/// Declared parameters read through Parameters (VelocityModel::parameters, configure(Parameters&)).
inline constexpr AbiFeature kAbiDeclaredParameters{3, 0, "declared parameters"};
/// Declared outputs handed to ModelOutputs (VelocityModel::outputs, finish(ModelOutputs&)).
inline constexpr AbiFeature kAbiDeclaredOutputs{3, 0, "declared outputs"};
/// The surface's source and coordinate system before configure (VelocityModel::set_surface).
inline constexpr AbiFeature kAbiSurfaceSource{3, 0, "surface source"};

// The features of ABI 3.1.
/// New components of G named by the model (VelocityModel::nuclei).
inline constexpr AbiFeature kAbiNuclei{3, 1, "nuclei"};

// The features of ABI 3.2.
/// ModelNeeds::whole_surface_distance: a model built before it gets d on the whole surface (its
/// needs() returns the shorter struct, and its author did not know d could be banded).
inline constexpr AbiFeature kAbiBandedDistance{3, 2, "banded distance"};

// The features of ABI 3.3.
/// StepContext::band_vertices(), and surface_normals() filled there only in a banded state: a model
/// built before it (which may read S's normals anywhere) gets d on the whole surface.
inline constexpr AbiFeature kAbiBandNormals{3, 3, "band normals"};

// The features of ABI 3.4.
/// ModelNeeds::remesh_everywhere: a model built before it gets each remesh looking everywhere (as
/// every remesh did then: its needs() returns the shorter struct).
inline constexpr AbiFeature kAbiRemeshWhereChanged{3, 4, "remesh where changed"};

/// Whether a plugin built for `abi` has `feature`.
constexpr bool plugin_has(std::uint32_t abi, AbiFeature feature) {
  return (abi >> 16) == feature.major && (abi & 0xffffu) >= feature.minor;
}
/// Whether the loader accepts a plugin built for `abi`: this major, a minor up to ours.
constexpr bool abi_compatible(std::uint32_t abi) {
  return (abi >> 16) == kPluginAbiMajor && (abi & 0xffffu) <= kPluginAbiMinor;
}
/// "3.0".
std::string abi_string(std::uint32_t abi);

}  // namespace bodyfit
