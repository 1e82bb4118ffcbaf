// bodyfit ros --fuel GR2 --wind 10 --wind-unit mph --wind-height 20ft --slope 20: a fire behaviour
// calculator as BehavePlus users know it (Rothermel 1972 with Albini 1976, Anderson's 1983
// ellipse, Byram's intensity and flame length): the fire model's own physics, one point at a time.
#include "commands.hpp"

#include "balbi.hpp"
#include "crown.hpp"
#include "fuel.hpp"
#include "rothermel.hpp"

#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <vector>

namespace {

using namespace bodyfit;
using namespace bodyfit::fire;

struct RosArguments {
  std::string model = "rothermel", fuel, table, table_file, scenario, preset;
  std::optional<double> moisture[kFuelClasses];
  double wind = 0, slope = 0, wind_direction = 0;
  std::optional<double> canopy_base_height, canopy_bulk_density;
  double foliar_moisture = 100;
  std::string wind_unit = "m/s", wind_height = "midflame";
  bool json = false, no_wind_limit = false;
};

const std::map<std::string, double>& wind_units() {
  static const std::map<std::string, double> units = {{"m/s", 1.0}, {"mph", 0.44704}, {"km/h", 1 / 3.6}};
  return units;
}

FuelMoisture moisture_of(const RosArguments& args) {
  FuelMoisture moisture;
  const char* options[kFuelClasses] = {"--m1h", "--m10h", "--m100h", "--mlh", "--mlw"};
  bool any = false;
  for (const auto& m : args.moisture) any = any || m.has_value();
  if (!args.scenario.empty()) {
    if (any) throw InputError("--scenario: give either a moisture scenario or --m1h … --mlw, not both");
    if (!moisture_scenario(args.scenario, moisture))
      throw InputError(fmt::format("--scenario '{}': expected D1L1 … D4L4 (Scott & Burgan 2005)", args.scenario));
    return moisture;
  }
  for (int k = 0; k < kFuelClasses; ++k) {
    if (!args.moisture[k])
      throw InputError(fmt::format("{}: the {} fuel moisture is needed (percent), or a --scenario such as D2L2",
                                   options[k], fuel_class_name(k)));
    const std::string problem = moisture_percent_problem(*args.moisture[k]);
    if (!problem.empty()) throw InputError(fmt::format("{}: {}", options[k], problem));
    moisture.value[k] = *args.moisture[k] / 100;
  }
  return moisture;
}

// Balbi's rate of spread with one of the paper's parameter sets: tan γ = n·(tan α ŝ + (U/u0) ŵ), so
// the head runs along that vector at R(atan |v|), the back and the flanks at R0 (γ ≤ 0).
int balbi_command(const RosArguments& args) {
  for (const auto& m : args.moisture)
    if (m) throw InputError("--m1h … --mlw: Balbi's parameter sets take no fuel moistures (give --model rothermel)");
  if (!args.fuel.empty() || !args.scenario.empty() || args.canopy_base_height || args.canopy_bulk_density)
    throw InputError("--fuel, --scenario, --cbh, --cbd: Balbi's rate of spread takes a --preset (the paper's "
                     "constants), not a fuel model");
  if (args.wind_height != "midflame")
    throw InputError("--wind-height: Balbi's rate of spread takes the wind at the flame (midflame)");
  BalbiParameters p;
  try {
    p = preset(args.preset.empty() ? "balbi2009" : args.preset);
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("--preset: {}", e.what()));
  }
  if (!(args.slope >= 0 && args.slope < 90)) throw InputError(fmt::format("--slope {}: expected degrees in [0, 90)", args.slope));
  const double speed = args.wind * wind_units().at(args.wind_unit);
  const double angle = args.wind_direction * M_PI / 180;
  const double tan_slope = std::tan(args.slope * M_PI / 180);
  const double vx = tan_slope + speed / p.u0 * std::cos(angle), vy = speed / p.u0 * std::sin(angle);
  const double head = rate_of_spread(std::atan(std::hypot(vx, vy)), p);
  const double direction = std::hypot(vx, vy) > 0 ? std::atan2(vy, vx) * 180 / M_PI : 0;
  if (args.json) {
    fmt::print("{{\"preset\": \"{}\", \"ros_head_mps\": {:.9g}, \"ros_flank_mps\": {:.9g}, \"ros_back_mps\": {:.9g}, "
               "\"midflame_wind_mps\": {:.9g}, \"length_to_width\": null, \"direction_of_max_spread_deg\": {:.9g}, "
               "\"fireline_intensity_kw_per_m\": null, \"flame_length_m\": null}}\n",
               args.preset.empty() ? "balbi2009" : args.preset, head, p.R0, p.R0, speed, direction);
    return 0;
  }
  const double ft_min = 60 / 0.3048;
  fmt::print("Balbi et al. (2009), preset {} (R0 {:.4f} m/s, A {:.4f}, u0 {:.1f} m/s, v0 {:.4f} m/s)\n",
             args.preset.empty() ? "balbi2009" : args.preset, p.R0, p.A, p.u0, p.v0);
  fmt::print("rate of spread  head  {:9.4f} m/s  {:9.2f} ft/min\n", head, head * ft_min);
  fmt::print("                flank {:9.4f} m/s  {:9.2f} ft/min\n", p.R0, p.R0 * ft_min);
  fmt::print("                back  {:9.4f} m/s  {:9.2f} ft/min\n", p.R0, p.R0 * ft_min);
  fmt::print("direction of spread   {:9.1f}° from upslope\n", direction);
  fmt::print("(no fuel load: no intensity or flame length; the front is the Wulff shape of R(n), not an ellipse)\n");
  return 0;
}

int ros_command(const RosArguments& args) {
  if (args.model == "balbi") return balbi_command(args);
  if (!args.preset.empty()) throw InputError("--preset: Balbi's parameter sets (give --model balbi)");
  if (args.fuel.empty()) throw InputError("--fuel: required by --model rothermel (a code or name: GR2, 102, FM1)");
  // Without a table, the shipped ones (their codes and names do not overlap: FM1 is 1, GR1 is 101).
  std::vector<FuelTable> tables;
  if (!args.table_file.empty()) tables.push_back(read_fuel_table(args.table_file));
  else if (!args.table.empty()) tables.push_back(fuel_table(args.table));
  else
    for (const std::string& name : builtin_fuel_tables()) tables.push_back(fuel_table(name));
  const FuelModel* fuel = nullptr;
  const FuelTable* table = nullptr;
  for (const FuelTable& t : tables)
    if (!fuel && (fuel = t.find(args.fuel))) table = &t;
  if (!fuel) {
    std::string names;
    for (const FuelTable& t : tables) names += (names.empty() ? "" : ", ") + t.source;
    throw InputError(fmt::format("--fuel {}: not a model of the fuel table {}", args.fuel, names));
  }
  const FuelMoisture moisture = moisture_of(args);
  if (!(args.slope >= 0 && args.slope < 90)) throw InputError(fmt::format("--slope {}: expected degrees in [0, 90)", args.slope));
  if (!(args.wind >= 0) || !std::isfinite(args.wind)) throw InputError(fmt::format("--wind {}: expected a speed ≥ 0", args.wind));
  WindHeight height;
  parse_wind_height(args.wind_height, height);

  const SurfaceFire fire = surface_fire(*fuel, moisture);
  const double midflame = args.wind * wind_units().at(args.wind_unit) * midflame_factor(height, fuel->depth);
  // The wind blows at wind_direction degrees from upslope (BehavePlus's "wind direction relative to upslope").
  const double angle = args.wind_direction * M_PI / 180;
  const HeadSpread s = head_spread(fire, Vec3(midflame * std::cos(angle), midflame * std::sin(angle), 0),
                                   Vec3(1, 0, 0), std::tan(args.slope * M_PI / 180),
                                   {.limit_effective_wind = !args.no_wind_limit});
  // A canopy: the crown fire over the surface fire (the 20-ft wind: a midflame one goes back up).
  const bool canopy_given = args.canopy_base_height || args.canopy_bulk_density;
  if (canopy_given && !(args.canopy_base_height && args.canopy_bulk_density))
    throw InputError("--cbh and --cbd: a canopy needs both its base height and its bulk density");
  CrownFire crown;
  crown.spread = s;
  if (canopy_given) {
    const double wind_20ft = args.wind * wind_units().at(args.wind_unit) * twenty_foot_factor(height, fuel->depth);
    const SurfaceFire fm10 = surface_fire(*fuel_table("anderson13").find("FM10"), moisture);
    const std::string problem = moisture_percent_problem(args.foliar_moisture);
    if (!problem.empty()) throw InputError("--fmc: " + problem);
    crown = crown_fire(s, fire.heat_per_unit_area,
                       {.base_height = *args.canopy_base_height, .bulk_density = *args.canopy_bulk_density,
                        .foliar_moisture = args.foliar_moisture / 100},
                       fm10, Vec3(wind_20ft * std::cos(angle), wind_20ft * std::sin(angle), 0), Vec3(1, 0, 0),
                       std::tan(args.slope * M_PI / 180), {.limit_effective_wind = !args.no_wind_limit});
  }
  const double intensity = fireline_intensity(fire.heat_per_unit_area, s.head);
  const double flame = flame_length(intensity);
  const double direction = s.head > 0 && s.direction.norm() > 0 ? std::atan2(s.direction[1], s.direction[0]) * 180 / M_PI : 0;
  if (args.json) {
    fmt::print("{{\"fuel\": \"{}\", \"ros_head_mps\": {:.9g}, \"ros_flank_mps\": {:.9g}, \"ros_back_mps\": {:.9g}, "
               "\"midflame_wind_mps\": {:.9g}, \"effective_wind_mps\": {:.9g}, \"wind_limited\": {}, "
               "\"length_to_width\": {:.9g}, \"direction_of_max_spread_deg\": {:.9g}, "
               "\"reaction_intensity_kw_per_m2\": {:.9g}, \"heat_per_unit_area_kj_per_m2\": {:.9g}, "
               "\"fireline_intensity_kw_per_m\": {:.9g}, \"flame_length_m\": {:.9g}, \"extinct\": \"{}\"{}}}\n",
               fuel->name, s.head, s.flank, s.back, midflame, s.effective_wind, s.wind_limited ? "true" : "false",
               s.length_to_width, direction, fire.reaction_intensity, fire.heat_per_unit_area, intensity, flame,
               fire.extinct,
               canopy_given ? fmt::format(", \"fire_type\": \"{}\", \"crown_initiation_intensity_kw_per_m\": {:.9g}, "
                                          "\"crown_active_ros_mps\": {:.9g}, \"crown_critical_ros_mps\": {:.9g}, "
                                          "\"final_ros_head_mps\": {:.9g}",
                                          fire_type_name(crown.type), crown.initiation_intensity, crown.active_rate,
                                          crown.critical_active_rate, crown.spread.head)
                            : std::string());
    return 0;
  }
  const double ft_min = 60 / 0.3048;
  fmt::print("{} ({}), {}\n", fuel->name, fuel->description, table->source);
  if (!fire.extinct.empty()) fmt::print("no spread: {}\n", fire.extinct);
  fmt::print("rate of spread  head  {:9.4f} m/s  {:9.2f} ft/min\n", s.head, s.head * ft_min);
  fmt::print("                flank {:9.4f} m/s  {:9.2f} ft/min\n", s.flank, s.flank * ft_min);
  fmt::print("                back  {:9.4f} m/s  {:9.2f} ft/min\n", s.back, s.back * ft_min);
  fmt::print("midflame wind         {:9.3f} m/s  (× {:.3f} from {})\n", midflame, midflame_factor(height, fuel->depth),
             args.wind_height);
  fmt::print("effective wind        {:9.3f} m/s{}\n", s.effective_wind, s.wind_limited ? "  (capped: 0.9 × reaction intensity)" : "");
  fmt::print("length-to-width       {:9.3f}\n", s.length_to_width);
  fmt::print("direction of spread   {:9.1f}° from upslope\n", direction);
  fmt::print("reaction intensity    {:9.1f} kW/m²\n", fire.reaction_intensity);
  fmt::print("heat per unit area    {:9.0f} kJ/m²\n", fire.heat_per_unit_area);
  fmt::print("fireline intensity    {:9.1f} kW/m\n", intensity);
  fmt::print("flame length          {:9.2f} m\n", flame);
  if (canopy_given) {
    fmt::print("fire type             {}\n", fire_type_name(crown.type));
    fmt::print("crown initiation      {:9.1f} kW/m (surface head intensity {:.1f})\n", crown.initiation_intensity, intensity);
    fmt::print("crown rate, active    {:9.4f} m/s (critical {:.4f} m/s)\n", crown.active_rate, crown.critical_active_rate);
    fmt::print("final head rate       {:9.4f} m/s  {:9.2f} ft/min\n", crown.spread.head, crown.spread.head * ft_min);
  }
  return 0;
}

bodyfit::cli::Command setup_ros(CLI::App& app) {
  auto* cmd = app.add_subcommand("ros", "fire behaviour at one point: rate of spread (head, flank, back), ellipse, "
                                        "fireline intensity and flame length of a fuel model (Rothermel)");
  auto args = std::make_shared<RosArguments>();
  cmd->add_option("--model", args->model, "rate-of-spread model")->check(CLI::IsMember({"rothermel", "balbi"}))->capture_default_str();
  cmd->add_option("--fuel", args->fuel, "rothermel: fuel model, code or name (GR2, 102, FM1)");
  cmd->add_option("--preset", args->preset, "balbi: the paper's parameter set (balbi2009, paper_table1)");
  cmd->add_option("--fuel-table", args->table_file, "a fuel table of your own (CSV with units in the header)");
  cmd->add_option("--table", args->table, "a shipped fuel table (default: the one that has --fuel)")
      ->check(CLI::IsMember(builtin_fuel_tables()));
  cmd->add_option("--scenario", args->scenario, "Scott & Burgan moisture scenario, D1L1 … D4L4");
  const char* names[kFuelClasses] = {"--m1h", "--m10h", "--m100h", "--mlh", "--mlw"};
  const char* what[kFuelClasses] = {"1-h dead", "10-h dead", "100-h dead", "live herbaceous", "live woody"};
  for (int k = 0; k < kFuelClasses; ++k)
    cmd->add_option_function<double>(names[k], [args, k](double v) { args->moisture[k] = v; },
                                     fmt::format("{} fuel moisture, percent", what[k]));
  cmd->add_option("--wind", args->wind, "wind speed")->capture_default_str();
  cmd->add_option("--wind-unit", args->wind_unit, "unit of --wind")->check(CLI::IsMember(wind_units()))->capture_default_str();
  cmd->add_option("--wind-height", args->wind_height, "height the wind is given at")
      ->check(CLI::IsMember({"midflame", "20ft", "10m"}))
      ->capture_default_str();
  cmd->add_option("--wind-direction", args->wind_direction, "direction the wind blows to, degrees from upslope")
      ->capture_default_str();
  cmd->add_option("--slope", args->slope, "slope, degrees")->capture_default_str();
  cmd->add_option_function<double>("--cbh", [args](double v) { args->canopy_base_height = v; },
                                   "canopy base height, m (with --cbd: crown fire)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option_function<double>("--cbd", [args](double v) { args->canopy_bulk_density = v; },
                                   "canopy bulk density, kg/m³")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--fmc", args->foliar_moisture, "foliar moisture content, percent")->capture_default_str();
  cmd->add_flag("--no-wind-limit", args->no_wind_limit, "do not cap the effective wind (Rothermel's limit)");
  cmd->add_flag("--json", args->json, "one JSON object instead of the table");
  return {cmd, [args]() { return ros_command(*args); }};
}

BODYFIT_COMMAND(88, setup_ros);

}  // namespace
