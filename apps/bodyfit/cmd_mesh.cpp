// bodyfit mesh sphere|terrain: mesh generators.
#include "commands.hpp"

#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>

#include <spdlog/spdlog.h>

#include <memory>

namespace {

bodyfit::cli::Command setup_mesh(CLI::App& app) {
  auto* cmd = app.add_subcommand("mesh", "generate a surface mesh (geodesic sphere, terrain)");
  cmd->require_subcommand(1);
  auto sphere = std::make_shared<bodyfit::SphereOptions>();
  auto output = std::make_shared<std::string>();
  auto* sph = cmd->add_subcommand("sphere", "geodesic sphere: near-equilateral triangles, vertices exactly on the sphere");
  sph->add_option("--faces", sphere->faces, "target number of triangles (result within ±10 %)")->capture_default_str();
  sph->add_option("--radius", sphere->radius, "radius")->capture_default_str();
  sph->add_option("-o,--output", *output, "output mesh (.mesh, .meshb, .obj, .off, .ply, .stl, .vtu)")->required();
  return {cmd, [=]() {
            if (sph->parsed()) {
              auto mesh = bodyfit::make_sphere(*sphere);
              bodyfit::write_mesh(mesh, *output);
              spdlog::info("sphere: {} vertices, {} faces, min quality {:.3f} -> {}", mesh.n_vertices(),
                           mesh.n_faces(), bodyfit::quality_stats(mesh).min, *output);
            }
            return 0;
          }};
}

BODYFIT_COMMAND(10, setup_mesh);

}  // namespace
