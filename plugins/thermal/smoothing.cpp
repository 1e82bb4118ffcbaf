#include "smoothing.hpp"

#include <bodyfit/error.hpp>

#include <cmath>
#include <fmt/format.h>

namespace bodyfit::thermal {

namespace {

/// t = 4r/(r² − 1), with r² − 1 = (r − 1)(r + 1) to keep its relative accuracy near ±1.
double exponent(double r) { return 4 * r / ((r - 1) * (r + 1)); }

void check_epsilon(double epsilon) {
  if (!(epsilon > 0) || !std::isfinite(epsilon))
    throw InputError(fmt::format("thermal model: ε = {} (the width of the Robin transition must be positive)", epsilon));
}

}  // namespace

double h(double r) {
  if (r <= -1) return 1;
  if (r >= 1) return 0;
  // 1 − 1/(1 + e^t) = σ(t), evaluated so that the exponential never overflows.
  double t = exponent(r);
  if (t >= 0) return 1 / (1 + std::exp(-t));
  double e = std::exp(t);
  return e / (1 + e);
}

double h_prime(double r) {
  if (r <= -1 || r >= 1) return 0;
  double t = exponent(r);
  // σ′(t) = e^{−|t|}/(1 + e^{−|t|})²: when it underflows, h′ is 0 (the rational factor only grows
  // like 1/(1 − r²)², far slower than the exponential decays).
  double e = std::exp(-std::abs(t));
  if (e == 0) return 0;
  double sigma_prime = e / ((1 + e) * (1 + e));
  double q = (r - 1) * (r + 1);
  return -sigma_prime * 4 * (1 + r * r) / (q * q);
}

double h_epsilon(double d, double epsilon) {
  check_epsilon(epsilon);
  return h(d / epsilon) / epsilon;
}

double h_epsilon_prime(double d, double epsilon) {
  check_epsilon(epsilon);
  return h_prime(d / epsilon) / (epsilon * epsilon);
}

}  // namespace bodyfit::thermal
