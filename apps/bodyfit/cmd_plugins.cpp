// bodyfit plugins: list the velocity models found on the plugin search path.
#include "commands.hpp"

#include <bodyfit/plugin_loader.hpp>

#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace {

bodyfit::cli::Command setup_plugins(CLI::App& app) {
  auto* cmd = app.add_subcommand("plugins",
                                 "list the velocity models found on the plugin search path (BODYFIT_PLUGIN_PATH, "
                                 "then the build tree, then the install prefix), with their parameters");
  return {cmd, []() {
            std::vector<std::string> failures;
            auto plugins = bodyfit::discover_plugins(&failures);

            fmt::print("search path:\n");
            for (const auto& dir : bodyfit::plugin_search_path()) {
              std::error_code ec;
              fmt::print("  {}{}\n", dir.string(), std::filesystem::is_directory(dir, ec) ? "" : "  (missing)");
            }
            fmt::print("\n{} plugin{} found\n", plugins.size(), plugins.size() == 1 ? "" : "s");
            for (const auto& p : plugins) {
              fmt::print("\n{} {}  (ABI {})\n  file: {}\n", p.name, p.version, bodyfit::abi_string(p.abi),
                         p.file.string());
              if (!p.description.empty()) fmt::print("  {}\n", p.description);
              if (p.parameters.empty()) {
                fmt::print("  parameters: none\n");
                continue;
              }
              fmt::print("  parameters:\n");
              std::size_t width = 0;
              for (const auto& q : p.parameters)
                width = std::max(width, q.name.size() + 3 + (q.default_value.empty() ? 10 : q.default_value.size()));
              for (const auto& q : p.parameters) {
                std::string lhs = fmt::format("{} = {}", q.name, q.default_value.empty() ? "(required)" : q.default_value);
                fmt::print("    {:<{}}  {}\n", lhs, width, q.description);
              }
            }
            if (!failures.empty()) {
              fmt::print("\n{} file{} failed to load:\n", failures.size(), failures.size() == 1 ? "" : "s");
              for (const auto& f : failures) fmt::print("  {}\n", f);
            }
            std::fflush(stdout);
            return 0;
          }};
}

BODYFIT_COMMAND(90, setup_plugins);

}  // namespace
