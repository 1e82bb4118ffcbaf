#pragma once
// Quadrature rules on triangles and tetrahedra, in barycentric coordinates with weights summing to 1
// (multiply by the area or volume).
#include <array>
#include <vector>

namespace bodyfit::thermal {

template <int N>
struct QuadraturePoint {
  std::array<double, N> barycentric;
  double weight;
};
using TrianglePoint = QuadraturePoint<3>;
using TetPoint = QuadraturePoint<4>;

struct TriangleQuadrature {
  /// The 7-point rule of degree 5 (Radon) on each of subdivisions² congruent sub-triangles. The
  /// Robin coefficient h_ε(d) changes from 1/ε to 0 across a band of width 2ε, one or two triangles
  /// when ε ≈ h. Measured with ε = h (docs/validation/thermal_solvers.md): relative errors of ∫h_ε φφ and
  /// ∫h′_ε φφ over S are 1e-5 and 3e-3 with 1 subdivision, 2e-6 and 1e-4 with 2 (28 points).
  int subdivisions = 2;
};

/// The points of `rule` (throws InputError when subdivisions < 1).
std::vector<TrianglePoint> triangle_points(const TriangleQuadrature& rule);

/// The 4-point rule of degree 2 on a tetrahedron.
const std::array<TetPoint, 4>& tet_points_degree2();

}  // namespace bodyfit::thermal
