#include "balbi.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace bodyfit::fire {

BalbiParameters preset(std::string_view name) {
  BalbiParameters p;
  if (name == "balbi2009") {
    p.R0 = 0.39801;
    p.A = 1.872531;
  } else if (name == "paper_table1") {
    p.R0 = 2.7;
    p.A = 1.25;
  } else {
    throw std::invalid_argument("unknown fuel preset '" + std::string(name) +
                                "' (known: balbi2009, paper_table1)");
  }
  p.u0 = 39.8;
  p.v0 = 12 * p.R0;
  return p;
}

double rate_of_spread(double tilt, const BalbiParameters& p) {
  if (!(tilt > 0)) return p.R0;  // backing fire (and NaN-safe)
  const double gamma = std::min(tilt, p.max_tilt);
  const double c = std::cos(gamma);
  const double ra = p.R0 + p.A * p.v0 * (1 + std::sin(gamma) - c) / c - p.v0 / c;
  const double b = 4 * p.v0 * p.R0 / c;  // 48·R0²/cos γ when v0 = 12·R0
  const double root = std::sqrt(ra * ra + b);
  // R is the positive root of R² − Ra·R − b/4 = 0. For Ra < 0, ½(Ra + root) cancels: use the
  // product of the roots instead, R = (b/4)/R⁻ with R⁻ = ½(root − Ra).
  return ra >= 0 ? 0.5 * (ra + root) : 0.5 * b / (root - ra);
}

double tan_tilt(double height_gradient_dot_normal, double vertical_normal, double wind_dot_normal,
                const BalbiParameters& p) {
  const double slope_term = vertical_normal > 1e-12 ? height_gradient_dot_normal / vertical_normal : 0.0;
  return slope_term + wind_dot_normal / p.u0;
}

}  // namespace bodyfit::fire
