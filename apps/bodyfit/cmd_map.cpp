// bodyfit map RUN_DIR|MESH [--arrival arrival_time.tif|.asc] -o map.png: a fire map (map.hpp) of a
// finished run or of a mesh with its regions: hillshade, burnt area, isochrones, scale bar, legend;
// with --at T (or --every S) the burnt area at that time, from the arrival raster.
#include "commands.hpp"
#include "validators.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/app/map.hpp>
#include <bodyfit/app/raster_io.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <memory>

namespace {

namespace fs = std::filesystem;
using namespace bodyfit;

struct MapArguments {
  std::string input, output, arrival, title = "Fire map", size = "1200x900", crs, datetime, time_unit = "auto";
  double interval_minutes = 0, sun_azimuth = 315, sun_altitude = 45, z_factor = 1;
  std::optional<double> at, every;  ///< seconds after t = 0
};

/// The maps of --every S: `map.png` → `map_001800s.png`, … (zero-padded: they sort by time).
fs::path map_at_time(const fs::path& output, double time) {
  return output.parent_path() / fmt::format("{}_{:06.0f}s{}", output.stem().string(), time, output.extension().string());
}

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
  if (!args.datetime.empty()) run.layers.datetime = args.datetime;
  if (args.at || args.every) {
    if (run.layers.arrival.cols == 0)
      throw InputError(fmt::format("{}: --at and --every draw the burnt area from the arrival times, and there are none "
                                   "(a run on a terrain writes arrival_time.tif; or give --arrival)",
                                   args.input));
    if (args.at && args.every) throw InputError("give --at or --every, not both");
  }
  if (args.every) {
    // Every multiple of S up to the latest arrival, that time included.
    double latest = 0;
    for (double t : run.layers.arrival.heights)
      if (std::isfinite(t) && t != run.layers.arrival.nodata) latest = std::max(latest, t);
    const long count = long(std::ceil(latest / *args.every - 1e-9));
    if (count > 1000) throw InputError(fmt::format("--every {}: {} maps up to {} s; at most 1000", *args.every, count, latest));
    for (long k = 1; k <= std::max(1L, count); ++k) {
      run.layers.burnt_at = double(k) * *args.every;
      draw_fire_map(map_at_time(args.output, *run.layers.burnt_at), run.mesh, run.layers, options);
    }
    spdlog::info("{}: {} maps, every {} s, -> {}", args.input, std::max(1L, count), *args.every,
                 map_at_time(args.output, *args.every).string());
    return 0;
  }
  run.layers.burnt_at = args.at;
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
  cmd->add_option("--interval", args->interval_minutes, "isochrone interval in minutes (default: a 1-2-5 step)")
      ->check(bodyfit::cli::finite_above(0));
  cmd->add_option("--time-unit", args->time_unit, "isochrone labels: auto | h | min")
      ->check(CLI::IsMember({"auto", "h", "min"}))
      ->capture_default_str();
  cmd->add_option("--sun-azimuth", args->sun_azimuth, "hillshade sun azimuth, degrees clockwise from north")
      ->check(bodyfit::cli::finite())
      ->capture_default_str();
  cmd->add_option("--sun-altitude", args->sun_altitude, "hillshade sun altitude, degrees")
      ->check(bodyfit::cli::finite_in(0, 90))
      ->capture_default_str();
  cmd->add_option("--z-factor", args->z_factor, "hillshade relief exaggeration (heights times this)")
      ->check(bodyfit::cli::finite_above(0))
      ->capture_default_str();
  cmd->add_option("--crs", args->crs, "coordinate system name for the caption (default: from the .prj)");
  cmd->add_option("--at", args->at, "the burnt area at this time, s after t = 0: the arrival raster's cells reached by then")
      ->check(bodyfit::cli::finite_at_least(0));
  cmd->add_option("--every", args->every,
                  "one map per multiple of this time (s) up to the last arrival, named map_001800s.png after -o map.png")
      ->check(bodyfit::cli::finite_above(0));
  cmd->add_option("--datetime", args->datetime, "date and time for the caption, e.g. \"2026-07-14 16:00 UTC\" (default: from the run's [time] start, the fire's start and the map's time)");
  return {cmd, [args]() { return map_command(*args); }};
}

}  // namespace

BODYFIT_COMMAND(87, setup_map);
