#include "remesh_options.hpp"

namespace bodyfit::cli {

void add_remesh_options(CLI::App& command, RemeshOptions& options) {
  command.add_option("--hmin", options.hmin, "smallest edge length (default hmax/20)");
  command.add_option("--hmax", options.hmax, "largest edge length (default: the input's resolution, the side of an equilateral triangle of its mean area)");
  command.add_option("--hausd", options.hausd, "allowed distance to the surface and interface (default diagonal/1000)");
  command.add_option("--hgrad", options.hgrad, "gradation between neighbouring sizes")->capture_default_str();
  command.add_option("--angle", options.feature_angle, "ridge detection angle in degrees, <= 0 disables")
      ->capture_default_str();
}

}  // namespace bodyfit::cli
