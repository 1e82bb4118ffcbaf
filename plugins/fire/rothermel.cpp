#include "rothermel.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace bodyfit::fire {
namespace {

// US customary units, in which Rothermel's equations and coefficients are published.
constexpr double kFoot = 0.3048;                               // m
constexpr double kPoundPerSquareFoot = 0.45359237 / (kFoot * kFoot);  // kg/m²
constexpr double kBtuPerPound = 2.326;                         // kJ/kg
constexpr double kBtuPerSquareFoot = 1.05505585262 / (kFoot * kFoot);  // kJ/m²
constexpr double kFootPerMinute = kFoot / 60;                  // m/s
constexpr double kMilePerHour = 0.44704;                       // m/s

constexpr double kParticleDensity = 32;   // lb/ft³
constexpr double kTotalMineral = 0.0555;  // S_T
constexpr double kEffectiveMineral = 0.010;  // S_e

struct Particle {
  double load = 0;      // lb/ft²
  double sav = 0;       // 1/ft
  double moisture = 0;  // fraction
  double heat = 0;      // BTU/lb
};

// Albini's (1976) size classes, which weight the net loads of particles of similar size together.
int size_class(double sav) {
  if (sav >= 1200) return 0;
  if (sav >= 192) return 1;
  if (sav >= 96) return 2;
  if (sav >= 48) return 3;
  if (sav >= 16) return 4;
  return 5;
}

// One category (dead or live) weighted by surface area (Rothermel 1972, eqs. 53–60).
struct Category {
  double area = 0;       // Σ σ w / ρ_p
  double sav = 0;        // σ_i
  double moisture = 0;   // M_f,i
  double heat = 0;       // h_i
  double net_load = 0;   // w_n,i with Albini's size-class weights
  double heat_sink = 0;  // Σ f_ij exp(−138/σ_ij)(250 + 1116 M_ij)
};

Category weigh(const std::vector<Particle>& particles) {
  Category c;
  for (const Particle& p : particles)
    if (p.load > 0) c.area += p.sav * p.load / kParticleDensity;
  if (!(c.area > 0)) return c;
  double class_weight[6] = {};
  for (const Particle& p : particles) {
    if (!(p.load > 0)) continue;
    const double f = p.sav * p.load / kParticleDensity / c.area;
    c.sav += f * p.sav;
    c.moisture += f * p.moisture;
    c.heat += f * p.heat;
    c.heat_sink += f * std::exp(-138 / p.sav) * (250 + 1116 * p.moisture);
    class_weight[size_class(p.sav)] += f;
  }
  for (const Particle& p : particles)
    if (p.load > 0) c.net_load += class_weight[size_class(p.sav)] * p.load * (1 - kTotalMineral);
  return c;
}

double moisture_damping(double moisture, double extinction) {
  if (!(extinction > 0)) return 0;
  const double r = moisture / extinction;
  if (r >= 1) return 0;  // the polynomial is 0 at 1 only up to rounding
  return 1 - 2.59 * r + 5.11 * r * r - 3.52 * r * r * r;
}

}  // namespace

SurfaceFire surface_fire(const FuelModel& fuel, const FuelMoisture& moisture, bool explain) {
  SurfaceFire fire;
  fire.depth = fuel.depth;
  if (!fuel.burnable()) {
    if (explain) fire.extinct = fmt::format("{} carries no fire (no fuel)", fuel.name);
    return fire;
  }
  auto load = [&](int k) { return fuel.load[k] / kPoundPerSquareFoot; };
  auto sav = [&](int k) { return fuel.sav[k] * kFoot; };
  const double heat_dead = fuel.heat_dead / kBtuPerPound, heat_live = fuel.heat_live / kBtuPerPound;
  // Dynamic models: the cured share of the herbaceous load joins the dead fuel, with the 1-h
  // moisture (all of it at 30 % herbaceous moisture, none at 120 %: Scott & Burgan 2005).
  const double cured = fuel.dynamic ? std::clamp((1.20 - moisture.value[live_herb]) / 0.90, 0.0, 1.0) : 0.0;
  const std::vector<Particle> dead = {
      {load(dead_1h), sav(dead_1h), moisture.value[dead_1h], heat_dead},
      {load(dead_10h), sav(dead_10h), moisture.value[dead_10h], heat_dead},
      {load(dead_100h), sav(dead_100h), moisture.value[dead_100h], heat_dead},
      {cured * load(live_herb), sav(live_herb), moisture.value[dead_1h], heat_dead},
  };
  const std::vector<Particle> live = {
      {(1 - cured) * load(live_herb), sav(live_herb), moisture.value[live_herb], heat_live},
      {load(live_woody), sav(live_woody), moisture.value[live_woody], heat_live},
  };
  const Category d = weigh(dead), l = weigh(live);
  const double total_area = d.area + l.area;
  const double f_dead = d.area / total_area, f_live = l.area / total_area;
  const double sigma = f_dead * d.sav + f_live * l.sav;  // characteristic surface-area-to-volume ratio, 1/ft

  double total_load = 0;
  for (int k = 0; k < kFuelClasses; ++k) total_load += load(k);
  const double depth = fuel.depth / kFoot;
  const double bulk_density = total_load / depth;  // lb/ft³
  const double packing = bulk_density / kParticleDensity;
  const double optimum = 3.348 * std::pow(sigma, -0.8189);
  const double ratio = packing / optimum;
  const double sigma15 = std::pow(sigma, 1.5);
  const double max_reaction_velocity = sigma15 / (495 + 0.0594 * sigma15);  // 1/min
  const double a = 133 * std::pow(sigma, -0.7913);                          // Albini (1976)
  const double reaction_velocity = max_reaction_velocity * std::pow(ratio, a) * std::exp(a * (1 - ratio));
  const double mineral_damping = std::min(1.0, 0.174 * std::pow(kEffectiveMineral, -0.19));

  // Moisture of extinction of the live fuel (Albini 1976), from the fine dead and live loads.
  const double dead_extinction = fuel.extinction_moisture;
  double live_extinction = dead_extinction;
  if (l.area > 0) {
    double fine_dead = 0, fine_dead_water = 0, fine_live = 0;
    for (const Particle& p : dead)
      if (p.load > 0) {
        const double w = p.load * std::exp(-138 / p.sav);
        fine_dead += w, fine_dead_water += w * p.moisture;
      }
    for (const Particle& p : live)
      if (p.load > 0) fine_live += p.load * std::exp(-500 / p.sav);
    const double dead_moisture = fine_dead > 0 ? fine_dead_water / fine_dead : 0;
    const double ratio_dead_live = fine_live > 0 ? fine_dead / fine_live : 0;
    live_extinction =
        std::max(dead_extinction, 2.9 * ratio_dead_live * (1 - dead_moisture / dead_extinction) - 0.226);
  }
  const double dead_damping = moisture_damping(d.moisture, dead_extinction);
  const double live_damping = l.area > 0 ? moisture_damping(l.moisture, live_extinction) : 0;
  const double reaction_intensity =  // BTU/ft²/min
      reaction_velocity * (d.net_load * d.heat * dead_damping + l.net_load * l.heat * live_damping) * mineral_damping;
  const double propagating_flux =
      std::exp((0.792 + 0.681 * std::sqrt(sigma)) * (packing + 0.1)) / (192 + 0.2595 * sigma);
  const double heat_sink = bulk_density * (f_dead * d.heat_sink + f_live * l.heat_sink);  // BTU/ft³
  const double rate0 = reaction_intensity * propagating_flux / heat_sink;                  // ft/min
  const double residence_time = 384 / sigma;                                               // min

  fire.rate0 = rate0 * kFootPerMinute;
  fire.reaction_intensity = reaction_intensity * kBtuPerSquareFoot / 60;
  fire.residence_time = residence_time * 60;
  fire.heat_per_unit_area = reaction_intensity * residence_time * kBtuPerSquareFoot;
  fire.wind_c = 7.47 * std::exp(-0.133 * std::pow(sigma, 0.55));
  fire.wind_b = 0.02526 * std::pow(sigma, 0.54);
  fire.wind_e = 0.715 * std::exp(-3.59e-4 * sigma);
  fire.packing_ratio_ratio = ratio;
  fire.slope_factor = 5.275 * std::pow(packing, -0.3);
  fire.max_effective_wind = 0.9 * reaction_intensity * kFootPerMinute;
  if (!(fire.rate0 > 0)) {
    fire.rate0 = 0;
    if (explain)
      fire.extinct = fmt::format("{} does not burn: the dead fuel's moisture ({:.3g} %) is at or above its moisture of "
                               "extinction ({:.3g} %){}",
                               fuel.name, 100 * d.moisture, 100 * dead_extinction,
                               l.area > 0 ? fmt::format(" and the live fuel's ({:.3g} %) at or above its own ({:.3g} %)",
                                                        100 * l.moisture, 100 * live_extinction)
                                          : std::string());
  }
  return fire;
}

HeadSpread head_spread(const SurfaceFire& fire, const Vec3& wind, const Vec3& upslope, double tan_slope,
                       const SpreadOptions& options) {
  HeadSpread s;
  if (!(fire.rate0 > 0)) return s;
  const double speed = wind.norm() / kFootPerMinute;  // ft/min
  const double wind_factor =
      speed > 0 ? fire.wind_c * std::pow(speed, fire.wind_b) * std::pow(fire.packing_ratio_ratio, -fire.wind_e) : 0;
  const double slope_factor = fire.slope_factor * tan_slope * tan_slope;
  // Wind and slope as vectors (BehavePlus): the direction of maximum spread is their sum's.
  Vec3 combined(0, 0, 0);
  if (speed > 0) combined += wind_factor * (wind / wind.norm());
  if (slope_factor > 0) combined += slope_factor * upslope;
  double factor = combined.norm();
  double effective = factor > 0 ? std::pow(factor * std::pow(fire.packing_ratio_ratio, fire.wind_e) / fire.wind_c,
                                           1 / fire.wind_b)
                                : 0;  // ft/min
  const double limit = fire.max_effective_wind / kFootPerMinute;
  if (options.limit_effective_wind && effective > limit) {
    effective = limit;
    const double capped = fire.wind_c * std::pow(effective, fire.wind_b) * std::pow(fire.packing_ratio_ratio, -fire.wind_e);
    s.wind_limited = true;
    combined *= capped / factor;
    factor = capped;
  }
  s.head = fire.rate0 * (1 + factor);
  s.direction = factor > 0 ? combined / combined.norm() : Vec3(0, 0, 0);
  s.effective_wind = effective * kFootPerMinute;
  s.length_to_width = std::min(length_to_width(s.effective_wind), options.max_length_to_width);
  const double lw = s.length_to_width;
  const double eccentricity = std::sqrt(std::max(0.0, lw * lw - 1)) / lw;
  s.back = s.head * (1 - eccentricity) / (1 + eccentricity);
  s.flank = (s.head + s.back) / (2 * lw);
  return s;
}

double ellipse_normal_rate(const HeadSpread& s, const Vec3& normal) {
  const double a = 0.5 * (s.head + s.back), c = 0.5 * (s.head - s.back), b = s.flank;
  const double along = OpenMesh::dot(normal, s.direction);
  const double across2 = std::max(0.0, normal.sqrnorm() - along * along);
  return c * along + std::sqrt(a * a * along * along + b * b * across2);
}

double length_to_width(double effective_wind) {
  const double u = effective_wind / kMilePerHour;
  return 0.936 * std::exp(0.2566 * u) + 0.461 * std::exp(-0.1548 * u) - 0.397;
}

double flame_length(double intensity) { return intensity > 0 ? 0.0775 * std::pow(intensity, 0.46) : 0.0; }

bool parse_wind_height(std::string_view name, WindHeight& height) {
  if (name == "midflame") height = WindHeight::midflame;
  else if (name == "20ft") height = WindHeight::twenty_feet;
  else if (name == "10m") height = WindHeight::ten_metres;
  else return false;
  return true;
}

std::string_view wind_height_name(WindHeight height) {
  switch (height) {
    case WindHeight::midflame: return "midflame";
    case WindHeight::twenty_feet: return "20ft";
    case WindHeight::ten_metres: return "10m";
  }
  return "?";
}

double wind_adjustment_factor(double depth, const Sheltering& shelter) {
  const double fill = shelter.cover / 3 * shelter.crown_ratio;
  if (fill > 0.05 && shelter.canopy_height > 0) {
    const double h = shelter.canopy_height / kFoot;
    return 0.555 / (std::sqrt(fill * h) * std::log((20 + 0.36 * h) / (0.13 * h)));
  }
  if (!(depth > 0)) return 0;
  const double feet = depth / kFoot;
  return 1.83 / std::log((20 + 0.36 * feet) / (0.13 * feet));
}

double midflame_factor(WindHeight height, double depth, const Sheltering& shelter) {
  switch (height) {
    case WindHeight::midflame: return 1;
    case WindHeight::twenty_feet: return wind_adjustment_factor(depth, shelter);
    case WindHeight::ten_metres: return wind_adjustment_factor(depth, shelter) / 1.15;
  }
  return 1;
}

double twenty_foot_factor(WindHeight height, double depth, const Sheltering& shelter) {
  switch (height) {
    case WindHeight::twenty_feet: return 1;
    case WindHeight::ten_metres: return 1 / 1.15;
    case WindHeight::midflame: {
      const double waf = wind_adjustment_factor(depth, shelter);
      return waf > 0 ? 1 / waf : 0.0;
    }
  }
  return 1;
}

}  // namespace bodyfit::fire

namespace bodyfit::fire {

TerrainSlope terrain_slope(const Vec3& normal) {
  // Upslope: the vertical's tangential part; |e3 − (e3·N)N| = sin θ, tan θ = sin θ / |N·e3|.
  const double nz = normal[2];
  Vec3 upslope = Vec3(0, 0, 1) - nz * normal;
  const double sine = upslope.norm();
  if (!(sine > 1e-12) || !(std::abs(nz) > 1e-12)) return {};
  return {upslope / sine, sine / std::abs(nz)};
}

Vec3 tangent_wind(const Vec3& wind, const Vec3& normal) {
  const double speed = wind.norm();
  const Vec3 along = wind - OpenMesh::dot(wind, normal) * normal;
  const double length = along.norm();
  return length > 1e-12 * std::max(1.0, speed) ? along * (speed / length) : Vec3(0, 0, 0);
}

HeadSpread head_spread_on_terrain(const SurfaceFire& fire, const Vec3& normal, const Vec3& wind, double to_midflame,
                                  const SpreadOptions& options) {
  const TerrainSlope slope = terrain_slope(normal);
  return head_spread(fire, tangent_wind(to_midflame * wind, normal), slope.upslope, slope.tan_slope, options);
}

}  // namespace bodyfit::fire
