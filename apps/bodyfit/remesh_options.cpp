#include "remesh_options.hpp"
#include "validators.hpp"

namespace bodyfit::cli {

void add_remesh_options(CLI::App& command, RemeshOptions& options) {
  // Sizes: omitted means the default (the input's resolution); given, they must be lengths.
  command.add_option("--hmin", options.hmin, "smallest edge length (default hmax/20)")->check(finite_above(0));
  command.add_option("--hmax", options.hmax, "largest edge length (default: the input's resolution, the side of an equilateral triangle of its mean area)")
      ->check(finite_above(0));
  command.add_option("--hausd", options.hausd, "allowed distance to the surface and interface (default diagonal/1000)")
      ->check(finite_above(0));
  command.add_option("--hausd-interface", options.hausd_interface,
                     "allowed distance to the interface curve alone (default --hausd)")
      ->check(finite_above(0));
  command.add_option("--hgrad", options.hgrad, "gradation between neighbouring sizes, ≥ 1")
      ->capture_default_str()
      ->check(finite_at_least(1));
  command.add_option("--angle", options.feature_angle, "ridge detection angle in degrees, <= 0 disables")
      ->capture_default_str()
      ->check(finite());
  // Together: --hmin above --hmax is refused while parsing, so it is a usage error too.
  command.parse_complete_callback([&options] {
    if (options.hmin > 0 && options.hmax > 0 && options.hmin > options.hmax)
      throw CLI::ValidationError("--hmin", fmt::format("{} exceeds --hmax {}", options.hmin, options.hmax));
  });
}

}  // namespace bodyfit::cli
