#pragma once
// Surface fuels as data: the fuel models of a fuel table (loads by size class, surface-area-to-
// volume ratios, bed depth, moisture of extinction, heat content), held in SI units, and the
// moistures of the fuel classes. Shipped tables: Anderson (1982) 13 and Scott & Burgan (2005) 40.
#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace bodyfit::fire {

/// The fuel classes of Rothermel's model, in the tables' column order.
enum FuelClass : int { dead_1h = 0, dead_10h = 1, dead_100h = 2, live_herb = 3, live_woody = 4 };
inline constexpr int kFuelClasses = 5;
/// Column names of the classes: "1h", "10h", "100h", "live_herb", "live_woody".
std::string_view fuel_class_name(int fuel_class);

/// One fuel model, SI units.
struct FuelModel {
  int code = 0;              ///< the fuel raster's code (Scott & Burgan: 101 for GR1)
  std::string name;          ///< "GR1", "FM1"
  std::string description;
  bool dynamic = false;      ///< live herbaceous load cures into a dead class with its moisture
  std::array<double, kFuelClasses> load{};  ///< oven-dry loads, kg/m²
  std::array<double, kFuelClasses> sav{};   ///< surface-area-to-volume ratios, 1/m
  double depth = 0;                ///< fuel bed depth, m
  double extinction_moisture = 0;  ///< of the dead fuel, fraction
  double heat_dead = 0, heat_live = 0;  ///< low heat content, kJ/kg

  /// Some load on a bed of some depth: a model that carries fire (NB models do not).
  bool burnable() const;
};

/// A fuel table: the models by code.
struct FuelTable {
  std::string source;  ///< "scott_burgan40", "anderson13" or the CSV's path
  std::vector<FuelModel> models;

  /// The model of a code, or nullptr.
  const FuelModel* find(int code) const;
  /// The model named `code_or_name` ("GR2", "102": either), or nullptr.
  const FuelModel* find(std::string_view code_or_name) const;
};

/// A fuel table from CSV: a header `code,name,dynamic,load_1h[unit],…` whose quantities carry
/// their unit in brackets (docs/reference/fire_model.md, "Fuel tables"), one model per row. Loads in
/// t/ac, lb/ft², kg/m² or t/ha; surface-area-to-volume ratios in 1/ft, 1/m or 1/cm; depth in ft, m
/// or cm; moisture of extinction in % or fraction; heat content in BTU/lb, kJ/kg or MJ/kg. Errors
/// (a negative load or ratio, a load without its ratio, a repeated code, an unknown unit) are
/// InputError "<file>:<line>: …".
FuelTable read_fuel_table(const std::filesystem::path& csv);
/// The same from the CSV's text; `source` names it.
FuelTable parse_fuel_table(std::string_view text, const std::string& source);

/// The names of the tables compiled in: "anderson13", "scott_burgan40".
std::vector<std::string> builtin_fuel_tables();
/// A table compiled in by its name, or the CSV file `name_or_file`.
FuelTable fuel_table(const std::string& name_or_file, const std::filesystem::path& file = {});
/// The CSV text of a table compiled in (what `bodyfit ros --print-table` shows); empty when unknown.
std::string_view builtin_fuel_table_text(std::string_view name);

/// Moisture contents per class, fractions of the oven-dry mass.
struct FuelMoisture {
  std::array<double, kFuelClasses> value{};
};

/// Scott & Burgan's (2005) moisture scenarios, "D1L1" … "D4L4": dead 1-h/10-h/100-h of 3/4/5 %
/// (D1, very low) to 12/13/14 % (D4, high), live herbaceous/woody of 30/60 % (L1, fully cured) to
/// 120/150 % (L4, fully green). std::nullopt-like: `ok` false for an unknown name.
bool moisture_scenario(std::string_view name, FuelMoisture& moisture);

/// A moisture in percent as the user gave it: an InputError-ready reason when it is not one
/// (negative, above 500 %, or below 1 where a dead class is given as a fraction: "0.06 looks like a
/// fraction: moistures are in percent (6 for 6 %)"); empty when it is fine.
std::string moisture_percent_problem(double percent);

}  // namespace bodyfit::fire
