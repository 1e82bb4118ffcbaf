#pragma once
// Advection of a level set on a surface by the method of characteristics (step 3 of Algorithm 1,
// paper §3.3): φ(T, x) = φ0(χ(0, T, x)), the foot of each vertex's characteristic found by tracing
// backwards along V on the triangulated surface.
#include <bodyfit/mesh.hpp>

namespace bodyfit {

struct AdvectionOptions {
  int rk_order = 2;            ///< 2 (midpoint) or 4 (classical Runge–Kutta)
  /// Sub-steps are sized so that one crosses at most about this many local edge lengths.
  double max_cells_per_substep = 1.0;
  int steps = 1;               ///< outer steps over (0, T) (the velocity is frozen anyway)
  /// Value at the foot: false = P1 interpolation of φ0; true = the mean of the P1 interpolation and
  /// of the barycentric average of the vertices' first-order Taylor expansions (vertex gradients),
  /// clamped to the face's range. The two have opposite O(h²) errors (P1 over-estimates a convex φ0
  /// such as a distance function, the Taylor planes under-estimate it), so the mean removes the
  /// inward drift of a convex front that P1 interpolation causes at every step.
  bool gradient_correction = true;
};

struct AdvectionReport {
  std::size_t traced = 0;            ///< characteristics traced (= vertices)
  std::size_t hit_boundary = 0;      ///< stopped on the boundary of an open surface
  std::size_t substeps = 0;          ///< total sub-steps over all vertices
  std::size_t lost = 0;              ///< characteristics that failed (must stay 0)
};

/// Solve ∂φ/∂t + V·∇_S φ = 0 on (0, T), V given at the vertices (projected on the tangent plane
/// where evaluated). Returns φ(T) at the vertices. Deterministic for any thread count.
ScalarField advect(const SurfaceMesh& mesh, const ScalarField& phi, const VectorField& velocity, double T,
                   const AdvectionOptions& options = {}, AdvectionReport* report = nullptr);

/// The Hamilton–Jacobi form (3.3): V = v ∇_S φ/|∇_S φ| (per-face gradients of φ averaged to the
/// vertices, area-weighted), then advect().
ScalarField advect_normal(const SurfaceMesh& mesh, const ScalarField& phi, const ScalarField& normal_speed,
                          double T, const AdvectionOptions& options = {}, AdvectionReport* report = nullptr);

}  // namespace bodyfit
