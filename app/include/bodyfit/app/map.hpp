#pragma once
// Fire maps a GIS user accepts: a top view of the terrain (north up) with a hillshade, the burnt
// area filled, isochrones of the arrival time labelled in h or min, the ignition points, a scale
// bar in m or km, a north arrow, a legend, a title and a caption (coordinate system, date-time).
// The drawing is Cairo's, in a module loaded on first use (app/map/, <libdir>/bodyfit/
// libbodyfit_map.so) so that neither the core nor the program links Cairo; the layout (where each
// world point lands, the scale bar, the isochrone levels and lines) is computed here, in the core,
// so that tests can check the picture against it.
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/mesh.hpp>
#include <bodyfit/app/render.hpp>

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace bodyfit {

/// What a map shows on top of the hillshaded mesh.
struct MapLayers {
  bool burnt_area = true;  ///< fill the faces of G (region kInside) and outline ∂G
  /// Arrival time in seconds on a raster (the fire model's arrival_time.asc); NaN or the grid's
  /// NODATA where the fire never came. No isochrones when it has no cells.
  HeightGrid arrival;
  std::vector<Vec3> ignitions;  ///< points (x, y) marked with a star
  std::string crs_name;         ///< e.g. "WGS 84 / UTM zone 32N", shown in the caption
  std::string datetime;         ///< e.g. "2026-07-14 16:00 UTC", shown in the caption
  /// The clock time of t = 0 (seconds since 1970, the case's [time] start): the caption then says
  /// when the fire started and, with `burnt_at`, the date-time of the map (map_time_caption).
  std::optional<double> clock_start;
  /// The burnt area at this time (s after t = 0; `bodyfit map --at`): the cells of `arrival`
  /// reached at or before it are filled and outlined instead of G's faces, and only the isochrones
  /// up to it are drawn. None: G of the mesh (the final state).
  std::optional<double> burnt_at;
};

enum class TimeUnit { automatic, hours, minutes };

struct MapOptions {
  int width = 1200, height = 900;  ///< pixels, legend and margins included
  std::string title = "Fire map";
  double sun_azimuth = 315;   ///< hillshade sun, degrees clockwise from north (315: north-west)
  double sun_altitude = 45;   ///< degrees above the horizon
  double z_factor = 1;        ///< heights times this for the hillshade only (gentle relief: 2 to 5)
  /// Isochrone spacing in seconds; 0 picks a 1-2-5 step in minutes or hours giving 3 to 8 lines.
  double isochrone_interval = 0;
  TimeUnit time_unit = TimeUnit::automatic;  ///< automatic: hours for intervals of 30 min or more
  Rgb burnt_color{215, 25, 20};
  double burnt_opacity = 0.5;
  Rgb ignition_color{255, 220, 0};
};

/// A point of the picture, in pixels (x to the right, y down).
struct MapPixel {
  double x = 0, y = 0;
};

/// Where things are on the picture: the map panel (left), the legend panel (right), and the
/// world→pixel transform of the map (north = +y up, equal scale on both axes).
struct MapLayout {
  int width = 0, height = 0;
  double panel_left = 0, panel_top = 0, panel_right = 0, panel_bottom = 0;  ///< the map's frame
  double legend_left = 0;  ///< the legend panel starts here and runs to the right edge
  double metres_per_pixel = 1;
  double world_x0 = 0, world_y0 = 0;  ///< the world point at pixel (pixel_x0, pixel_y0)
  double pixel_x0 = 0, pixel_y0 = 0;
  MapPixel to_pixel(double x, double y) const {
    return {pixel_x0 + (x - world_x0) / metres_per_pixel, pixel_y0 - (y - world_y0) / metres_per_pixel};
  }
};

/// The layout of a map of the plan-view box [xmin, xmax] × [ymin, ymax]. InputError for a size
/// below 320 × 240 or above 8192 × 8192, or an empty box.
MapLayout map_layout(double xmin, double ymin, double xmax, double ymax, const MapOptions& options);

/// The scale bar: a round length (1, 2 or 5 × 10^k metres) about a quarter of the map's width.
struct ScaleBar {
  double metres = 0;
  double pixels = 0;       ///< metres / metres_per_pixel
  MapPixel left;           ///< the bar's left end, on its centre line
  std::string label;       ///< "500 m", "2 km"
};
ScaleBar scale_bar(const MapLayout& layout);

/// The largest of 1, 2, 5 × 10^k not above `value` (> 0).
double nice_step_below(double value);

/// The isochrone spacing in seconds: the options' or the automatic one over the raster's span
/// (0 when fewer than two distinct arrival times).
double isochrone_interval(const HeightGrid& arrival, const MapOptions& options);
/// The isochrone times, in seconds: multiples of the interval (the given one or the automatic
/// one, see MapOptions) strictly between the earliest and the latest arrival of the raster.
std::vector<double> isochrone_levels(const HeightGrid& arrival, const MapOptions& options);
/// A time as its label: "1.5 h", "40 min" (the unit from the options and the levels' spacing).
std::string time_label(double seconds, double interval, const MapOptions& options);

/// The colour of isochrone `index` of `count`: the viridis-like colormap (render.hpp) from the
/// earliest (dark violet) to the latest (yellow).
Rgb isochrone_colour(std::size_t index, std::size_t count);

/// The contour t = level of a raster (cell centres, marching squares with linear interpolation;
/// NaN or NODATA cells break the line), as world segments.
std::vector<std::array<Vec3, 2>> isochrone_segments(const HeightGrid& arrival, double level);

/// Where fires started, from their arrival times: a front only moves away from its ignitions, so
/// each ignition is a plateau of cells no later than any neighbour (a disk burning at t = 0, a later
/// ignition at its time). The centroid of each such plateau of connected cells, in world (x, y).
std::vector<Vec3> ignitions_from_arrival(const HeightGrid& arrival);

/// The caption's time: `datetime` when given; else, with a clock start, "fire start <date-time>"
/// and, for a map at a time, "map at <date-time>"; else "".
std::string map_time_caption(const MapLayers& layers);

/// A label's box on the picture, in pixels.
struct LabelBox {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};
/// For each line, the index of the first of its candidate boxes (in order of preference) that
/// lies within the map panel and overlaps no box chosen before it; -1 when none does (the line
/// goes unlabelled: the legend gives its time).
std::vector<int> place_labels(const std::vector<std::vector<LabelBox>>& candidates, const MapLayout& layout);

/// The cells of `arrival` reached at or before `time` (1) or not (0), in the raster's order (row 0
/// north); NaN and NODATA cells never are.
std::vector<char> burnt_cells(const HeightGrid& arrival, double time);

/// Draw the map as a PNG (written atomically). InputError for options out of range (size, sun
/// altitude in [0, 90], opacity in [0, 1], negative interval, z factor ≤ 0), and when bodyfit was built without
/// Cairo or its map module cannot be loaded, naming what to install.
void draw_fire_map(const std::filesystem::path& png, const SurfaceMesh& mesh, const MapLayers& layers,
                   const MapOptions& options = {});

/// What a finished run directory holds for a map: final.mesh, arrival_time.tif or .asc when
/// present (with the coordinate system's name), the ignition points (the centres of case.toml's
/// [region] disks, or the arrival time's ignition plateaus for other shapes) and [time] start. InputError naming the missing file.
struct RunMap {
  SurfaceMesh mesh;
  MapLayers layers;
};
RunMap load_run_map(const std::filesystem::path& run_dir);
/// The layers alone (all of load_run_map but final.mesh): for a run that draws its own map from
/// the mesh it has just written.
MapLayers load_map_layers(const std::filesystem::path& run_dir);

/// The name of a coordinate system given as WKT (its first quoted string: PROJCS["name", ...]).
std::string crs_name_of_wkt(const std::string& wkt);

}  // namespace bodyfit
