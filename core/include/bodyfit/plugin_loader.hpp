#pragma once
// Finding and loading velocity-model plugins (shared objects named bodyfit_<model>.so).
//
// Search order: the directories of BODYFIT_PLUGIN_PATH (colon-separated), the plugin directory
// beside the loaded libbodyfit_core (<libdir>/bodyfit/plugins: the build tree's or the install
// prefix's, wherever the tree now lives; no build path is compiled in), the configured install
// prefix's plugin directory (duplicates dropped). Every failure (no such model, dlopen error,
// missing symbol, ABI mismatch, throwing constructor) is an InputError naming the file and reason.
// The ABI (major << 16 | minor) is checked before anything else (plugin_abi.hpp): the major must
// equal ours and the plugin's minor must not exceed ours (a plugin built against older headers of
// the same major loads).
#include <bodyfit/velocity_model.hpp>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace bodyfit {

struct PluginInfo {
  std::filesystem::path file;
  std::uint32_t abi = 0;
  std::string name, version, description;
  std::vector<ParameterDecl> parameters;
  std::vector<OutputDecl> outputs;
};

/// A model created by a plugin, keeping the shared object loaded while the model lives.
class LoadedModel {
 public:
  LoadedModel() = default;
  LoadedModel(LoadedModel&&) noexcept;
  LoadedModel& operator=(LoadedModel&&) noexcept;
  ~LoadedModel();
  /// A model made by the program itself, not loaded from a plugin (a Python object given to
  /// bodyfit.run): `origin` names it in messages as a plugin's file does; its ABI is ours.
  static LoadedModel hosted(std::unique_ptr<VelocityModel> model, std::filesystem::path origin);
  VelocityModel& model() const { return *model_; }
  VelocityModel* operator->() const { return model_; }
  const std::filesystem::path& file() const { return file_; }
  /// The ABI the plugin reported (kPluginAbi of the headers it was built with).
  std::uint32_t abi() const { return abi_; }
  /// The plugin's file, ABI and the model's self-description and declarations.
  PluginInfo info() const;

 private:
  friend LoadedModel load_plugin_file(const std::filesystem::path& file);
  void reset();
  void* handle_ = nullptr;
  VelocityModel* model_ = nullptr;
  void (*destroy_)(VelocityModel*) = nullptr;
  std::filesystem::path file_;
  std::uint32_t abi_ = 0;
};

/// Directories searched, in order.
std::vector<std::filesystem::path> plugin_search_path();
/// Every plugin found on the search path (the first of each name wins), with its description.
/// Files that fail to load are reported in `failures` (one message each) instead of throwing.
std::vector<PluginInfo> discover_plugins(std::vector<std::string>* failures = nullptr);
/// Load the model `name` (bodyfit_<name>.so on the search path), or a plugin file when `name`
/// contains a '/' or ends in .so.
LoadedModel load_model(std::string_view name);
LoadedModel load_plugin_file(const std::filesystem::path& file);
/// Call model.set_surface(surface), then model.configure() with the [model] table read through the
/// model's declarations, then refuse every key of the table that configure() did not read
/// (Parameters::check_consumed: unknown keys, and declared keys these settings do not use). An
/// InputError thrown by configure (the documented way to refuse a parameter) becomes InputError
/// "<file>: configure failed: <reason>"; any other exception PluginError "<file>: model '<name>'
/// failed in configure: <reason>" (a key read that the model did not declare is one).
void configure_model(LoadedModel& model, const toml::table& parameters, const SurfaceSource& surface = {});

}  // namespace bodyfit
