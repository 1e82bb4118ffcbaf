// bodyfit distance: signed geodesic distance to the zero set of a level set, or to a labelled region
// (the Mshdist stage of the pipeline).
#include "commands.hpp"
#include "validators.hpp"

#include <bodyfit/app/stages.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/io.hpp>

#include <spdlog/spdlog.h>

#include <chrono>
#include <memory>
#include <optional>

namespace {

struct DistanceArguments {
  std::string mesh, phi, output;
  int region = 0;
  double narrow_band = 0;  // 0: none
};

bodyfit::cli::Command setup_distance(CLI::App& app) {
  auto args = std::make_shared<DistanceArguments>();
  auto* cmd = app.add_subcommand("distance", "signed geodesic distance at the vertices (negative inside)");
  cmd->add_option("mesh", args->mesh, "surface mesh")->required();
  auto* phi = cmd->add_option("--phi", args->phi, "level set (.sol): distance to its zero set");
  auto* region = cmd->add_option("--region", args->region,
                                 "distance to the faces with this ref (interface: the edges between them and the rest)");
  phi->excludes(region);
  cmd->add_option("--narrow-band", args->narrow_band, "stop beyond this |d| (those vertices get ±1e300); 0: everywhere")
      ->check(bodyfit::cli::finite_at_least(0));
  cmd->add_option("-o,--output", args->output, "output distance (.sol)")->required();
  return {cmd, [args, phi, region]() {
            if (phi->count() == 0 && region->count() == 0)
              throw bodyfit::InputError("bodyfit distance: give either --phi in.sol or --region REF");
            const auto start = std::chrono::steady_clock::now();
            bodyfit::SurfaceMesh mesh = bodyfit::read_mesh(args->mesh);
            bodyfit::DistanceOptions options;
            if (args->narrow_band > 0) options.narrow_band = args->narrow_band;
            bodyfit::DistanceReport report;
            const bodyfit::ScalarField phi_values =
                phi->count() > 0 ? bodyfit::read_scalar_sol(args->phi, mesh.n_vertices()) : bodyfit::ScalarField();
            const bodyfit::ScalarField d = bodyfit::distance_stage(mesh, phi->count() > 0 ? &phi_values : nullptr,
                                                                   args->region, options, &report);
            if (!report.has_interface)
              spdlog::warn("distance: no interface (the level set does not change sign): all values are ±infinity");
            bodyfit::write_scalar_sol(args->output, d);
            const double total =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            spdlog::info(
                "distance: {} vertices, {} faces; {} initialised, {} marched; distance {:.1f} ms "
                "(setup {:.1f}, segments {:.1f}, march {:.1f}), total with IO {:.1f} ms -> {}",
                mesh.n_vertices(), mesh.n_faces(), report.initialised, report.marched,
                report.setup_ms + report.init_ms + report.march_ms, report.setup_ms, report.init_ms, report.march_ms,
                total, args->output);
            return 0;
          },
          /*on_huge_pages=*/true};
}

BODYFIT_COMMAND(30, setup_distance);

}  // namespace
