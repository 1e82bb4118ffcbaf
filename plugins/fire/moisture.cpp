#include "moisture.hpp"

#include "csv_table.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/parameters.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <string>

namespace bodyfit::fire {
namespace {

constexpr const char* kClassKeys[kFuelClasses] = {"dead_1h", "dead_10h", "dead_100h", "live_herb", "live_woody"};

std::string map_key(int k) { return std::string(kClassKeys[k]) + "_map"; }

// A moisture raster: percent per cell, each valid cell a percentage; NODATA cells take the nearest
// valid value (a moisture field has no holes where there is fuel).
HeightGrid read_moisture_raster(const std::filesystem::path& file, const RasterReader& read) {
  HeightGrid grid = read ? read(file) : read_raster(file);
  for (std::size_t row = 0; row < grid.rows; ++row)
    for (std::size_t col = 0; col < grid.cols; ++col) {
      if (!grid.valid(row, col)) continue;
      const std::string problem = moisture_percent_problem(grid.at(row, col));
      if (!problem.empty())
        throw file_error(file, fmt::format("the cell at row {}, column {}: {}", row + 1, col + 1, problem));
    }
  if (const std::size_t filled = fill_nodata(grid))
    spdlog::warn("{}: {} NODATA cell(s) of {} filled with the nearest valid moisture", file.string(), filled,
                 grid.heights.size());
  return grid;
}

}  // namespace

MoistureField MoistureField::constant(const FuelMoisture& moisture) {
  MoistureField field;
  field.constant_ = moisture;
  return field;
}

MoistureField MoistureField::series(const std::filesystem::path& file) {
  constexpr std::string_view expected = "time,dead_1h,dead_10h,dead_100h,live_herb,live_woody (percent)";
  const Csv csv = read_csv(file, "the moisture series", expected);
  require_columns(csv, {"time", "dead_1h", "dead_10h", "dead_100h", "live_herb", "live_woody"}, expected);
  MoistureField field;
  field.kind_ = Kind::series;
  field.file_ = file;
  field.times_ = read_series_times(csv, field.clock_times_);
  for (const CsvRow& row : csv.rows) {
    FuelMoisture m;
    for (int k = 0; k < kFuelClasses; ++k) {
      const double percent = finite_number(csv, row, kClassKeys[k]);
      const std::string problem = moisture_percent_problem(percent);
      if (!problem.empty()) throw file_error(file, row.line, fmt::format("{}: {}", kClassKeys[k], problem));
      m.value[std::size_t(k)] = percent / 100;
    }
    field.values_.push_back(m);
  }
  return field;
}

void MoistureField::set_clock(std::optional<double> clock_start) {
  if (kind_ != Kind::series || on_clock_) return;
  run_times_ = series_run_times(times_, clock_times_, clock_start, file_);
  on_clock_ = true;
}

void MoistureField::read_per_fuel(const std::filesystem::path& file) {
  constexpr std::string_view expected = "code,dead_1h,dead_10h,dead_100h,live_herb,live_woody (percent)";
  const Csv csv = read_csv(file, "the moistures per fuel", expected);
  require_columns(csv, {"code", "dead_1h", "dead_10h", "dead_100h", "live_herb", "live_woody"}, expected);
  per_fuel_.clear();
  for (const CsvRow& row : csv.rows) {
    const double code = finite_number(csv, row, "code");
    if (code != std::round(code) || code < 1 || code > 1e9)
      throw file_error(file, row.line, fmt::format("code: {} is not a fuel code (a positive integer)", code));
    FuelMoisture m;
    for (int k = 0; k < kFuelClasses; ++k) {
      const double percent = finite_number(csv, row, kClassKeys[k]);
      const std::string problem = moisture_percent_problem(percent);
      if (!problem.empty()) throw file_error(file, row.line, fmt::format("{}: {}", kClassKeys[k], problem));
      m.value[std::size_t(k)] = percent / 100;
    }
    if (!per_fuel_.emplace(int(code), m).second)
      throw file_error(file, row.line, fmt::format("code {} is given twice", code));
  }
}

FuelMoisture MoistureField::at(double x, double y, double t, int fuel_code) const {
  if (!per_fuel_.empty())
    if (const auto it = per_fuel_.find(fuel_code); it != per_fuel_.end()) return it->second;
  switch (kind_) {
    case Kind::constant: return constant_;
    case Kind::series: {
      if (!on_clock_) throw std::logic_error("MoistureField::at: the series is not on the run's clock (set_clock)");
      const TimeBracket b = bracket_time(run_times_, t);
      FuelMoisture m;
      for (int k = 0; k < kFuelClasses; ++k) {
        const double a = values_[b.index].value[std::size_t(k)], c = values_[b.next].value[std::size_t(k)];
        m.value[std::size_t(k)] = a + b.weight * (c - a);
      }
      return m;
    }
    case Kind::maps: {
      FuelMoisture m = constant_;
      for (int k = 0; k < kFuelClasses; ++k)
        if (maps_[std::size_t(k)].cols > 0) m.value[std::size_t(k)] = maps_[std::size_t(k)].sample(x, y) / 100;
      return m;
    }
  }
  return constant_;
}

std::vector<std::pair<const HeightGrid*, std::filesystem::path>> MoistureField::rasters() const {
  std::vector<std::pair<const HeightGrid*, std::filesystem::path>> rasters;
  for (int k = 0; k < kFuelClasses; ++k)
    if (maps_[std::size_t(k)].cols > 0) rasters.emplace_back(&maps_[std::size_t(k)], map_files_[std::size_t(k)]);
  return rasters;
}

std::vector<ParameterDecl> moisture_parameters() {
  std::vector<ParameterDecl> declared = {
      ParameterDecl::string("moisture.scenario", "Scott & Burgan's moisture scenario D1L1 … D4L4 (dead 3/4/5 % to "
                                                 "12/13/14 %, live herbaceous/woody 30/60 % to 120/150 %), instead of "
                                                 "the five classes"),
      ParameterDecl::path("moisture.per_fuel", "moistures by fuel code: CSV code,dead_1h,dead_10h,dead_100h,"
                                               "live_herb,live_woody (percent), replacing the others for those fuels"),
      ParameterDecl::path("moisture.file", "the moistures in time: CSV time,dead_1h,dead_10h,dead_100h,live_herb,"
                                           "live_woody (percent; times in s after t = 0 or ISO 8601), linear in time, "
                                           "the end values held")};
  const char* what[kFuelClasses] = {"1-h dead fuel moisture", "10-h dead fuel moisture", "100-h dead fuel moisture",
                                    "live herbaceous fuel moisture", "live woody fuel moisture"};
  for (int k = 0; k < kFuelClasses; ++k) {
    declared.push_back(ParameterDecl::number(std::string("moisture.") + kClassKeys[k], "%", what[k]).at_least(0));
    declared.push_back(ParameterDecl::path("moisture." + map_key(k),
                                           fmt::format("the {} per cell, a raster in percent (instead of {})", what[k],
                                                       kClassKeys[k])));
  }
  return declared;
}

MoistureField read_moisture(Parameters& m, const RasterReader& read) {
  bool any_class = false;
  for (int k = 0; k < kFuelClasses; ++k) any_class = any_class || m.has(kClassKeys[k]) || m.has(map_key(k));
  MoistureField field;
  if (m.has("scenario")) {
    const std::string scenario = m.string("scenario");
    if (any_class || m.has("file")) m.fail("scenario", "give either a scenario, the classes or a file, not several");
    FuelMoisture moisture;
    if (!moisture_scenario(scenario, moisture))
      m.fail("scenario", fmt::format("'{}' is not a moisture scenario (D1L1 … D4L4: Scott & Burgan 2005)", scenario));
    field = MoistureField::constant(moisture);
  } else if (m.has("file")) {
    if (any_class) m.fail("file", "give either a file (the moistures in time) or the classes, not both");
    field = MoistureField::series(m.path("file"));
  } else {
    if (!any_class)
      m.fail("expected the fuel moistures: scenario = \"D2L2\", dead_1h, dead_10h, dead_100h, live_herb and "
             "live_woody in percent (each a number or a raster: dead_1h_map, …), or file = a series in time");
    for (int k = 0; k < kFuelClasses; ++k) {
      const std::size_t i = std::size_t(k);
      if (m.has(map_key(k))) {
        if (m.has(kClassKeys[k]))
          m.fail(map_key(k), fmt::format("give either {} or {}, not both", kClassKeys[k], map_key(k)));
        field.map_files_[i] = m.path(map_key(k));
        field.maps_[i] = read_moisture_raster(field.map_files_[i], read);
        field.kind_ = MoistureField::Kind::maps;
        continue;
      }
      const double percent = m.required_number(kClassKeys[k]);
      const std::string problem = moisture_percent_problem(percent);
      if (!problem.empty()) m.fail(kClassKeys[k], problem);
      field.constant_.value[i] = percent / 100;
    }
  }
  if (m.has("per_fuel")) field.read_per_fuel(m.path("per_fuel"));
  return field;
}

}  // namespace bodyfit::fire
