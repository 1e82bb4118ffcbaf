// Rothermel's surface fire spread model, the fuel tables and the fire ellipse: published values
// (BehavePlus's wind adjustment factors), the model's limits and invariants, unit conversions
// checked in both systems, and the errors of bad fuel tables and moistures.
#include "fuel.hpp"
#include "moisture.hpp"
#include "rothermel.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/parameters.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>
#include <fmt/format.h>
#include <toml++/toml.h>

#include <cmath>
#include <regex>
#include <sstream>
#include <string>

using namespace bodyfit;
using namespace bodyfit::fire;

namespace {

FuelMoisture percent(double d1, double d10, double d100, double herb, double woody) {
  return {{d1 / 100, d10 / 100, d100 / 100, herb / 100, woody / 100}};
}

// The Anderson 13 table rewritten in SI units, with factors written here from their definitions
// (1 short ton = 907.18474 kg, 1 acre = 4046.8564224 m², 1 ft = 0.3048 m, 1 BTU/lb = 2.326 kJ/kg).
std::string anderson13_in_si() {
  std::istringstream in{std::string(builtin_fuel_table_text("anderson13"))};
  std::ostringstream out;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      line = std::regex_replace(line, std::regex("\\[t/ac\\]"), "[kg/m²]");
      line = std::regex_replace(line, std::regex("\\[1/ft\\]"), "[1/m]");
      line = std::regex_replace(line, std::regex("\\[ft\\]"), "[m]");
      line = std::regex_replace(line, std::regex("\\[%\\]"), "[fraction]");
      line = std::regex_replace(line, std::regex("\\[BTU/lb\\]"), "[kJ/kg]");
      out << line << '\n';
      header = false;
      continue;
    }
    std::vector<std::string> f;
    std::stringstream fields(line);
    for (std::string s; std::getline(fields, s, ',');) f.push_back(s);
    auto scaled = [&](std::size_t i, double factor) { return fmt::format("{:.17g}", std::stod(f[i]) * factor); };
    const double ton_per_acre = 907.18474 / 4046.8564224;
    for (std::size_t i = 3; i <= 7; ++i) f[i] = scaled(i, ton_per_acre);
    for (std::size_t i = 8; i <= 10; ++i) f[i] = scaled(i, 1 / 0.3048);
    f[11] = scaled(11, 0.3048);
    f[12] = scaled(12, 0.01);
    f[13] = scaled(13, 2.326), f[14] = scaled(14, 2.326);
    for (std::size_t i = 0; i < f.size(); ++i) out << (i ? "," : "") << f[i];
    out << '\n';
  }
  return out.str();
}

std::string table_error(const std::string& csv) {
  try {
    parse_fuel_table(csv, "fuels.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST_CASE("wind adjustment factors: BehavePlus's unsheltered values for the 13 Anderson models") {
  // Andrews (2012), RMRS-GTR-266, the unsheltered wind adjustment factor of each of the 13 models
  // (two decimals, as published).
  const double published[13] = {0.36, 0.36, 0.44, 0.55, 0.42, 0.44, 0.44, 0.28, 0.28, 0.36, 0.36, 0.43, 0.46};
  const FuelTable table = fuel_table("anderson13");
  REQUIRE(table.models.size() == 13);
  for (int k = 0; k < 13; ++k) {
    CAPTURE(k + 1);
    CHECK(std::round(100 * wind_adjustment_factor(table.models[std::size_t(k)].depth)) / 100 == published[k]);
  }
  // 10 m is 1.15 × 20 ft.
  CHECK(midflame_factor(WindHeight::ten_metres, 0.3048) ==
        doctest::Approx(midflame_factor(WindHeight::twenty_feet, 0.3048) / 1.15));
  CHECK(midflame_factor(WindHeight::midflame, 0.3048) == 1);
}

TEST_CASE("fuel tables: the shipped ones, and a table in SI units gives the same fires as in US units") {
  const FuelTable sb = fuel_table("scott_burgan40");
  int burnable = 0;
  for (const auto& m : sb.models) burnable += m.burnable();
  CHECK(burnable == 40);
  CHECK(sb.models.size() == 45);  // and NB1, NB2, NB3, NB8, NB9
  CHECK(sb.find("GR2") == sb.find("102"));
  CHECK(sb.find(102)->load[live_herb] == doctest::Approx(1.0 * 907.18474 / 4046.8564224));
  CHECK(sb.find(102)->dynamic);
  CHECK(sb.find("SH2")->dynamic == false);

  const FuelTable us = fuel_table("anderson13");
  const FuelTable si = parse_fuel_table(anderson13_in_si(), "anderson13_si.csv");
  REQUIRE(si.models.size() == us.models.size());
  const FuelMoisture m = percent(6, 7, 8, 60, 90);
  for (std::size_t k = 0; k < us.models.size(); ++k) {
    CAPTURE(us.models[k].name);
    const SurfaceFire a = surface_fire(us.models[k], m), b = surface_fire(si.models[k], m);
    CHECK(a.rate0 == doctest::Approx(b.rate0).epsilon(1e-12));
    CHECK(a.reaction_intensity == doctest::Approx(b.reaction_intensity).epsilon(1e-12));
    CHECK(a.heat_per_unit_area == doctest::Approx(b.heat_per_unit_area).epsilon(1e-12));
  }
}

TEST_CASE("Rothermel: calm flat ground spreads as a circle at R0, moisture of extinction stops it") {
  const FuelTable table = fuel_table("anderson13");
  const SurfaceFire fm1 = surface_fire(*table.find("FM1"), percent(6, 7, 8, 60, 90));
  REQUIRE(fm1.extinct.empty());
  const HeadSpread calm = head_spread(fm1, Vec3(0, 0, 0), Vec3(1, 0, 0), 0);
  CHECK(calm.head == fm1.rate0);
  CHECK(calm.back == doctest::Approx(fm1.rate0));
  CHECK(calm.flank == doctest::Approx(fm1.rate0));
  CHECK(calm.length_to_width == doctest::Approx(1.0).epsilon(1e-12));  // Anderson's fit is 1 at U = 0
  for (double angle : {0.0, 1.0, 2.5})
    CHECK(ellipse_normal_rate(calm, Vec3(std::cos(angle), std::sin(angle), 0)) == doctest::Approx(fm1.rate0));

  // FM1's moisture of extinction is 12 %: at 12 % and above nothing burns, and it says why.
  const SurfaceFire wet = surface_fire(*table.find("FM1"), percent(12, 13, 14, 60, 90));
  CHECK(wet.rate0 == 0);
  CHECK(wet.extinct.find("12 %") != std::string::npos);
  CHECK(head_spread(wet, Vec3(5, 0, 0), Vec3(1, 0, 0), 0.5).head == 0);
  // Drier burns faster, just below extinction slower still than at 6 %.
  CHECK(surface_fire(*table.find("FM1"), percent(11, 12, 13, 60, 90)).rate0 < fm1.rate0);
  CHECK(surface_fire(*table.find("FM1"), percent(3, 4, 5, 60, 90)).rate0 > fm1.rate0);
  // A non-burnable model carries no fire.
  CHECK_FALSE(surface_fire(*fuel_table("scott_burgan40").find("NB8"), percent(6, 7, 8, 60, 90))
                  .extinct.empty());
}

TEST_CASE("Rothermel: wind and slope factors, their vector sum and the effective wind limit") {
  const FuelTable table = fuel_table("anderson13");
  const SurfaceFire fire = surface_fire(*table.find("FM2"), percent(6, 7, 8, 60, 90));
  // The wind factor as Rothermel (1972) writes it, U in ft/min.
  const double u = 2.0;  // m/s midflame
  const double phi_w = fire.wind_c * std::pow(u / 0.00508, fire.wind_b) * std::pow(fire.packing_ratio_ratio, -fire.wind_e);
  const HeadSpread wind = head_spread(fire, Vec3(0, u, 0), Vec3(1, 0, 0), 0);
  CHECK(wind.head == doctest::Approx(fire.rate0 * (1 + phi_w)).epsilon(1e-12));
  CHECK(wind.direction[1] == doctest::Approx(1));
  CHECK(wind.effective_wind == doctest::Approx(u).epsilon(1e-9));  // wind alone: the effective wind is the wind
  // Slope alone: φ_s = 5.275 β^−0.3 tan²θ, upslope.
  const double tan_slope = std::tan(20 * M_PI / 180);
  const HeadSpread slope = head_spread(fire, Vec3(0, 0, 0), Vec3(1, 0, 0), tan_slope);
  const double phi_s = fire.slope_factor * tan_slope * tan_slope;
  CHECK(slope.head == doctest::Approx(fire.rate0 * (1 + phi_s)).epsilon(1e-12));
  CHECK(slope.direction[0] == doctest::Approx(1));
  // Across each other: the factors add as vectors.
  const HeadSpread both = head_spread(fire, Vec3(0, u, 0), Vec3(1, 0, 0), tan_slope);
  CHECK(both.head == doctest::Approx(fire.rate0 * (1 + std::hypot(phi_w, phi_s))).epsilon(1e-12));
  CHECK(std::atan2(both.direction[1], both.direction[0]) == doctest::Approx(std::atan2(phi_w, phi_s)));
  // A gale: capped at 0.9 × the reaction intensity (in ft/min per BTU/ft²/min), unless asked not to.
  const HeadSpread gale = head_spread(fire, Vec3(60, 0, 0), Vec3(1, 0, 0), 0);
  CHECK(gale.wind_limited);
  CHECK(gale.effective_wind == doctest::Approx(fire.max_effective_wind));
  const HeadSpread free = head_spread(fire, Vec3(60, 0, 0), Vec3(1, 0, 0), 0, {.limit_effective_wind = false});
  CHECK_FALSE(free.wind_limited);
  CHECK(free.head > gale.head);
  CHECK(free.length_to_width == 8);  // the cap of the ellipse's elongation
}

TEST_CASE("the fire ellipse: head, back and flank rates, Anderson's length-to-width and Byram's flame") {
  const SurfaceFire fire = surface_fire(*fuel_table("scott_burgan40").find("GR2"), percent(6, 7, 8, 60, 90));
  const HeadSpread s = head_spread(fire, Vec3(2.2352, 0, 0), Vec3(0, 1, 0), 0);  // 5 mi/h midflame
  // Anderson (1983) at 5 mi/h: 0.936 e^1.283 + 0.461 e^−0.774 − 0.397.
  CHECK(s.length_to_width == doctest::Approx(0.936 * std::exp(1.283) + 0.461 * std::exp(-0.774) - 0.397));
  const double e = std::sqrt(s.length_to_width * s.length_to_width - 1) / s.length_to_width;
  CHECK(s.back == doctest::Approx(s.head * (1 - e) / (1 + e)));
  CHECK(s.flank == doctest::Approx((s.head + s.back) / (2 * s.length_to_width)));
  CHECK(ellipse_normal_rate(s, Vec3(1, 0, 0)) == doctest::Approx(s.head));
  CHECK(ellipse_normal_rate(s, Vec3(-1, 0, 0)) == doctest::Approx(s.back));
  CHECK(ellipse_normal_rate(s, Vec3(0, 1, 0)) == doctest::Approx(s.flank));
  // The normal rate is the support function of the ellipse centred (head − back)/2 ahead: the
  // largest n·p over the ellipse's points p, found here by sampling them.
  const double a = 0.5 * (s.head + s.back), c = 0.5 * (s.head - s.back);
  for (double angle = 0.1; angle < 6.2; angle += 0.7) {
    const Vec3 n(std::cos(angle), std::sin(angle), 0);
    double support = -1e300;
    for (int i = 0; i < 200000; ++i) {
      const double t = 2 * M_PI * i / 200000;
      support = std::max(support, n[0] * (c + a * std::cos(t)) + n[1] * s.flank * std::sin(t));
    }
    CHECK(ellipse_normal_rate(s, n) == doctest::Approx(support).epsilon(1e-6));
  }
  // Byram: 0.45 I^0.46 ft with I in BTU/ft/s is 0.0775 I^0.46 m with I in kW/m.
  const double intensity = fireline_intensity(fire.heat_per_unit_area, s.head);
  const double btu_per_ft_s = intensity / (1.05505585262 / 0.3048);
  CHECK(flame_length(intensity) == doctest::Approx(0.45 * std::pow(btu_per_ft_s, 0.46) * 0.3048).epsilon(2e-3));
}

TEST_CASE("dynamic fuel models: cured herbaceous load burns as dead fuel") {
  const FuelTable table = fuel_table("scott_burgan40");
  FuelModel gr2 = *table.find("GR2");
  FuelModel fixed = gr2;
  fixed.dynamic = false;
  // Fully green (≥ 120 %): nothing is transferred, the dynamic model is the static one.
  CHECK(surface_fire(gr2, percent(6, 7, 8, 120, 150)).rate0 == surface_fire(fixed, percent(6, 7, 8, 120, 150)).rate0);
  // Cured (30 %): the herbaceous load is dead, dry fuel: faster than the same load kept live.
  CHECK(surface_fire(gr2, percent(6, 7, 8, 30, 60)).rate0 > 2 * surface_fire(fixed, percent(6, 7, 8, 30, 60)).rate0);
}

TEST_CASE("fuel tables and moistures: bad input is an error naming the file, line and column") {
  const std::string header =
      "code,name,dynamic,load_1h[t/ac],load_10h[t/ac],load_100h[t/ac],load_live_herb[t/ac],load_live_woody[t/ac],"
      "sav_1h[1/ft],sav_live_herb[1/ft],sav_live_woody[1/ft],depth[ft],extinction_moisture[%],heat_dead[BTU/lb],"
      "heat_live[BTU/lb]\n";
  const std::string good = "1,A,no,1,0,0,0,0,2000,0,0,1,20,8000,8000\n";
  CHECK(table_error(header + good) == "no error");
  CHECK(table_error(header + "1,A,no,-1,0,0,0,0,2000,0,0,1,20,8000,8000\n") == "fuels.csv:2: load_1h[t/ac]: -1 is negative");
  CHECK(table_error(header + "1,A,no,1,0,0,0,0,-2000,0,0,1,20,8000,8000\n") == "fuels.csv:2: sav_1h[1/ft]: -2000 is negative");
  CHECK(table_error(header + "1,A,no,1,0,0,0,1,2000,0,0,1,20,8000,8000\n").find("no surface-area-to-volume") != std::string::npos);
  CHECK(table_error(header + good + "1,B,no,1,0,0,0,0,2000,0,0,1,20,8000,8000\n") == "fuels.csv:3: code 1 is given twice (also for A)");
  CHECK(table_error(header + "1,A,maybe,1,0,0,0,0,2000,0,0,1,20,8000,8000\n") == "fuels.csv:2: dynamic: 'maybe' (expected yes or no)");
  CHECK(table_error(header + "1,A,no,1,0,0,0,0,2000,0,0,1,20\n").starts_with("fuels.csv:2: 13 field(s), the header has 15"));
  std::string bad_unit = header;
  bad_unit.replace(bad_unit.find("depth[ft]"), 9, "depth[yd]");
  CHECK(table_error(bad_unit + good).starts_with("fuels.csv:1: column 'depth[yd]': unknown unit 'yd'"));
  std::string no_unit = header;
  no_unit.replace(no_unit.find("depth[ft]"), 9, "depth");
  CHECK(table_error(no_unit + good).starts_with("fuels.csv:1: column 'depth' has no unit"));
  CHECK(table_error(header + "1,A,no,1,0,0,0,0,2000,0,0,1,0.2,8000,8000\n") == "no error");  // 0.2 % is odd, not wrong
  CHECK(table_error(header + "1,A,no,1,0,0,0,0,2000,0,0,0,20,8000,8000\n") ==
        "fuels.csv:2: depth: 0 for a model with fuel (expected the fuel bed's depth > 0)");
  CHECK(table_error(header + "x,A,no,1,0,0,0,0,2000,0,0,1,20,8000,8000\n").starts_with("fuels.csv:2: code: 'x' is not"));

  auto moisture_error = [](const std::string& text) -> std::string {
    const toml::table t = toml::parse(text);
    Parameters p(t, moisture_parameters(), "model");
    try {
      read_moisture(p.section("moisture"));  // constant classes or a scenario here
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  CHECK(moisture_error("[moisture]\nscenario = 'D2L3'\n") == "no error");
  CHECK(moisture_error("[moisture]\nscenario = 'D5L1'\n").find("is not a moisture scenario") != std::string::npos);
  CHECK(moisture_error("[moisture]\ndead_1h = 0.06\ndead_10h = 7\ndead_100h = 8\nlive_herb = 60\nlive_woody = 90\n")
            .find("0.06 looks like a fraction: moistures are in percent (6 for 6 %)") != std::string::npos);
  CHECK(moisture_error("[moisture]\ndead_1h = 6\n").find("live") == std::string::npos);  // names the missing dead_10h first
  CHECK(moisture_error("[moisture]\ndead_1h = 6\n").find("dead_10h") != std::string::npos);
  CHECK(moisture_error("[moisture]\nscenario = 'D1L1'\ndead_1h = 6\n").find("not several") != std::string::npos);
}

TEST_CASE("bodyfit ros: the calculator's units, JSON, Balbi's presets and its errors") {
  auto json_number = [](const std::string& json, const std::string& key) {
    const std::size_t at = json.find("\"" + key + "\": ");
    REQUIRE_MESSAGE(at != std::string::npos, key);
    return std::stod(json.substr(at + key.size() + 4));
  };
  // 10 mi/h at 20 ft over GR2 (1 ft bed): the library's head spread at 4.4704 m/s × the bed's factor.
  const auto gr2 = test::run_bodyfit("ros --fuel GR2 --scenario D1L1 --wind 10 --wind-unit mph --wind-height 20ft --json");
  REQUIRE_MESSAGE(gr2.exit_code == 0, gr2.output);
  FuelMoisture d1l1;
  REQUIRE(moisture_scenario("D1L1", d1l1));
  const FuelModel model = *fuel_table("scott_burgan40").find("GR2");  // a copy: the table is a temporary
  const SurfaceFire fire = surface_fire(model, d1l1);
  const double midflame = 4.4704 * wind_adjustment_factor(model.depth);
  const HeadSpread s = head_spread(fire, Vec3(midflame, 0, 0), Vec3(1, 0, 0), 0);
  CHECK(json_number(gr2.output, "midflame_wind_mps") == doctest::Approx(midflame).epsilon(1e-8));
  CHECK(json_number(gr2.output, "ros_head_mps") == doctest::Approx(s.head).epsilon(1e-8));
  CHECK(json_number(gr2.output, "ros_back_mps") == doctest::Approx(s.back).epsilon(1e-8));
  CHECK(json_number(gr2.output, "ros_flank_mps") == doctest::Approx(s.flank).epsilon(1e-8));
  CHECK(json_number(gr2.output, "length_to_width") == doctest::Approx(s.length_to_width).epsilon(1e-8));
  CHECK(json_number(gr2.output, "fireline_intensity_kw_per_m") ==
        doctest::Approx(fire.heat_per_unit_area * s.head).epsilon(1e-8));
  CHECK(json_number(gr2.output, "flame_length_m") > 0);
  // km/h and m/s give the same midflame wind for the same speed.
  const auto kmh = test::run_bodyfit("ros --fuel GR2 --scenario D1L1 --wind 16.09344 --wind-unit km/h --wind-height 20ft --json");
  CHECK(json_number(kmh.output, "ros_head_mps") == doctest::Approx(s.head).epsilon(1e-8));
  // Balbi's preset on a 30° slope: R(30°) = 2.360116 m/s by hand (docs/reference/fire_model.md).
  const auto balbi = test::run_bodyfit("ros --model balbi --slope 30 --json");
  REQUIRE_MESSAGE(balbi.exit_code == 0, balbi.output);
  CHECK(json_number(balbi.output, "ros_head_mps") == doctest::Approx(2.360116).epsilon(1e-6));
  CHECK(json_number(balbi.output, "ros_back_mps") == doctest::Approx(0.39801));
  // Above extinction: 0, and why.
  const auto wet = test::run_bodyfit("ros --fuel FM1 --m1h 12 --m10h 13 --m100h 14 --mlh 60 --mlw 90 --json");
  CHECK(json_number(wet.output, "ros_head_mps") == 0);
  CHECK(wet.output.find("at or above its moisture of extinction") != std::string::npos);
  // Errors: exit 1 with the reason.
  const auto fraction = test::run_bodyfit("ros --fuel FM1 --m1h 0.06 --m10h 7 --m100h 8 --mlh 60 --mlw 90");
  CHECK(fraction.exit_code == 1);
  CHECK(fraction.output.find("--m1h: 0.06 looks like a fraction") != std::string::npos);
  const auto unknown = test::run_bodyfit("ros --fuel XX9 --scenario D1L1");
  CHECK(unknown.exit_code == 1);
  CHECK(unknown.output.find("--fuel XX9: not a model of the fuel table anderson13, scott_burgan40") != std::string::npos);
  CHECK(test::run_bodyfit("ros --fuel GR2 --scenario D1L1 --wind-height 3m").exit_code != 0);
  CHECK(test::run_bodyfit("ros --model balbi --fuel GR2").exit_code == 1);
}
