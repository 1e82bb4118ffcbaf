// bodyfit advect: carry a level set along a tangential velocity field on the surface by the method
// of characteristics (the Advection stage of the pipeline).
#include "commands.hpp"
#include "validators.hpp"

#include <bodyfit/app/stages.hpp>
#include <bodyfit/io.hpp>

#include <spdlog/spdlog.h>

#include <chrono>
#include <memory>

namespace {

struct AdvectArguments {
  std::string mesh, phi, velocity, output;
  double time = 0;
  bodyfit::AdvectionOptions options;
  bool plain_p1 = false;
};

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

bodyfit::cli::Command setup_advect(CLI::App& app) {
  auto args = std::make_shared<AdvectArguments>();
  auto* cmd = app.add_subcommand("advect", "solve dφ/dt + V·∇φ = 0 on the surface over (0, T) by characteristics");
  cmd->add_option("mesh", args->mesh, "surface mesh")->required();
  cmd->add_option("--phi", args->phi, "level set at the vertices (.sol)")->required();
  cmd->add_option("--velocity", args->velocity, "velocity at the vertices (vector .sol)")->required();
  cmd->add_option("--time", args->time, "final time T")->required()->check(bodyfit::cli::finite_at_least(0));
  cmd->add_option("--steps", args->options.steps, "outer steps over (0, T)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--rk", args->options.rk_order, "Runge-Kutta order of the tracing (2 or 4)")
      ->capture_default_str()
      ->check(CLI::IsMember({2, 4}));
  cmd->add_flag("--p1", args->plain_p1,
                "plain P1 interpolation at the feet (default: P1 averaged with the vertex-gradient Taylor "
                "expansions, which removes the O(h²) interpolation bias)");
  cmd->add_option("--cells", args->options.max_cells_per_substep, "edge lengths crossed per sub-step, at most about")
      ->capture_default_str()
      ->check(bodyfit::cli::finite_above(0));
  cmd->add_option("--max-substeps", args->options.max_substeps,
                  "refuse to start when the sub-steps of all characteristics are estimated above this (0: no limit)")
      ->capture_default_str()
      ->check(bodyfit::cli::finite_at_least(0));
  cmd->add_option("-o,--output", args->output, "advected level set (.sol)")->required();
  return {cmd, [args]() {
            const auto start = std::chrono::steady_clock::now();
            const bodyfit::SurfaceMesh mesh = bodyfit::read_mesh(args->mesh);
            const auto phi = bodyfit::read_scalar_sol(args->phi, mesh.n_vertices());
            const auto velocity = bodyfit::read_vector_sol(args->velocity, mesh.n_vertices());
            const double read_ms = ms_since(start);
            const auto advect_start = std::chrono::steady_clock::now();
            bodyfit::AdvectionReport report;
            args->options.gradient_correction = !args->plain_p1;
            const auto result =
                bodyfit::advect_stage(mesh, phi, velocity, args->time, args->options, &report);
            const double advect_ms = ms_since(advect_start);
            bodyfit::write_scalar_sol(args->output, result);
            spdlog::info(
                "advect: {} vertices, {} faces, T = {}, RK{}; {} characteristics, {} sub-steps, {} stopped on the "
                "boundary, {} lost; advect {:.1f} ms, read {:.1f} ms, total {:.1f} ms -> {}",
                mesh.n_vertices(), mesh.n_faces(), args->time, args->options.rk_order, report.traced, report.substeps,
                report.hit_boundary, report.lost, advect_ms, read_ms, ms_since(start), args->output);
            return 0;
          },
          /*on_huge_pages=*/true};
}

BODYFIT_COMMAND(40, setup_advect);

}  // namespace
