#include "fuel.hpp"

#include "csv_table.hpp"

#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>

namespace bodyfit::fire {
namespace detail {
extern const std::string_view kAnderson13Csv;
extern const std::string_view kScottBurgan40Csv;
}  // namespace detail

namespace {

constexpr std::string_view kExpected =
    "code,name,dynamic,load_1h[t/ac],load_10h[…],load_100h[…],load_live_herb[…],load_live_woody[…],sav_1h[1/ft],"
    "sav_live_herb[…],sav_live_woody[…],depth[ft],extinction_moisture[%],heat_dead[BTU/lb],heat_live[BTU/lb] and "
    "optionally sav_10h[…], sav_100h[…], description";

// The standard ratios of the 10-h and 100-h classes when a table does not give them (1/ft).
constexpr double kSav10hPerFoot = 109, kSav100hPerFoot = 30;
constexpr double kFoot = 0.3048;

// Conversions to SI of the units a table may give, by quantity.
const std::map<std::string_view, double>& units_of(std::string_view quantity) {
  static const std::map<std::string_view, double> load = {{"kg/m²", 1.0},
                                                          {"kg/m2", 1.0},
                                                          {"t/ha", 0.1},
                                                          {"lb/ft²", 0.45359237 / (kFoot * kFoot)},
                                                          {"lb/ft2", 0.45359237 / (kFoot * kFoot)},
                                                          {"t/ac", 907.18474 / 4046.8564224}};
  static const std::map<std::string_view, double> sav = {{"1/m", 1.0}, {"1/ft", 1.0 / kFoot}, {"1/cm", 100.0}};
  static const std::map<std::string_view, double> depth = {{"m", 1.0}, {"ft", kFoot}, {"cm", 0.01}};
  static const std::map<std::string_view, double> moisture = {{"%", 0.01}, {"fraction", 1.0}};
  static const std::map<std::string_view, double> heat = {{"kJ/kg", 1.0}, {"MJ/kg", 1000.0}, {"BTU/lb", 2.326}};
  if (quantity.starts_with("load_")) return load;
  if (quantity.starts_with("sav_")) return sav;
  if (quantity == "depth") return depth;
  if (quantity == "extinction_moisture") return moisture;
  return heat;
}

struct Column {
  std::size_t index = 0;
  double to_si = 1;
};

std::vector<std::string_view> quantities() {
  return {"load_1h", "load_10h", "load_100h", "load_live_herb", "load_live_woody", "sav_1h", "sav_10h", "sav_100h",
          "sav_live_herb", "sav_live_woody", "depth", "extinction_moisture", "heat_dead", "heat_live"};
}

FuelTable table_from(const Csv& csv, const std::string& source) {
  // The header: plain columns and quantities with their unit in brackets.
  std::map<std::string, Column> columns;
  for (std::size_t i = 0; i < csv.columns.size(); ++i) {
    const std::string& header = csv.columns[i];
    const std::size_t open = header.find('[');
    const std::string quantity = header.substr(0, open);
    const auto known = quantities();
    const bool is_quantity = std::find(known.begin(), known.end(), quantity) != known.end();
    if (!is_quantity) {
      if (quantity != "code" && quantity != "name" && quantity != "dynamic" && quantity != "description")
        throw file_error(csv.file, csv.header_line, fmt::format("unknown column '{}' (expected {})", header, kExpected));
      columns[quantity] = {i, 1};
      continue;
    }
    if (open == std::string::npos || header.back() != ']')
      throw file_error(csv.file, csv.header_line,
                       fmt::format("column '{}' has no unit: write it in brackets, e.g. {}[{}]", header, quantity,
                                   units_of(quantity).rbegin()->first));
    const std::string unit = header.substr(open + 1, header.size() - open - 2);
    const auto& units = units_of(quantity);
    const auto found = units.find(unit);
    if (found == units.end()) {
      std::string accepted;
      for (const auto& [name, factor] : units) accepted += (accepted.empty() ? "" : ", ") + std::string(name);
      throw file_error(csv.file, csv.header_line,
                       fmt::format("column '{}': unknown unit '{}' (accepted: {})", header, unit, accepted));
    }
    columns[quantity] = {i, found->second};
  }
  for (std::string_view required : {"code", "name", "dynamic", "load_1h", "load_10h", "load_100h", "load_live_herb",
                                    "load_live_woody", "sav_1h", "sav_live_herb", "sav_live_woody", "depth",
                                    "extinction_moisture", "heat_dead", "heat_live"})
    if (!columns.count(std::string(required)))
      throw file_error(csv.file, csv.header_line, fmt::format("no column '{}' (expected {})", required, kExpected));

  FuelTable table{.source = source, .models = {}};
  for (const CsvRow& row : csv.rows) {
    auto text = [&](std::string_view name) -> const std::string& { return row.fields[columns.at(std::string(name)).index]; };
    auto quantity = [&](std::string_view name) {
      const Column& c = columns.at(std::string(name));
      const double value = finite_number(csv, row, csv.columns[c.index]);
      if (value < 0) throw file_error(csv.file, row.line, fmt::format("{}: {} is negative", csv.columns[c.index], value));
      return value * c.to_si;
    };
    FuelModel m;
    const std::string& code = text("code");
    const auto [end, error] = std::from_chars(code.data(), code.data() + code.size(), m.code);
    if (error != std::errc() || end != code.data() + code.size() || m.code < 1)
      throw file_error(csv.file, row.line, fmt::format("code: '{}' is not a positive integer (the fuel raster's code)", code));
    m.name = text("name");
    if (m.name.empty()) throw file_error(csv.file, row.line, "name: empty");
    const std::string& dynamic = text("dynamic");
    if (dynamic != "yes" && dynamic != "no")
      throw file_error(csv.file, row.line, fmt::format("dynamic: '{}' (expected yes or no)", dynamic));
    m.dynamic = dynamic == "yes";
    if (columns.count("description")) m.description = text("description");
    const char* load_columns[] = {"load_1h", "load_10h", "load_100h", "load_live_herb", "load_live_woody"};
    const char* sav_columns[] = {"sav_1h", "sav_10h", "sav_100h", "sav_live_herb", "sav_live_woody"};
    for (int k = 0; k < kFuelClasses; ++k) {
      m.load[k] = quantity(load_columns[k]);
      if (columns.count(sav_columns[k])) m.sav[k] = quantity(sav_columns[k]);
      else m.sav[k] = (k == dead_10h ? kSav10hPerFoot : kSav100hPerFoot) / kFoot;
      if (m.load[k] > 0 && !(m.sav[k] > 0))
        throw file_error(csv.file, row.line,
                         fmt::format("{}: the class has a load but no surface-area-to-volume ratio ({} is 0)",
                                     load_columns[k], sav_columns[k]));
    }
    m.depth = quantity("depth");
    m.extinction_moisture = quantity("extinction_moisture");
    m.heat_dead = quantity("heat_dead");
    m.heat_live = quantity("heat_live");
    double total_load = 0;
    for (double w : m.load) total_load += w;
    if (total_load > 0 && !(m.depth > 0))
      throw file_error(csv.file, row.line, "depth: 0 for a model with fuel (expected the fuel bed's depth > 0)");
    if (m.dynamic && m.load[live_herb] == 0)
      throw file_error(csv.file, row.line, "dynamic: yes, but the model has no live herbaceous load to cure");
    if (m.burnable()) {
      if (!(m.extinction_moisture > 0))
        throw file_error(csv.file, row.line, "extinction_moisture: 0 for a model with fuel (expected > 0)");
      if (!(m.heat_dead > 0) || (m.load[live_herb] + m.load[live_woody] > 0 && !(m.heat_live > 0)))
        throw file_error(csv.file, row.line, "heat_dead, heat_live: 0 for a class with fuel (expected > 0)");
      if (m.extinction_moisture > 1.5)
        throw file_error(csv.file, row.line,
                         fmt::format("extinction_moisture: {} % is above 150 % (a fraction given as percent?)",
                                     100 * m.extinction_moisture));
    }
    for (const FuelModel& other : table.models) {
      if (other.code == m.code)
        throw file_error(csv.file, row.line, fmt::format("code {} is given twice (also for {})", m.code, other.name));
      if (other.name == m.name)
        throw file_error(csv.file, row.line, fmt::format("name {} is given twice (codes {} and {})", m.name, other.code, m.code));
    }
    table.models.push_back(std::move(m));
  }
  return table;
}

}  // namespace

std::string_view fuel_class_name(int fuel_class) {
  static constexpr std::string_view names[] = {"1h", "10h", "100h", "live_herb", "live_woody"};
  return names[fuel_class];
}

bool FuelModel::burnable() const {
  double total = 0;
  for (double w : load) total += w;
  return total > 0 && depth > 0;
}

const FuelModel* FuelTable::find(int code) const {
  for (const FuelModel& m : models)
    if (m.code == code) return &m;
  return nullptr;
}

const FuelModel* FuelTable::find(std::string_view code_or_name) const {
  for (const FuelModel& m : models)
    if (m.name == code_or_name || std::to_string(m.code) == code_or_name) return &m;
  return nullptr;
}

FuelTable read_fuel_table(const std::filesystem::path& file) {
  return table_from(read_csv(file, "the fuel table", kExpected), file.string());
}

FuelTable parse_fuel_table(std::string_view text, const std::string& source) {
  return table_from(parse_csv(text, source, kExpected), source);
}

std::vector<std::string> builtin_fuel_tables() { return {"anderson13", "scott_burgan40"}; }

std::string_view builtin_fuel_table_text(std::string_view name) {
  if (name == "anderson13") return detail::kAnderson13Csv;
  if (name == "scott_burgan40") return detail::kScottBurgan40Csv;
  return {};
}

FuelTable fuel_table(const std::string& name_or_file, const std::filesystem::path& file) {
  const std::string_view text = builtin_fuel_table_text(name_or_file);
  if (!text.empty()) return parse_fuel_table(text, name_or_file);
  return read_fuel_table(file.empty() ? std::filesystem::path(name_or_file) : file);
}

bool moisture_scenario(std::string_view name, FuelMoisture& moisture) {
  if (name.size() != 4 || name[0] != 'D' || name[2] != 'L' || name[1] < '1' || name[1] > '4' || name[3] < '1' ||
      name[3] > '4')
    return false;
  const int d = name[1] - '1', l = name[3] - '1';
  static constexpr double dead[4] = {0.03, 0.06, 0.09, 0.12};
  static constexpr double herb[4] = {0.30, 0.60, 0.90, 1.20};
  moisture.value = {dead[d], dead[d] + 0.01, dead[d] + 0.02, herb[l], herb[l] + 0.30};
  return true;
}

std::string moisture_percent_problem(double percent) {
  if (!std::isfinite(percent) || percent < 0) return fmt::format("{} is not a moisture (expected percent ≥ 0)", percent);
  if (percent > 0 && percent < 1)
    return fmt::format("{} looks like a fraction: moistures are in percent ({} for {} %)", percent, percent * 100,
                       percent * 100);
  if (percent > 500) return fmt::format("{} % is above any fuel's moisture (expected percent, up to 500)", percent);
  return {};
}

}  // namespace bodyfit::fire
