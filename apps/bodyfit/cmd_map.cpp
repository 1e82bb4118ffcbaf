// bodyfit map RUN_DIR|MESH [--arrival arrival_time.tif|.asc] -o map.png: a fire map (map.hpp) of a
// finished run or of a mesh with its regions: hillshade, burnt area, isochrones, scale bar, legend.
#include "commands.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/map.hpp>
#include <bodyfit/raster_io.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <memory>

namespace {

namespace fs = std::filesystem;
using namespace bodyfit;

struct MapArguments {
  std::string input, output, arrival, title = "Fire map", size = "1200x900", crs, datetime, time_unit = "auto";
  double interval_minutes = 0, sun_azimuth = 315, sun_altitude = 45, z_factor = 1;
};

int map_command(const MapArguments& args) {
  MapOptions options;
  options.title = args.title;
  options.sun_azimuth = args.sun_azimuth;
  options.sun_altitude = args.sun_altitude;
  options.z_factor = args.z_factor;
  options.isochrone_interval = args.interval_minutes * 60;
  options.time_unit = args.time_unit == "h" ? TimeUnit::hours : args.time_unit == "min" ? TimeUnit::minutes : TimeUnit::automatic;
  int w = 0, h = 0;
  char x = 0;
  if (std::sscanf(args.size.c_str(), "%d%c%d", &w, &x, &h) != 3 || (x != 'x' && x != 'X'))
    throw InputError(fmt::format("--size '{}': expected WxH, e.g. 1200x900", args.size));
  options.width = w, options.height = h;

  RunMap run;
  if (fs::is_directory(args.input)) {
    run = load_run_map(args.input);
  } else {
    run.mesh = read_mesh(args.input);
    run.mesh.garbage_collection();
  }
  if (!args.arrival.empty()) {
    run.layers.arrival = read_raster_values(args.arrival);
    run.layers.crs_name = crs_name_of_wkt(run.layers.arrival.crs);
  }
  if (!args.crs.empty()) run.layers.crs_name = args.crs;
  run.layers.datetime = args.datetime;
  draw_fire_map(args.output, run.mesh, run.layers, options);
  spdlog::info("{}: {}x{} map of {} faces, {} -> {}", args.input, w, h, run.mesh.n_faces(),
               run.layers.arrival.cols ? "with isochrones" : "no arrival times", args.output);
  return 0;
}

bodyfit::cli::Command setup_map(CLI::App& app) {
  auto* cmd = app.add_subcommand("map", "draw a fire map (hillshade, burnt area, isochrones, scale bar, legend) to a PNG");
  auto args = std::make_shared<MapArguments>();
  // No ExistingFile check: a missing file is an input error (exit 1), as for every reader.
  cmd->add_option("input", args->input,
                  "a finished run directory (final.mesh, arrival_time.tif or .asc, case.toml) or a mesh with regions")
      ->required();
  cmd->add_option("-o,--output", args->output, "output .png")->required();
  cmd->add_option("--arrival", args->arrival, "arrival times in seconds, an ESRI ASCII grid (default: the run's)");
  cmd->add_option("--title", args->title, "title above the map")->capture_default_str();
  cmd->add_option("--size", args->size, "image size WxH in pixels")->capture_default_str();
  cmd->add_option("--interval", args->interval_minutes, "isochrone interval in minutes (default: a 1-2-5 step)");
  cmd->add_option("--time-unit", args->time_unit, "isochrone labels: auto | h | min")
      ->check(CLI::IsMember({"auto", "h", "min"}))
      ->capture_default_str();
  cmd->add_option("--sun-azimuth", args->sun_azimuth, "hillshade sun azimuth, degrees clockwise from north")
      ->capture_default_str();
  cmd->add_option("--sun-altitude", args->sun_altitude, "hillshade sun altitude, degrees")->capture_default_str();
  cmd->add_option("--z-factor", args->z_factor, "hillshade relief exaggeration (heights times this)")
      ->capture_default_str();
  cmd->add_option("--crs", args->crs, "coordinate system name for the caption (default: from the .prj)");
  cmd->add_option("--datetime", args->datetime, "date and time for the caption, e.g. \"2026-07-14 16:00 UTC\"");
  return {cmd, [args]() { return map_command(*args); }};
}

}  // namespace

BODYFIT_COMMAND(87, setup_map);
