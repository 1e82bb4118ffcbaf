#pragma once
// Crown fire (Van Wagner 1977; Rothermel 1991; Scott & Reinhardt 2001, as FlamMap and BehavePlus
// classify it): whether a surface fire climbs into the canopy, and whether the crown fire spreads
// on its own (active) or only torches trees (passive).
#include "rothermel.hpp"

namespace bodyfit::fire {

/// The canopy over a point.
struct Canopy {
  double base_height = 0;        ///< canopy base height, m
  double bulk_density = 0;       ///< canopy bulk density, kg/m³
  double foliar_moisture = 1.0;  ///< foliar moisture content, fraction (100 % by default)
};

enum class FireType : int { surface = 1, passive = 2, active = 3 };
std::string_view fire_type_name(FireType type);

struct CrownFire {
  FireType type = FireType::surface;
  double initiation_intensity = 0;  ///< Van Wagner's critical surface intensity, kW/m (∞ without canopy)
  double active_rate = 0;           ///< Rothermel's (1991) crown rate of spread, m/s: 3.34 × FM10's
  double critical_active_rate = 0;  ///< Van Wagner's 3.0 / CBD m/min, in m/s (∞ without canopy)
  HeadSpread spread;                ///< the fire's ellipse: the surface one, or the active crown fire's
};

/// The crown fire over a surface fire of head spread `surface` and heat per unit area
/// `surface_heat` (kJ/m²): initiation when its head intensity reaches (0.010 CBH (460 + 25.9 FMC))^1.5
/// kW/m (FMC in %); active when the crown rate 3.34 R₁₀ reaches 3.0/CBD m/min, R₁₀ the head rate of
/// Anderson's fuel model 10 (`fm10`, under the same moistures) with the 20-ft wind × 0.4 and the
/// same slope. An active fire spreads at 3.34 R₁₀ with the length-to-width 1 + 0.125 U₂₀ (U₂₀ in
/// mi/h, Rothermel 1991) along the surface fire's direction; a passive one at the surface rate.
CrownFire crown_fire(const HeadSpread& surface, double surface_heat, const Canopy& canopy, const SurfaceFire& fm10,
                     const Vec3& wind_20ft, const Vec3& upslope, double tan_slope, const SpreadOptions& options = {});

}  // namespace bodyfit::fire
