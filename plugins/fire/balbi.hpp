#pragma once
// The rate of spread of Balbi et al. (2009) as used in the paper's §4.3 (formulas 4.7, 4.8).
// Pure functions, SI units: metres, seconds, radians.
#include <string_view>

namespace bodyfit::fire {

struct BalbiParameters {
  double R0 = 0.39801;  ///< rate of spread without slope and wind, m/s
  double A = 1.872531;  ///< radiant / ignition energy ratio of the fuel, dimensionless
  double u0 = 39.8;     ///< combustion gas velocity without slope, m/s
  double v0 = 12 * 0.39801;  ///< flame-base velocity, m/s (12·R0 in Balbi's model)
  /// Tilt angles are capped here: R grows like 1/cos γ and is infinite at 90°.
  double max_tilt = 80.0 * 3.14159265358979323846 / 180.0;
};

/// Named parameter sets. "balbi2009": Balbi's fuel values (R0 ≈ 0.398 m/s, A ≈ 1.873), which give
/// the range of rates of spread the paper reports; "paper_table1": the paper's Table 1
/// (R0 = 2.7 m/s, A = 1.25), which contradicts its own reported minimum of 0.4 m/s.
/// Throws std::invalid_argument for an unknown name.
BalbiParameters preset(std::string_view name);

/// R(γ): R0 for γ ≤ 0, else (4.8), evaluated without cancellation (Ra < 0 for small γ), with γ
/// capped at max_tilt. Continuous at γ = 0 (R(0⁺) = R0) and increasing in γ.
double rate_of_spread(double tilt, const BalbiParameters& p);

/// tan γ from (4.7) written without angles, so that flat ground and calm air need no special case:
///   tan α cos β_p = (∇_S s · n_Σ) / |N·e3|   (∇_S s the tangential gradient of the height,
///                                              N the surface normal, n_Σ the unit front normal)
///   |U|/u0 cos β_U = (U · n_Σ) / u0
/// `height_gradient_dot_normal` is ∇_S s · n_Σ, `vertical_normal` is |N·e3|.
double tan_tilt(double height_gradient_dot_normal, double vertical_normal, double wind_dot_normal,
                const BalbiParameters& p);

}  // namespace bodyfit::fire
