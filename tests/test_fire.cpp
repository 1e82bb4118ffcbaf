// The Balbi rate of spread (paper §4.3, formulas 4.7–4.8) and the fire plugin.
#include "balbi.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <stdexcept>

using namespace bodyfit::fire;

namespace {
constexpr double kDeg = M_PI / 180;

// (4.8) exactly as printed, for comparison where it does not cancel.
double textbook_ros(double gamma, const BalbiParameters& p) {
  double c = std::cos(gamma);
  double ra = p.R0 + 12 * p.A * p.R0 * (1 + std::sin(gamma) - c) / c - 12 * p.R0 / c;
  return 0.5 * (ra + std::sqrt(ra * ra + 48 * p.R0 * p.R0 / c));
}
}  // namespace

TEST_CASE("rate of spread: golden values of Balbi's fuel parameters") {
  BalbiParameters p;  // R0 = 0.39801, A = 1.872531, v0 = 12·R0
  CHECK(rate_of_spread(5 * kDeg, p) == doctest::Approx(0.471067).epsilon(1e-6));
  CHECK(rate_of_spread(30 * kDeg, p) == doctest::Approx(2.360116).epsilon(1e-6));
  CHECK(rate_of_spread(60 * kDeg, p) == doctest::Approx(15.524577).epsilon(1e-6));
  CHECK(rate_of_spread(0.0, p) == p.R0);
  CHECK(rate_of_spread(-20 * kDeg, p) == p.R0);
  CHECK(rate_of_spread(std::nan(""), p) == p.R0);
}

TEST_CASE("rate of spread is continuous at zero tilt and increasing") {
  BalbiParameters p;
  for (double g : {1e-12, 1e-9, 1e-6}) CHECK(rate_of_spread(g, p) == doctest::Approx(p.R0).epsilon(1e-5));
  double previous = p.R0;
  for (double g = 0.5; g < 80; g += 0.5) {
    double r = rate_of_spread(g * kDeg, p);
    CHECK(r > previous);
    previous = r;
  }
}

TEST_CASE("stable evaluation agrees with the printed formula where it does not cancel") {
  BalbiParameters p;
  for (double g : {20.0, 45.0, 70.0}) CHECK(rate_of_spread(g * kDeg, p) == doctest::Approx(textbook_ros(g * kDeg, p)).epsilon(1e-12));
  // Near 0 the printed formula loses digits; the stable one keeps R(γ)−R0 ∝ γ to first order.
  double g = 1e-7;
  double slope = (rate_of_spread(2 * g, p) - rate_of_spread(g, p)) / g;
  double slope_ref = (rate_of_spread(2e-4, p) - rate_of_spread(1e-4, p)) / 1e-4;
  CHECK(slope == doctest::Approx(slope_ref).epsilon(1e-3));
}

TEST_CASE("rate of spread is linear in R0 (with v0 = 12·R0)") {
  BalbiParameters p;
  BalbiParameters q = p;
  q.R0 = 3 * p.R0;
  q.v0 = 12 * q.R0;
  for (double g : {-10.0, 0.0, 5.0, 30.0, 60.0})
    CHECK(rate_of_spread(g * kDeg, q) == doctest::Approx(3 * rate_of_spread(g * kDeg, p)).epsilon(1e-12));
}

TEST_CASE("tilt is capped below 90 degrees") {
  BalbiParameters p;
  CHECK(std::isfinite(rate_of_spread(89.999 * kDeg, p)));
  CHECK(rate_of_spread(89.999 * kDeg, p) == rate_of_spread(p.max_tilt, p));
}

TEST_CASE("presets") {
  CHECK(preset("balbi2009").R0 == doctest::Approx(0.39801));
  CHECK(preset("paper_table1").R0 == doctest::Approx(2.7));
  CHECK(preset("paper_table1").A == doctest::Approx(1.25));
  CHECK_THROWS_AS(preset("pine"), std::invalid_argument);
}

TEST_CASE("tan of the tilt angle: slope and wind terms") {
  BalbiParameters p;
  // Plane inclined at α about the x axis, front normal uphill: tan γ = tan α.
  double alpha = 20 * kDeg;
  // ∇_S s · n_Σ = sin α (n_Σ uphill), |N·e3| = cos α.
  CHECK(tan_tilt(std::sin(alpha), std::cos(alpha), 0, p) == doctest::Approx(std::tan(alpha)));
  // Flat ground, wind along the front normal: tan γ = |U|/u0.
  CHECK(tan_tilt(0, 1, 10.0, p) == doctest::Approx(10.0 / p.u0));
  // Vertical wall (N·e3 = 0) does not divide by zero.
  CHECK(std::isfinite(tan_tilt(1, 0, 0, p)));
}
