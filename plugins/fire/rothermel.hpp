#pragma once
// Rothermel's (1972) surface fire spread model with Albini's (1976) corrections, as BehavePlus,
// FARSITE, FlamMap and ELMFIRE use it: the head rate of spread from the fuel, its moistures, the
// midflame wind and the slope (combined as an effective wind, with its maximum), the elliptical
// fire shape of Anderson (1983), Byram's fireline intensity and flame length. The equations are
// evaluated in the published US customary units; every input and output here is SI.
#include "fuel.hpp"

#include <bodyfit/mesh.hpp>

#include <string>
#include <string_view>

namespace bodyfit::fire {

/// What a fuel bed does under given moistures, before wind and slope.
struct SurfaceFire {
  double rate0 = 0;               ///< no-wind, no-slope rate of spread, m/s
  double reaction_intensity = 0;  ///< kW/m²
  double residence_time = 0;      ///< flame residence time, s (384/σ min)
  double heat_per_unit_area = 0;  ///< kJ/m² (reaction intensity × residence time)
  double depth = 0;               ///< fuel bed depth, m (for the wind adjustment factor)
  std::string extinct;            ///< why it does not burn (no fuel, moisture above extinction); "" when it does
  // Wind and slope factors (Rothermel's C, B, E, β/β_op and 5.275 β^-0.3), in his units (ft/min).
  double wind_c = 0, wind_b = 0, wind_e = 0, packing_ratio_ratio = 0, slope_factor = 0;
  double max_effective_wind = 0;  ///< 0.9 × reaction intensity (ft/min per BTU/ft²/min), m/s
};

/// The fuel bed of `fuel` under `moisture` (dead and live moistures of extinction, the dynamic
/// transfer of cured herbaceous load to the dead classes). `explain`: say in `extinct` why it does
/// not burn (false where that is not read: per vertex, per cell).
SurfaceFire surface_fire(const FuelModel& fuel, const FuelMoisture& moisture, bool explain = true);

struct SpreadOptions {
  /// Cap the effective wind speed at 0.9 × the reaction intensity (Rothermel 1972), as BehavePlus
  /// does by default.
  bool limit_effective_wind = true;
  /// The largest length-to-width ratio of the fire ellipse (BehavePlus and FARSITE take 8).
  double max_length_to_width = 8;
};

/// The fire's ellipse at a point: the head rate in the direction of maximum spread, and the shape.
struct HeadSpread {
  double head = 0;             ///< m/s
  double back = 0;             ///< m/s
  double flank = 0;            ///< m/s, the half-width rate: (head + back) / (2 · length_to_width)
  Vec3 direction{0, 0, 0};     ///< of maximum spread (unit; 0 without wind and slope)
  double effective_wind = 0;   ///< m/s: the midflame wind that alone gives the head rate
  double length_to_width = 1;  ///< Anderson (1983)
  bool wind_limited = false;   ///< the effective wind was capped
};

/// The head spread under the midflame wind `wind` (m/s, a vector) on a slope rising along `upslope`
/// (a unit vector in the plane of the wind) with tan(slope angle) `tan_slope`.
HeadSpread head_spread(const SurfaceFire& fire, const Vec3& wind, const Vec3& upslope, double tan_slope,
                       const SpreadOptions& options = {});

/// The normal speed of the front of the ellipse in the direction `normal` (unit, in the plane of
/// the spread): the support function of the ellipse traced in unit time with the ignition at its
/// rear focus-side point, c (n·d) + √(a²(n·d)² + b²|n − (n·d)d|²), a = (head + back)/2,
/// c = (head − back)/2, b = flank. head along d, back against it, flank across.
double ellipse_normal_rate(const HeadSpread& spread, const Vec3& normal);

/// Anderson's (1983) length-to-width ratio of a fire under an effective midflame wind (m/s):
/// 0.936 e^{0.2566 U} + 0.461 e^{−0.1548 U} − 0.397 with U in mi/h; 1 in calm air.
double length_to_width(double effective_wind);

/// Byram's (1959) fireline intensity, kW/m, of a fire of heat per unit area `heat` (kJ/m²) moving at `rate` (m/s).
inline double fireline_intensity(double heat, double rate) { return heat * rate; }
/// Byram's (1959) flame length, m: 0.0775 I^0.46 (I in kW/m; 0.45 I^0.46 in ft and BTU/ft/s).
double flame_length(double intensity);

/// The height a wind is given at.
enum class WindHeight { midflame, twenty_feet, ten_metres };
/// "midflame", "20ft", "10m"; false for another name.
bool parse_wind_height(std::string_view name, WindHeight& height);
std::string_view wind_height_name(WindHeight height);
/// A canopy that shelters the fuel from the wind.
struct Sheltering {
  double cover = 0;          ///< canopy cover, fraction
  double canopy_height = 0;  ///< m
  double crown_ratio = 0;    ///< (canopy height − base height) / canopy height
};
/// The wind adjustment factor of Albini & Baughman (1979) as BehavePlus uses it (Andrews 2012):
/// unsheltered 1.83 / ln((20 + 0.36 δ) / (0.13 δ)), δ the fuel bed depth in ft; under a canopy whose
/// crown fill f = cover/3 · crown ratio exceeds 5 %, sheltered 0.555 / (√(f H) ln((20 + 0.36 H) /
/// (0.13 H))), H the canopy height in ft.
double wind_adjustment_factor(double depth, const Sheltering& shelter = {});
/// The midflame wind of a wind measured at `height` over a bed of `depth` (m): a 10-m wind is
/// 1.15 × the 20-ft wind (Turner & Lawson 1978), a 20-ft wind × the wind adjustment factor.
double midflame_factor(WindHeight height, double depth, const Sheltering& shelter = {});
/// The factor that brings a wind measured at `height` to 20 ft (a midflame wind goes back up by
/// the wind adjustment factor; 0 where that is 0: no bed, no wind to speak of).
double twenty_foot_factor(WindHeight height, double depth, const Sheltering& shelter = {});

}  // namespace bodyfit::fire

namespace bodyfit::fire {

/// The slope of a terrain of unit normal `normal`: the upslope direction in its tangent plane
/// (0 on flat ground) and tan(slope angle).
struct TerrainSlope {
  Vec3 upslope{0, 0, 0};
  double tan_slope = 0;
};
TerrainSlope terrain_slope(const Vec3& normal);
/// A horizontal wind turned into the tangent plane of `normal`, its speed kept.
Vec3 tangent_wind(const Vec3& wind, const Vec3& normal);

/// Rothermel's spread at a point of a terrain of unit normal `normal`: the slope and its upslope
/// direction from the normal, the horizontal wind `wind` (m/s, at its height) times
/// `to_midflame`, turned into the tangent plane with its speed kept.
HeadSpread head_spread_on_terrain(const SurfaceFire& fire, const Vec3& normal, const Vec3& wind, double to_midflame,
                                  const SpreadOptions& options = {});

}  // namespace bodyfit::fire
