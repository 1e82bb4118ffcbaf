#pragma once
// The wind of the fire model: a horizontal U(x, t) in m/s, static (uniform, rotating, one raster
// pair) or a time series (one uniform wind or one raster pair per time, linearly interpolated in
// time on the components u, v; the end values held before the first time and after the last).
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/mesh.hpp>
#include <bodyfit/parameters.hpp>

#include <toml++/toml.h>

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace bodyfit::fire {

/// Winds given at increasing times: uniform ones (`series`) or raster pairs (`grid_series`).
struct WindSeries {
  std::filesystem::path file{};     ///< the CSV, for messages
  std::vector<double> times{};      ///< as the file gives them: s after t = 0, or s since the epoch
  bool clock_times = false;         ///< the file gives ISO 8601 date-times (the run needs [time] start)
  std::vector<Vec3> uniform{};      ///< series: (u, v, 0) per time
  std::vector<HeightGrid> u{}, v{}; ///< grid_series: the component rasters per time, on one frame
  std::vector<std::filesystem::path> u_files{}, v_files{};
};

/// `time,speed,direction_deg` (the direction the wind blows from, degrees clockwise from north) or
/// `time,u,v` (m/s). Times are seconds after t = 0 or ISO 8601 date-times (all of one kind),
/// strictly increasing. Errors are InputError "<file>:<line>: …".
WindSeries read_wind_series(const std::filesystem::path& csv);
/// How the model reads a raster (the fire model: checked against the surface's coordinate system,
/// and warped like the DEM when the case reprojects it); empty: read_raster as it is.
using RasterReader = std::function<HeightGrid(const std::filesystem::path&)>;

/// `time,u_file,v_file`: raster names relative to the CSV, read like a wind grid (NODATA cells
/// take the nearest valid value), every raster on the frame of the first (checked) and in its
/// coordinate system.
WindSeries read_wind_grid_series(const std::filesystem::path& csv, const RasterReader& read = {});

/// Where t falls among increasing `times`: the value there is a[index] + weight·(a[next] − a[index])
/// (next = index and weight 0 at or outside the ends: the end values held).
struct TimeBracket {
  std::size_t index = 0, next = 0;
  double weight = 0;
};
TimeBracket bracket_time(const std::vector<double>& times, double t);

/// Horizontal wind U(x, t) in m/s.
struct WindField {
  std::string type = "none";  ///< none | uniform | rotating | grid | series | grid_series
  Vec3 uniform{0, 0, 0};
  Vec3 center{0, 0, 0};
  bool has_center = false;
  double scale = 1e-3;        ///< rotating: U = scale·(y − yc, −(x − xc), 0)
  HeightGrid u, v;            ///< grid: components on rasters
  std::filesystem::path u_file, v_file;
  WindSeries series;          ///< series, grid_series

  /// Put the series' times on the run's clock (t = 0 at `clock_start`, seconds since the epoch);
  /// InputError naming the file when they are date-times and the run has no [time] start.
  void set_clock(std::optional<double> clock_start);
  /// U at x and time t (after set_clock for a series).
  Vec3 at(const Vec3& x, double t) const;
  /// The rasters read, with their files (for the case's coordinate-system check).
  std::vector<std::pair<const HeightGrid*, std::filesystem::path>> rasters() const;

 private:
  std::vector<double> run_times_;  ///< the series' times in s after t = 0
  bool on_clock_ = false;
};

/// The declarations of [model.wind] (keys "wind.<key>").
std::vector<ParameterDecl> wind_parameters();
/// The [model.wind] table (docs/reference/fire_model.md) read through wind_parameters(): the type and the keys it
/// uses (the others are refused when set), files relative to the case.
WindField read_wind_table(Parameters& wind, const RasterReader& read = {});

}  // namespace bodyfit::fire
