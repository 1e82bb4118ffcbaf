// bodyfit info FILE [--json]: what a mesh is made of (counts, size, quality, edge lengths, regions,
// interface, topology, feature tags), as one screen of aligned text or as JSON for scripts.
#include "commands.hpp"

#include <bodyfit/app/stages.hpp>
#include <bodyfit/io.hpp>

#include <cstdio>
#include <memory>
#include <string>

namespace {

bodyfit::cli::Command setup_info(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "describe a mesh: counts, size, quality, edge lengths, regions, interface, "
                                         "topology (components, boundary loops, Euler characteristic), feature tags");
  auto file = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  cmd->add_option("file", *file, "mesh file (.mesh, .meshb, .obj, .off, .ply, .stl)")->required();
  cmd->add_flag("--json", *json, "print JSON (for scripts) instead of text");
  return {cmd, [=]() {
            auto mesh = bodyfit::read_mesh(*file);
            const auto info = bodyfit::describe_mesh(mesh);
            std::fputs((*json ? bodyfit::to_json(info, *file) : bodyfit::to_text(info, *file)).c_str(), stdout);
            return 0;
          },
          /*on_huge_pages=*/true};
}

BODYFIT_COMMAND(20, setup_info);

}  // namespace
