#include "quadrature.hpp"

#include <bodyfit/error.hpp>

#include <cmath>
#include <fmt/format.h>

namespace bodyfit::thermal {

namespace {

/// Radon's 7-point rule of degree 5 on the reference triangle: the centroid and two orbits of three
/// points (a, a, 1 − 2a), a = (6 ∓ √15)/21.
std::array<TrianglePoint, 7> radon7() {
  const double s = std::sqrt(15.0);
  const double a1 = (6 - s) / 21, w1 = (155 - s) / 1200;
  const double a2 = (6 + s) / 21, w2 = (155 + s) / 1200;
  const double b1 = 1 - 2 * a1, b2 = 1 - 2 * a2;
  return {{{{1.0 / 3, 1.0 / 3, 1.0 / 3}, 9.0 / 40},
           {{a1, a1, b1}, w1},
           {{a1, b1, a1}, w1},
           {{b1, a1, a1}, w1},
           {{a2, a2, b2}, w2},
           {{a2, b2, a2}, w2},
           {{b2, a2, a2}, w2}}};
}

}  // namespace

std::vector<TrianglePoint> triangle_points(const TriangleQuadrature& rule) {
  const int k = rule.subdivisions;
  if (k < 1 || k > 64)
    throw InputError(fmt::format("triangle quadrature: subdivisions = {} (expected 1 to 64)", k));
  const auto base = radon7();
  std::vector<TrianglePoint> points;
  points.reserve(std::size_t(7 * k * k));
  // Sub-triangles of the barycentric grid of step 1/k, in (ξ, η) coordinates (λ = (1 − ξ − η, ξ, η)).
  auto add = [&](std::array<double, 2> p0, std::array<double, 2> p1, std::array<double, 2> p2) {
    for (const auto& q : base) {
      double xi = q.barycentric[0] * p0[0] + q.barycentric[1] * p1[0] + q.barycentric[2] * p2[0];
      double eta = q.barycentric[0] * p0[1] + q.barycentric[1] * p1[1] + q.barycentric[2] * p2[1];
      points.push_back({{1 - xi - eta, xi, eta}, q.weight / double(k * k)});
    }
  };
  const double step = 1.0 / k;
  for (int i = 0; i < k; ++i)
    for (int j = 0; i + j < k; ++j) {
      add({i * step, j * step}, {(i + 1) * step, j * step}, {i * step, (j + 1) * step});
      if (i + j + 2 <= k)
        add({(i + 1) * step, j * step}, {(i + 1) * step, (j + 1) * step}, {i * step, (j + 1) * step});
    }
  return points;
}

const std::array<TetPoint, 4>& tet_points_degree2() {
  static const std::array<TetPoint, 4> points = [] {
    const double a = (5 - std::sqrt(5.0)) / 20, b = 1 - 3 * a;
    return std::array<TetPoint, 4>{{{{b, a, a, a}, 0.25}, {{a, b, a, a}, 0.25}, {{a, a, b, a}, 0.25},
                                    {{a, a, a, b}, 0.25}}};
  }();
  return points;
}

}  // namespace bodyfit::thermal
