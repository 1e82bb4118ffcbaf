// bodyfit discretize: cut the zero level set of φ into the mesh and remesh (the job of `mmgs -ls 0`):
// the output carries the regions (refs 3 inside, 2 outside) and the interface edges (ref 10).
#include "commands.hpp"
#include "remesh_options.hpp"
#include "validators.hpp"

#include <bodyfit/app/stages.hpp>
#include <bodyfit/io.hpp>

#include <spdlog/spdlog.h>

#include <chrono>
#include <memory>

namespace {

class Stopwatch {
 public:
  /// Milliseconds since construction or the previous lap.
  double lap() {
    auto now = std::chrono::steady_clock::now();
    double ms = std::chrono::duration<double, std::milli>(now - last_).count();
    last_ = now;
    return ms;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

bodyfit::cli::Command setup_discretize(CLI::App& app) {
  auto* cmd = app.add_subcommand("discretize", "cut the zero level set of phi into the mesh, then remesh (mmgs -ls 0)");
  auto input = std::make_shared<std::string>();
  auto phi_file = std::make_shared<std::string>();
  auto output = std::make_shared<std::string>();
  auto cut = std::make_shared<bodyfit::DiscretizeOptions>();
  auto options = std::make_shared<bodyfit::RemeshOptions>();
  auto no_remesh = std::make_shared<bool>(false);
  cmd->add_option("input", *input, "input mesh (.mesh, .meshb, ...)")->required();
  cmd->add_option("--phi", *phi_file, "level set at the vertices (.sol/.solb, negative inside)")
      ->required();
  cmd->add_option("-o,--output", *output, "output mesh (.mesh keeps refs, readable by MMG)")->required();
  cmd->add_option("--snap", cut->snap_ratio,
                  "put a vertex on the level set when the crossing is closer than this fraction of the edge")
      ->capture_default_str()
      ->check(bodyfit::cli::finite_in(0.0, 0.5));
  cmd->add_option("--snap-fixed", cut->fixed_snap_ratio,
                  "the same for vertices the remesher cannot move (boundary, ridges, corners, required); "
                  "the larger of the two applies")
      ->capture_default_str()
      ->check(bodyfit::cli::finite_in(0.0, 0.5));
  cmd->add_option("--speck", cut->speck_area,
                  "give parts of a region smaller than this many h² (h: mean edge length) to the region around them")
      ->capture_default_str()
      ->check(bodyfit::cli::finite_at_least(0));
  bodyfit::cli::add_remesh_options(*cmd, *options);
  cmd->add_flag("--no-remesh", *no_remesh, "only cut the level set in (thin triangles remain)");
  return {cmd, [=]() {
            Stopwatch clock;
            auto mesh = bodyfit::read_mesh(*input);
            auto phi = bodyfit::read_scalar_sol(*phi_file, mesh.n_vertices());
            double read_ms = clock.lap();
            std::size_t faces_before = mesh.n_faces();
            const auto stage = bodyfit::discretize_stage(mesh, phi, *cut, *options, !*no_remesh);
            clock.lap();
            const auto& report = stage.cut;
            auto quality = bodyfit::quality_stats(mesh);
            spdlog::info("discretize: {} -> {} faces, {} crossed edges, {} snapped and {} separated vertices, "
                         "{} flipped diagonals, {} specks removed; {} interface edges, {} inside faces; quality min {:.3g} mean {:.3f}; "
                         "{:.1f} ms (read {:.1f} ms)",
                         faces_before, mesh.n_faces(), report.crossed_edges, report.snapped_vertices,
                         report.separated_vertices, report.flipped_diagonals, report.removed_specks, report.interface_edges,
                         report.inside_faces, quality.min, quality.mean, stage.cut_ms, read_ms);
            if (const auto& remeshed = stage.remesh)
              spdlog::info("remesh: {} faces, quality min {:.3f} mean {:.3f}; {} splits, {} collapses, {} flips, "
                           "{} relocations in {} passes; {:.1f} ms",
                           mesh.n_faces(), remeshed->min_quality, remeshed->mean_quality, remeshed->splits,
                           remeshed->collapses, remeshed->flips, remeshed->relocations, remeshed->passes, stage.remesh_ms);
            bodyfit::write_mesh(mesh, *output);
            spdlog::info("wrote {} ({:.1f} ms)", *output, clock.lap());
            return 0;
          },
          /*on_huge_pages=*/true};
}

BODYFIT_COMMAND(55, setup_discretize);

}  // namespace
