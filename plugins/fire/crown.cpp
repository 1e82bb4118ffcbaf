#include "crown.hpp"

#include <cmath>
#include <limits>

namespace bodyfit::fire {

std::string_view fire_type_name(FireType type) {
  switch (type) {
    case FireType::surface: return "surface";
    case FireType::passive: return "passive crown";
    case FireType::active: return "active crown";
  }
  return "?";
}

CrownFire crown_fire(const HeadSpread& surface, double surface_heat, const Canopy& canopy, const SurfaceFire& fm10,
                     const Vec3& wind_20ft, const Vec3& upslope, double tan_slope, const SpreadOptions& options) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  CrownFire crown;
  crown.spread = surface;
  const bool has_canopy = canopy.bulk_density > 0;
  crown.initiation_intensity =
      has_canopy ? std::pow(0.010 * canopy.base_height * (460 + 25.9 * 100 * canopy.foliar_moisture), 1.5) : inf;
  crown.critical_active_rate = has_canopy ? 3.0 / canopy.bulk_density / 60 : inf;
  const HeadSpread fm10_spread = head_spread(fm10, 0.4 * wind_20ft, upslope, tan_slope, options);
  crown.active_rate = 3.34 * fm10_spread.head;
  if (!has_canopy || fireline_intensity(surface_heat, surface.head) < crown.initiation_intensity) return crown;
  if (crown.active_rate < crown.critical_active_rate) {
    crown.type = FireType::passive;
    return crown;
  }
  crown.type = FireType::active;
  HeadSpread& s = crown.spread;
  s.head = std::max(crown.active_rate, surface.head);
  if (s.direction.sqrnorm() == 0) s.direction = fm10_spread.direction;
  s.length_to_width = std::min(1 + 0.125 * wind_20ft.norm() / 0.44704, options.max_length_to_width);
  const double lw = s.length_to_width;
  const double eccentricity = std::sqrt(std::max(0.0, lw * lw - 1)) / lw;
  s.back = s.head * (1 - eccentricity) / (1 + eccentricity);
  s.flank = (s.head + s.back) / (2 * lw);
  return crown;
}

}  // namespace bodyfit::fire
