// bodyfit render in.mesh -o out.png: a PNG picture of a mesh, no viewer needed.
#include "commands.hpp"
#include "validators.hpp"

#include <bodyfit/distance.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/app/render.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <memory>

namespace {

namespace fs = std::filesystem;
using namespace bodyfit;

struct RenderArguments {
  std::string input, output, field = "region", view = "iso", size = "800x600";
  double azimuth = 1e9, elevation = 1e9;  // unset: from --view
  bool perspective = false, no_interface = false;
};

int render_command(const RenderArguments& args) {
  VtuFields vtu;  // a VTU carries its fields: the run's d, velocity, the model's
  const bool is_vtu = fs::path(args.input).extension() == ".vtu";
  SurfaceMesh mesh = is_vtu ? read_vtu(args.input, &vtu) : read_mesh(args.input);
  mesh.garbage_collection();
  RenderOptions options;
  set_view(options, args.view);
  if (args.azimuth < 1e8) options.azimuth = args.azimuth;
  if (args.elevation < 1e8) options.elevation = args.elevation;
  options.perspective = args.perspective;
  options.draw_interface = !args.no_interface;
  int w = 0, h = 0;
  char x = 0;
  if (std::sscanf(args.size.c_str(), "%d%c%d", &w, &x, &h) != 3 || (x != 'x' && x != 'X') || w < 16 || h < 16 ||
      w > 8192 || h > 8192)
    throw InputError(fmt::format("--size '{}': expected WxH with each in [16, 8192], e.g. 800x600", args.size));
  options.width = w, options.height = h;

  const std::string& field = args.field;
  auto in_vtu = std::find_if(vtu.point_scalars.begin(), vtu.point_scalars.end(),
                             [&](const auto& named) { return named.first == field; });
  if (in_vtu != vtu.point_scalars.end()) {
    options.field = in_vtu->second;
    options.field_name = field;
  } else if (field.size() > 4 && (field.ends_with(".sol") || field.ends_with(".solb"))) {
    options.field = read_scalar_sol(field, mesh.n_vertices());
    options.field_name = fs::path(field).stem().string();
  } else if (field == "d") {
    options.field = signed_distance_to_region(mesh);
    options.field_name = "d";
  } else if (field == "phi") {
    // φ lives in a .sol next to the mesh (Medit keeps fields apart from meshes).
    fs::path sol = fs::path(args.input).replace_extension(".sol");
    if (!fs::exists(sol)) throw InputError(fmt::format("--field phi: no {} next to the mesh (pass the .sol file instead)", sol.string()));
    options.field = read_scalar_sol(sol, mesh.n_vertices());
    options.field_name = "phi";
  } else if (field != "region") {
    options.field = named_vertex_field(mesh, field);
    if (options.field.empty()) {
      std::string in_file;
      for (const auto& [name, values] : vtu.point_scalars) in_file += ", " + name;
      throw InputError(fmt::format("--field '{}': expected region, phi, d, quality, height, a .sol file{}", field,
                                   in_file.empty() ? std::string() : " or a field of the VTU (" + in_file.substr(2) + ")"));
    }
    options.field_name = field;
  }
  render_png(mesh, args.output, options);
  spdlog::info("{}: {}x{} image of {} faces -> {}", args.input, w, h, mesh.n_faces(), args.output);
  return 0;
}

bodyfit::cli::Command setup_render(CLI::App& app) {
  auto* cmd = app.add_subcommand("render", "render a mesh to a PNG image (region colours or a field with a colorbar)");
  auto args = std::make_shared<RenderArguments>();
  // No ExistingFile check: a missing file is an input error (exit 1), as for every reader.
  cmd->add_option("mesh", args->input, "input mesh (any format read_mesh reads, .vtu with its fields)")->required();
  cmd->add_option("-o,--output", args->output, "output .png")->required();
  cmd->add_option("--field", args->field, "region | phi | d | quality | height | a .sol file | a point field of the .vtu")
      ->capture_default_str();
  cmd->add_option("--view", args->view, "iso | top | front")->capture_default_str();
  cmd->add_option("--azimuth", args->azimuth, "camera azimuth in degrees (overrides --view)")
      ->check(bodyfit::cli::finite());
  cmd->add_option("--elevation", args->elevation, "camera elevation in degrees (overrides --view)")
      ->check(bodyfit::cli::finite_in(-90, 90));
  cmd->add_option("--size", args->size, "image size WxH")->capture_default_str();
  cmd->add_flag("--perspective", args->perspective, "perspective instead of orthographic projection");
  cmd->add_flag("--no-interface", args->no_interface, "do not draw the interface edges");
  return {cmd, [args]() { return render_command(*args); }};
}

BODYFIT_COMMAND(85, setup_render);

}  // namespace
