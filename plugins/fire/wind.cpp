#include "wind.hpp"

#include "csv_table.hpp"

#include <bodyfit/app/clock_time.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/parameters.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string_view>
#include <tuple>

namespace bodyfit::fire {
namespace {

constexpr double kDegree = M_PI / 180.0;

/// A weather report's wind: its speed and the direction it blows from, clockwise from north (a
/// wind from 270° blows towards +x).
Vec3 wind_from_direction(double speed, double direction_deg) {
  const double from = direction_deg * kDegree;
  return Vec3(-speed * std::sin(from), -speed * std::cos(from), 0);
}

// Winds beyond this are not winds near the ground (the strongest measured, 113 m/s, in a cyclone):
// a unit mistake (km/h, knots, cm/s) or a damaged value, refused where it is read.
constexpr double kMaxWind = 150;

std::string too_strong(double speed) {
  return fmt::format("a wind of {:.4g} m/s is beyond {} m/s (the strongest measured near the ground is 113 m/s): "
                     "a unit mistake (km/h? knots?) or a damaged value",
                     speed, kMaxWind);
}

/// A wind raster: its NODATA cells take the nearest valid value (a wind field has no holes).
HeightGrid read_wind_raster(const std::filesystem::path& file, const RasterReader& read) {
  HeightGrid grid = read ? read(file) : read_raster(file);
  if (const std::size_t filled = fill_nodata(grid))
    spdlog::warn("{}: {} NODATA cell(s) of {} filled with the nearest valid wind", file.string(), filled,
                 grid.heights.size());
  return grid;
}

}  // namespace

WindSeries read_wind_series(const std::filesystem::path& file) {
  constexpr std::string_view expected = "time,speed,direction_deg or time,u,v";
  const Csv csv = read_csv(file, "the wind series", expected);
  const bool components = csv.has("u") || csv.has("v");
  if (components) require_columns(csv, {"time", "u", "v"}, expected);
  else require_columns(csv, {"time", "speed", "direction_deg"}, expected);
  WindSeries series{.file = file};
  series.times = read_series_times(csv, series.clock_times);
  for (const CsvRow& row : csv.rows) {
    if (components) {
      series.uniform.emplace_back(finite_number(csv, row, "u"), finite_number(csv, row, "v"), 0);
    } else {
      const double speed = finite_number(csv, row, "speed");
      if (speed < 0) throw file_error(file, row.line, fmt::format("speed: {} is negative (m/s, expected ≥ 0)", speed));
      series.uniform.push_back(wind_from_direction(speed, finite_number(csv, row, "direction_deg")));
    }
    const double speed = std::hypot(series.uniform.back()[0], series.uniform.back()[1]);  // no overflow at 1e300
    if (speed > kMaxWind) throw file_error(file, row.line, too_strong(speed));
  }
  return series;
}

WindSeries read_wind_grid_series(const std::filesystem::path& file, const RasterReader& read) {
  constexpr std::string_view expected = "time,u_file,v_file";
  const Csv csv = read_csv(file, "the wind series", expected);
  require_columns(csv, {"time", "u_file", "v_file"}, expected);
  WindSeries series{.file = file};
  series.times = read_series_times(csv, series.clock_times);
  for (const CsvRow& row : csv.rows) {
    for (auto [column, grids, files] : {std::tuple{"u_file", &series.u, &series.u_files},
                                        std::tuple{"v_file", &series.v, &series.v_files}}) {
      const std::string& name = row.fields[csv.column(column)];
      if (name.empty()) throw file_error(file, row.line, fmt::format("{}: empty (expected a raster's file name)", column));
      const std::filesystem::path raster = (file.parent_path() / name).lexically_normal();
      try {
        grids->push_back(read_wind_raster(raster, read));
      } catch (const InputError& e) {
        throw file_error(file, row.line, fmt::format("{}: {}", column, e.what()));
      }
      files->push_back(raster);
      const HeightGrid& first = series.u.front();
      const HeightGrid& grid = grids->back();
      if (!same_frame(first, grid))
        throw file_error(file, row.line,
                         fmt::format("{}: {} is {}×{} cells of {} m from ({}, {}), {} is {}×{} of {} m from ({}, {}): the "
                                     "rasters of a grid series share one frame",
                                     column, raster.string(), grid.cols, grid.rows, grid.cell_size, grid.x_origin,
                                     grid.y_origin, series.u_files.front().string(), first.cols, first.rows,
                                     first.cell_size, first.x_origin, first.y_origin));
      require_same_crs(first, series.u_files.front(), grid, raster);
    }
  }
  return series;
}

TimeBracket bracket_time(const std::vector<double>& times, double t) {
  if (times.empty() || t <= times.front()) return {};
  if (t >= times.back()) return {times.size() - 1, times.size() - 1, 0};
  const std::size_t next = std::size_t(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  const std::size_t index = next - 1;
  return {index, next, (t - times[index]) / (times[next] - times[index])};
}

void WindField::set_clock(std::optional<double> clock_start) {
  if (on_clock_ || series.times.empty()) return;
  run_times_ = series_run_times(series.times, series.clock_times, clock_start, series.file);
  on_clock_ = true;
}

Vec3 WindField::at(const Vec3& x, double t) const {
  if (type == "uniform") return uniform;
  if (type == "rotating") return scale * Vec3(x[1] - center[1], -(x[0] - center[0]), 0);
  if (type == "grid") return Vec3(u.sample(x[0], x[1]), v.sample(x[0], x[1]), 0);
  if (type == "series" || type == "grid_series") {
    if (!on_clock_) throw std::logic_error("WindField::at: the series is not on the run's clock (set_clock)");
    // a + w·(b − a): exactly a where the two ends are equal (a constant series is a uniform wind).
    const TimeBracket b = bracket_time(run_times_, t);
    if (type == "series") return series.uniform[b.index] + b.weight * (series.uniform[b.next] - series.uniform[b.index]);
    const double u0 = series.u[b.index].sample(x[0], x[1]), v0 = series.v[b.index].sample(x[0], x[1]);
    if (b.next == b.index) return Vec3(u0, v0, 0);
    const double u1 = series.u[b.next].sample(x[0], x[1]), v1 = series.v[b.next].sample(x[0], x[1]);
    return Vec3(u0 + b.weight * (u1 - u0), v0 + b.weight * (v1 - v0), 0);
  }
  return Vec3(0, 0, 0);
}

std::vector<std::pair<const HeightGrid*, std::filesystem::path>> WindField::rasters() const {
  std::vector<std::pair<const HeightGrid*, std::filesystem::path>> list;
  if (u.cols > 0) list.emplace_back(&u, u_file);
  if (v.cols > 0) list.emplace_back(&v, v_file);
  if (!series.u.empty()) list.emplace_back(&series.u.front(), series.u_files.front());  // all share its system
  return list;
}

std::vector<ParameterDecl> wind_parameters() {
  return {
      ParameterDecl::choice("wind.type", {"none", "uniform", "rotating", "grid", "series", "grid_series"},
                            "the wind: none, uniform, rotating about a centre, gridded, a series in time, gridded in time")
          .fallback("none"),
      ParameterDecl::numbers("wind.velocity", 2, "m/s", "uniform: the wind (x, y)").fallback(std::vector<double>{0, 0}),
      ParameterDecl::number("wind.speed", "m/s", "uniform: the wind's speed, instead of velocity").at_least(0),
      ParameterDecl::number("wind.direction_deg", "degrees",
                            "uniform, with speed: the direction it blows from, clockwise from north"),
      ParameterDecl::numbers("wind.center", 2, "m", "rotating: the centre (x, y): U = scale·(y − yc, −(x − xc), 0)")
          .computed("the centre of the domain"),
      ParameterDecl::number("wind.scale", "1/s", "rotating: the angular rate (m/s of wind per m from the centre)")
          .fallback(1e-3),
      ParameterDecl::path("wind.u_file", "grid: the x component, an ESRI ASCII grid or GeoTIFF (m/s)"),
      ParameterDecl::path("wind.v_file", "grid: the y component (m/s)"),
      ParameterDecl::path("wind.file", "series: CSV time,speed,direction_deg or time,u,v; grid_series: CSV "
                                       "time,u_file,v_file (rasters relative to it); times in s after t = 0 or ISO "
                                       "8601 ([time] start); linear in time on (u, v), the end values held outside"),
      ParameterDecl::choice("wind.height", {"midflame", "20ft", "10m"},
                            "the height the wind is given at: midflame, or 20 ft / 10 m above the vegetation "
                            "(spread = \"rothermel\": brought to midflame by the fuel's wind adjustment factor)")
          .fallback("midflame"),
  };
}

WindField read_wind_table(Parameters& w, const RasterReader& read) {
  WindField wind;
  wind.type = w.choice("type");
  const auto applies_to = [&](const char* key, const char* types) {
    w.not_used(key, fmt::format("it applies to type = {} (the wind is type = \"{}\")", types, wind.type));
  };
  if (wind.type == "uniform") {
    // As a velocity, or as a weather report gives it (what an ensemble samples).
    if (w.has("speed") || w.has("direction_deg")) {
      if (w.has("velocity")) w.fail("velocity", "give either velocity or speed and direction_deg");
      const double speed = w.required_number("speed");
      wind.uniform = wind_from_direction(speed, w.required_number("direction_deg"));
      if (speed > kMaxWind) w.fail("speed", too_strong(speed));
    } else {
      const auto velocity = w.numbers("velocity");
      wind.uniform = Vec3(velocity[0], velocity[1], 0);
      if (const double speed = std::hypot(velocity[0], velocity[1]); speed > kMaxWind) w.fail("velocity", too_strong(speed));
    }
  } else {
    for (const char* key : {"velocity", "speed", "direction_deg"}) applies_to(key, "\"uniform\"");
  }
  if (wind.type == "rotating") {
    if (w.has("center")) {
      const auto center = w.numbers("center", {});
      wind.has_center = true;
      wind.center = Vec3(center[0], center[1], 0);
    }
    wind.scale = w.number("scale");
  } else {
    for (const char* key : {"center", "scale"}) applies_to(key, "\"rotating\"");
  }
  if (wind.type == "grid") {
    if (!w.has("u_file") || !w.has("v_file"))
      throw InputError("[model.wind] type = \"grid\" needs u_file and v_file (ESRI ASCII grids)");
    wind.u_file = w.path("u_file");
    wind.v_file = w.path("v_file");
    wind.u = read_wind_raster(wind.u_file, read);
    wind.v = read_wind_raster(wind.v_file, read);
    if (wind.u.heights.size() == wind.v.heights.size())
      for (std::size_t i = 0; i < wind.u.heights.size(); ++i)
        if (const double speed = std::hypot(wind.u.heights[i], wind.v.heights[i]); speed > kMaxWind)
          throw InputError(fmt::format("{} and {}: the cell at row {}, column {}: {}", wind.u_file.string(),
                                       wind.v_file.string(), i / wind.u.cols + 1, i % wind.u.cols + 1,
                                       too_strong(speed)));
  } else {
    for (const char* key : {"u_file", "v_file"}) applies_to(key, "\"grid\"");
  }
  if (wind.type == "series" || wind.type == "grid_series") {
    if (!w.has("file"))
      w.fail(fmt::format("type = \"{}\" needs file = \"wind.csv\" ({})", wind.type,
                         wind.type == "series" ? "time,speed,direction_deg or time,u,v" : "time,u_file,v_file"));
    const std::filesystem::path file = w.path("file");
    wind.series = wind.type == "series" ? read_wind_series(file) : read_wind_grid_series(file, read);
    if (!wind.series.clock_times) wind.set_clock(std::nullopt);
  } else {
    applies_to("file", "\"series\" or \"grid_series\"");
  }
  return wind;
}

}  // namespace bodyfit::fire
