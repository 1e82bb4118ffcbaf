#pragma once
// The fuel moistures of a fire ([model.moisture]): constant (five classes in percent, or a Scott &
// Burgan scenario), in time (a CSV series, uniform in space, linear in time, the end values held)
// or per cell (a raster per class, in percent, constant in time).
#include "fuel.hpp"
#include "wind.hpp"

#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <utility>
#include <vector>

namespace bodyfit::fire {

class MoistureField {
 public:
  enum class Kind { constant, series, maps };

  Kind kind() const { return kind_; }
  /// Put a series' times on the run's clock (t = 0 at `clock_start`, seconds since the epoch).
  void set_clock(std::optional<double> clock_start);
  /// The moistures at (x, y) and time t (after set_clock for a series) of the fuel `fuel_code`:
  /// its row of the per-fuel table when it has one.
  FuelMoisture at(double x, double y, double t, int fuel_code = 0) const;
  /// Moistures per fuel code: `code,dead_1h,dead_10h,dead_100h,live_herb,live_woody` (percent), a
  /// fuel's row replacing the field's moistures wherever that fuel is. Errors name the file and line.
  void read_per_fuel(const std::filesystem::path& csv);
  /// The rasters read, with their files (for the case's coordinate-system check).
  std::vector<std::pair<const HeightGrid*, std::filesystem::path>> rasters() const;

  static MoistureField constant(const FuelMoisture& moisture);
  /// `time,dead_1h,dead_10h,dead_100h,live_herb,live_woody` (percent); times in seconds after
  /// t = 0 or ISO 8601 date-times, strictly increasing. Errors are InputError "<file>:<line>: …".
  static MoistureField series(const std::filesystem::path& csv);

  friend MoistureField read_moisture(Parameters& moisture, const RasterReader& read);

 private:
  Kind kind_ = Kind::constant;
  FuelMoisture constant_{};
  std::filesystem::path file_{};
  std::vector<double> times_{}, run_times_{};
  bool clock_times_ = false, on_clock_ = false;
  std::vector<FuelMoisture> values_{};
  std::array<HeightGrid, kFuelClasses> maps_{};  ///< a class without a raster has cols == 0
  std::array<std::filesystem::path, kFuelClasses> map_files_{};
  std::map<int, FuelMoisture> per_fuel_{};
};

/// The declarations of [model.moisture] (keys "moisture.<key>").
std::vector<ParameterDecl> moisture_parameters();
/// [model.moisture] read through moisture_parameters(): `scenario` ("D2L2"); or each class
/// (dead_1h, dead_10h, dead_100h, live_herb, live_woody, in percent) as a number or a raster
/// (`dead_1h_map`, …: percent per cell, read with `read`); or `file`, a series in time; with any of
/// them, `per_fuel`, a table of moistures by fuel code. Mixing the first three,
/// a class missing, or a value that is not a percentage are errors naming the key, file or cell.
MoistureField read_moisture(Parameters& moisture, const RasterReader& read = {});

}  // namespace bodyfit::fire
