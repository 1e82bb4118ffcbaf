// bodyfit plugins: the velocity models found on the plugin search path, and one model's reference.
#include "commands.hpp"

#include <bodyfit/app/model_reference.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/plugin_loader.hpp>

#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <memory>

namespace {

struct PluginsArguments {
  std::string describe;  ///< a model's name: print its reference
  bool markdown = false;
};

int list_plugins() {
  std::vector<std::string> failures;
  const auto plugins = bodyfit::discover_plugins(&failures);
  fmt::print("search path:\n");
  for (const auto& dir : bodyfit::plugin_search_path()) {
    std::error_code ec;
    fmt::print("  {}{}\n", dir.string(), std::filesystem::is_directory(dir, ec) ? "" : "  (missing)");
  }
  fmt::print("\n{} plugin{} found (bodyfit plugins --describe NAME: parameters and outputs)\n", plugins.size(),
             plugins.size() == 1 ? "" : "s");
  for (const auto& p : plugins) {
    fmt::print("\n{} {}  (ABI {})\n  file: {}\n", p.name, p.version, bodyfit::abi_string(p.abi), p.file.string());
    if (!p.description.empty()) fmt::print("  {}\n", p.description);
  }
  if (!failures.empty()) {
    fmt::print("\n{} file{} failed to load:\n", failures.size(), failures.size() == 1 ? "" : "s");
    for (const auto& f : failures) fmt::print("  {}\n", f);
  }
  std::fflush(stdout);
  return 0;
}

int describe_plugin(const PluginsArguments& args) {
  const bodyfit::PluginInfo info = bodyfit::load_model(args.describe).info();
  fmt::print("{}", bodyfit::describe_model(info, args.markdown ? bodyfit::ReferenceFormat::Markdown
                                                                : bodyfit::ReferenceFormat::Text));
  std::fflush(stdout);
  return 0;
}

bodyfit::cli::Command setup_plugins(CLI::App& app) {
  auto* cmd = app.add_subcommand("plugins",
                                 "list the velocity models found on the plugin search path (BODYFIT_PLUGIN_PATH, "
                                 "then the build tree, then the install prefix); --describe NAME prints one model's "
                                 "parameters and outputs");
  auto args = std::make_shared<PluginsArguments>();
  auto* describe = cmd->add_option("--describe", args->describe, "a model's reference: its parameters and outputs");
  cmd->add_flag("--markdown", args->markdown, "with --describe: as Markdown tables (the docs' reference)")
      ->needs(describe);
  return {cmd, [args]() { return args->describe.empty() ? list_plugins() : describe_plugin(*args); }};
}

BODYFIT_COMMAND(90, setup_plugins);

}  // namespace
