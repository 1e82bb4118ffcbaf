// bodyfit remesh: interface-preserving adaptive remeshing of a Medit mesh (the `mmgs -ls` step
// after a cut), keeping regions, interface, ridges, corners, boundaries and required entities.
#include "commands.hpp"
#include "remesh_options.hpp"

#include <bodyfit/app/stages.hpp>
#include <bodyfit/io.hpp>

#include <spdlog/spdlog.h>

#include <chrono>
#include <memory>

namespace {

bodyfit::cli::Command setup_remesh(CLI::App& app) {
  auto* cmd = app.add_subcommand("remesh", "remesh to high quality, keeping S, the interface (ref 10) and features");
  auto input = std::make_shared<std::string>();
  auto output = std::make_shared<std::string>();
  auto options = std::make_shared<bodyfit::RemeshOptions>();
  cmd->add_option("input", *input, "input mesh (.mesh, .meshb, ...)")->required();
  cmd->add_option("-o,--output", *output, "output mesh (.mesh keeps refs, readable by MMG)")->required();
  bodyfit::cli::add_remesh_options(*cmd, *options);
  cmd->add_option("--passes", options->max_passes,
                  "cap on the collapse/flip/relocate passes (0: none; they stop when done or when they stop making "
                  "progress)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--full", [options](std::int64_t) { options->incremental = false; },
                "work on every vertex, not only where the mesh needs change");
  return {cmd, [=]() {
            auto start = std::chrono::steady_clock::now();
            auto mesh = bodyfit::read_mesh(*input);
            auto before = bodyfit::quality_stats(mesh);
            std::size_t faces_before = mesh.n_faces();
            auto report = bodyfit::remesh_stage(mesh, *options);
            bodyfit::write_mesh(mesh, *output);
            double total = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            spdlog::info("remesh: {} -> {} faces, quality min {:.3f} mean {:.3f} (before {:.3f} / {:.3f})", faces_before,
                         mesh.n_faces(), report.min_quality, report.mean_quality, before.min, before.mean);
            spdlog::info("remesh: {} splits, {} collapses, {} flips, {} relocations in {} split rounds + {} passes ({}); "
                         "longest edge {:.3f} × its target, {} above the split bound; {:.1f} ms remesh, {:.1f} ms total -> {}",
                         report.splits, report.collapses, report.flips, report.relocations, report.split_rounds,
                         report.passes, bodyfit::to_string(report.stop), report.max_edge_ratio, report.long_edges,
                         report.milliseconds, total, *output);
            return 0;
          },
          /*on_huge_pages=*/true};
}

BODYFIT_COMMAND(60, setup_remesh);

}  // namespace
