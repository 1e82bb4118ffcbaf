// The layout of fire maps (map.hpp) and the call into the Cairo module that draws them.
#include <bodyfit/app/map.hpp>

#include "map_module.hpp"

#include <bodyfit/atomic_file.hpp>
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/app/clock_time.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/app/raster_io.hpp>

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bodyfit {
namespace {

bool reached(double t, double nodata) { return std::isfinite(t) && t != nodata; }

// The smallest of 1, 2, 5 × 10^k at or above `value` (> 0).
double nice_step_above(double value) {
  const double below = nice_step_below(value);
  if (below == value) return below;
  const double decade = std::pow(10.0, std::floor(std::log10(below) + 1e-9));
  const double mantissa = std::round(below / decade);
  return mantissa == 1 ? 2 * decade : mantissa == 2 ? 5 * decade : 10 * decade;
}

// The automatic isochrone spacing for arrivals spanning `span` seconds: 3 to 7 lines, a 1-2-5
// step in minutes (up to 30 min) or in hours.
double automatic_interval(double span) {
  const double raw = span / 7;
  if (raw < 60) return nice_step_above(raw);
  const double minutes = nice_step_above(raw / 60);
  if (minutes <= 30) return minutes * 60;
  return nice_step_above(raw / 3600) * 3600;
}

bool in_hours(double interval, const MapOptions& options) {
  if (options.time_unit == TimeUnit::hours) return true;
  if (options.time_unit == TimeUnit::minutes) return false;
  return interval >= 1800;  // half-hours and longer: "0.5 h, 1 h, 1.5 h" reads better than minutes
}

// The interval the levels use (the given one, or the automatic one over the raster's span).
double interval_for(const HeightGrid& arrival, const MapOptions& options, double& earliest, double& latest) {
  earliest = std::numeric_limits<double>::infinity();
  latest = -earliest;
  for (double t : arrival.heights)
    if (reached(t, arrival.nodata)) earliest = std::min(earliest, t), latest = std::max(latest, t);
  if (!(latest > earliest)) return 0;
  return options.isochrone_interval > 0 ? options.isochrone_interval : automatic_interval(latest - earliest);
}

}  // namespace

std::vector<char> burnt_cells(const HeightGrid& arrival, double time) {
  std::vector<char> cells(arrival.heights.size(), 0);
  for (std::size_t i = 0; i < cells.size(); ++i)
    cells[i] = reached(arrival.heights[i], arrival.nodata) && arrival.heights[i] <= time;
  return cells;
}

double nice_step_below(double value) {
  if (!(value > 0) || !std::isfinite(value)) throw InputError(fmt::format("nice_step_below: {} is not a positive length", value));
  const double decade = std::pow(10.0, std::floor(std::log10(value)));
  const double mantissa = value / decade;
  // A tolerance of a few ulps so that 5000 gives 5000, not 2000.
  const double step = mantissa >= 5 * (1 - 1e-12) ? 5 : mantissa >= 2 * (1 - 1e-12) ? 2 : 1;
  return step * decade;
}

MapLayout map_layout(double xmin, double ymin, double xmax, double ymax, const MapOptions& options) {
  if (options.width < 320 || options.height < 240 || options.width > 8192 || options.height > 8192)
    throw InputError(fmt::format("map size {}x{}: expected from 320x240 to 8192x8192", options.width, options.height));
  if (!(xmax > xmin) || !(ymax > ymin) || !std::isfinite(xmax - xmin) || !std::isfinite(ymax - ymin))
    throw InputError(fmt::format("map: the mesh's plan view [{}, {}] × [{}, {}] is empty", xmin, xmax, ymin, ymax));
  MapLayout layout;
  layout.width = options.width;
  layout.height = options.height;
  const double title = std::clamp(0.07 * options.height, 30.0, 80.0);
  const double caption = std::clamp(0.045 * options.height, 22.0, 50.0);
  const double legend = std::clamp(0.25 * options.width, 190.0, 420.0);
  const double margin = 14;
  const double right_edge = options.width - legend;  // where the legend starts when the map fills its room
  const double left = margin, right = right_edge - margin, top = title, bottom = options.height - caption;
  const double available_w = right - left, available_h = bottom - top;
  layout.metres_per_pixel = std::max((xmax - xmin) / available_w, (ymax - ymin) / available_h);
  const double w = (xmax - xmin) / layout.metres_per_pixel, h = (ymax - ymin) / layout.metres_per_pixel;
  // The map and the legend side by side, the pair centred: a tall map keeps its legend beside it.
  layout.panel_left = left + 0.5 * (available_w - w);
  layout.panel_right = layout.panel_left + w;
  layout.legend_left = layout.panel_right + 2 * margin;
  layout.panel_top = top + 0.5 * (available_h - h);
  layout.panel_bottom = layout.panel_top + h;
  layout.world_x0 = xmin;
  layout.world_y0 = ymin;
  layout.pixel_x0 = layout.panel_left;
  layout.pixel_y0 = layout.panel_bottom;
  return layout;
}

ScaleBar scale_bar(const MapLayout& layout) {
  ScaleBar bar;
  const double panel_metres = (layout.panel_right - layout.panel_left) * layout.metres_per_pixel;
  bar.metres = nice_step_below(0.25 * panel_metres);
  bar.pixels = bar.metres / layout.metres_per_pixel;
  bar.left = {layout.panel_left + 18, layout.panel_bottom - 22};
  bar.label = bar.metres >= 1000 ? fmt::format("{:g} km", bar.metres / 1000) : fmt::format("{:g} m", bar.metres);
  return bar;
}

double isochrone_interval(const HeightGrid& arrival, const MapOptions& options) {
  double earliest = 0, latest = 0;
  return interval_for(arrival, options, earliest, latest);
}

std::vector<double> isochrone_levels(const HeightGrid& arrival, const MapOptions& options) {
  double earliest = 0, latest = 0;
  const double interval = interval_for(arrival, options, earliest, latest);
  if (interval <= 0) return {};
  const double first = std::floor(earliest / interval) + 1, last = std::ceil(latest / interval) - 1;
  if (last - first > 200)
    throw InputError(fmt::format("isochrone interval {} s: {} lines between {} s and {} s (at most 200)", interval,
                                 last - first + 1, earliest, latest));
  std::vector<double> levels;
  for (double k = first; k <= last; ++k) levels.push_back(k * interval);
  return levels;
}

std::string time_label(double seconds, double interval, const MapOptions& options) {
  if (in_hours(interval, options)) return fmt::format("{:g} h", std::round(seconds / 36) / 100);
  return fmt::format("{:g} min", std::round(seconds / 0.6) / 100);
}

Rgb isochrone_colour(std::size_t index, std::size_t count) {
  return colormap(count < 2 ? 0.5 : double(index) / double(count - 1));
}

std::vector<Vec3> ignitions_from_arrival(const HeightGrid& grid) {
  const std::size_t rows = grid.rows, cols = grid.cols;
  auto value = [&](long r, long c) {
    if (r < 0 || c < 0 || r >= long(rows) || c >= long(cols)) return std::numeric_limits<double>::quiet_NaN();
    const double t = grid.at(std::size_t(r), std::size_t(c));
    return reached(t, grid.nodata) ? t : std::numeric_limits<double>::quiet_NaN();
  };
  // A cell is on an ignition plateau when no reached neighbour (8 of them) was reached earlier.
  std::vector<char> lowest(rows * cols, 0);
  for (long r = 0; r < long(rows); ++r)
    for (long c = 0; c < long(cols); ++c) {
      const double t = value(r, c);
      if (std::isnan(t)) continue;
      bool low = true;
      for (long dr = -1; dr <= 1 && low; ++dr)
        for (long dc = -1; dc <= 1 && low; ++dc) low = !(value(r + dr, c + dc) < t);
      lowest[std::size_t(r) * cols + std::size_t(c)] = low;
    }
  // Plateaus: connected cells (8 neighbours) of one arrival time.
  std::vector<Vec3> points;
  std::vector<char> seen(rows * cols, 0);
  std::vector<std::size_t> stack;
  for (std::size_t start = 0; start < rows * cols; ++start) {
    if (!lowest[start] || seen[start]) continue;
    const double t = grid.heights[start];
    double sx = 0, sy = 0;
    std::size_t n = 0;
    stack.assign(1, start);
    seen[start] = 1;
    while (!stack.empty()) {
      const std::size_t cell = stack.back();
      stack.pop_back();
      const long r = long(cell / cols), c = long(cell % cols);
      sx += grid.x_origin + (double(c) + 0.5) * grid.cell_size;
      sy += grid.y_origin + (double(rows) - double(r) - 0.5) * grid.cell_size;
      ++n;
      for (long dr = -1; dr <= 1; ++dr)
        for (long dc = -1; dc <= 1; ++dc) {
          const long rr = r + dr, cc = c + dc;
          if (rr < 0 || cc < 0 || rr >= long(rows) || cc >= long(cols)) continue;
          const std::size_t next = std::size_t(rr) * cols + std::size_t(cc);
          if (lowest[next] && !seen[next] && grid.heights[next] == t) seen[next] = 1, stack.push_back(next);
        }
    }
    points.emplace_back(sx / double(n), sy / double(n), 0.0);
  }
  return points;
}

std::string map_time_caption(const MapLayers& layers) {
  if (!layers.datetime.empty()) return layers.datetime;
  if (!layers.clock_start) return {};
  std::string text = "fire start " + format_iso8601(*layers.clock_start);
  if (layers.burnt_at) text = "map at " + format_iso8601(*layers.clock_start + *layers.burnt_at) + ", " + text;
  return text;
}

std::vector<int> place_labels(const std::vector<std::vector<LabelBox>>& candidates, const MapLayout& layout) {
  std::vector<int> chosen(candidates.size(), -1);
  std::vector<LabelBox> placed;
  auto overlaps = [](const LabelBox& a, const LabelBox& b) {
    return a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1;
  };
  for (std::size_t line = 0; line < candidates.size(); ++line)
    for (std::size_t k = 0; k < candidates[line].size(); ++k) {
      const LabelBox& box = candidates[line][k];
      if (box.x0 < layout.panel_left || box.x1 > layout.panel_right || box.y0 < layout.panel_top ||
          box.y1 > layout.panel_bottom)
        continue;
      if (std::any_of(placed.begin(), placed.end(), [&](const LabelBox& other) { return overlaps(box, other); }))
        continue;
      chosen[line] = int(k);
      placed.push_back(box);
      break;
    }
  return chosen;
}

std::vector<std::array<Vec3, 2>> isochrone_segments(const HeightGrid& grid, double level) {
  std::vector<std::array<Vec3, 2>> segments;
  if (grid.cols < 2 || grid.rows < 2) return segments;
  auto centre = [&](std::size_t r, std::size_t c) {
    return Vec3(grid.x_origin + (double(c) + 0.5) * grid.cell_size,
                grid.y_origin + (double(grid.rows - 1 - r) + 0.5) * grid.cell_size, 0.0);
  };
  for (std::size_t r = 0; r + 1 < grid.rows; ++r)
    for (std::size_t c = 0; c + 1 < grid.cols; ++c) {
      // Corners clockwise from the north-west one; edge i joins corner i and corner i + 1.
      const std::array<std::pair<std::size_t, std::size_t>, 4> at = {{{r, c}, {r, c + 1}, {r + 1, c + 1}, {r + 1, c}}};
      std::array<double, 4> value;
      bool valid = true;
      for (int i = 0; i < 4; ++i) {
        value[i] = grid.at(at[i].first, at[i].second);
        valid = valid && reached(value[i], grid.nodata);
      }
      if (!valid) continue;
      std::array<bool, 4> above;
      for (int i = 0; i < 4; ++i) above[i] = value[i] >= level;
      auto crossing = [&](int edge) {
        const int i = edge, j = (edge + 1) % 4;
        const double s = (level - value[i]) / (value[j] - value[i]);
        return centre(at[i].first, at[i].second) * (1 - s) + centre(at[j].first, at[j].second) * s;
      };
      std::vector<int> crossed;
      for (int e = 0; e < 4; ++e)
        if (above[e] != above[(e + 1) % 4]) crossed.push_back(e);
      if (crossed.size() == 2) {
        segments.push_back({crossing(crossed[0]), crossing(crossed[1])});
      } else if (crossed.size() == 4) {
        // A saddle: the mean of the corners tells whether corners 0 and 2 are joined across it.
        const bool centre_above = (value[0] + value[1] + value[2] + value[3]) / 4 >= level;
        if (centre_above == above[0]) {
          segments.push_back({crossing(0), crossing(1)});  // around corner 1
          segments.push_back({crossing(2), crossing(3)});  // around corner 3
        } else {
          segments.push_back({crossing(3), crossing(0)});  // around corner 0
          segments.push_back({crossing(1), crossing(2)});  // around corner 2
        }
      }
    }
  return segments;
}

void draw_fire_map(const std::filesystem::path& png, const SurfaceMesh& mesh, const MapLayers& layers,
                   const MapOptions& options) {
  if (!(options.sun_altitude >= 0 && options.sun_altitude <= 90))
    throw InputError(fmt::format("map: sun altitude {} degrees, expected from 0 to 90", options.sun_altitude));
  if (!(options.z_factor > 0) || !std::isfinite(options.z_factor))
    throw InputError(fmt::format("map: z factor {}, expected > 0", options.z_factor));
  if (!(options.burnt_opacity >= 0 && options.burnt_opacity <= 1))
    throw InputError(fmt::format("map: burnt-area opacity {}, expected from 0 to 1", options.burnt_opacity));
  if (!(options.isochrone_interval >= 0) || !std::isfinite(options.isochrone_interval))
    throw InputError(fmt::format("map: isochrone interval {} s, expected ≥ 0 (0: automatic)", options.isochrone_interval));
  map_layout(0, 0, 1, 1, options);  // the size, checked before the module is loaded
  const map_module::Api& module = map_module::module_for(png);
  std::string bytes, error;
  if (!module.draw_png(mesh, layers, options, bytes, error)) throw file_error(png, error);
  write_atomically(png, [&](std::ostream& out) { out.write(bytes.data(), std::streamsize(bytes.size())); });
}

std::string crs_name_of_wkt(const std::string& wkt) {
  const auto open = wkt.find('"');
  if (open == std::string::npos) return {};
  const auto close = wkt.find('"', open + 1);
  if (close == std::string::npos) return {};
  return wkt.substr(open + 1, close - open - 1);
}

RunMap load_run_map(const std::filesystem::path& run_dir) {
  namespace fs = std::filesystem;
  const fs::path mesh_file = run_dir / "final.mesh";
  if (!fs::exists(mesh_file))
    throw file_error(mesh_file, "no final mesh: expected a finished run directory (bodyfit run ... -o DIR) or a mesh file");
  RunMap run;
  run.mesh = read_mesh(mesh_file);
  run.mesh.garbage_collection();
  run.layers = load_map_layers(run_dir);
  return run;
}

MapLayers load_map_layers(const std::filesystem::path& run_dir) {
  namespace fs = std::filesystem;
  MapLayers layers;
  for (const char* name : {"arrival_time.tif", "arrival_time.asc"})  // the fire model's format, GeoTIFF by default
    if (const fs::path arrival = run_dir / name; fs::exists(arrival)) {
      layers.arrival = read_raster_values(arrival);
      layers.crs_name = crs_name_of_wkt(layers.arrival.crs);
      break;
    }
  if (const fs::path case_file = run_dir / "case.toml"; fs::exists(case_file)) {
    const toml::table table = read_case_table(case_file);
    if (table["region"]["shape"].value_or(std::string()) == "disks") {
      if (const toml::array* centres = table["region"]["centers"].as_array())
        for (const toml::node& centre : *centres)
          if (const toml::array* xy = centre.as_array(); xy && xy->size() >= 2)
            layers.ignitions.emplace_back((*xy)[0].value_or(0.0), (*xy)[1].value_or(0.0), 0.0);
    } else if (layers.arrival.cols > 0) {
      // Ignitions from a layer (points, lines, polygons, some later than others), or any shape:
      // where the arrival time starts.
      layers.ignitions = ignitions_from_arrival(layers.arrival);
    }
    if (const auto start = table["time"]["start"].value<std::string>()) {
      layers.clock_start = parse_iso8601(*start);
    }
  }
  return layers;
}

}  // namespace bodyfit
