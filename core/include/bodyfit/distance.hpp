#pragma once
// Signed geodesic distance on a triangulated surface (step 2 of Algorithm 1, paper §3.2).
#include <bodyfit/mesh.hpp>

#include <limits>
#include <memory>
#include <span>
#include <vector>

namespace bodyfit {

struct DistanceOptions {
  /// Stop marching beyond this |d| (narrow band); vertices beyond keep ±infinity.
  double narrow_band = std::numeric_limits<double>::infinity();
  /// Region mode: measure the distance to the smooth curve through the interface vertices, not to
  /// the polygon of interface edges. Each edge is taken as an arc bending with the curvature
  /// estimated at its two ends (circle through each vertex and its two neighbours, in the tangent
  /// plane): the chord lies O(h²κ) inside a convex curve, the arc removes that bias (O(h³) left).
  /// Edges with an end that is not a smooth curve point (interface-degree ≠ 2, on the boundary of
  /// S, or a turn above 30°) stay straight. The φ mode ignores it (its zero set is O(h²) anyway).
  bool curved_interface = true;
  /// Region mode with curved_interface: carry the geodesic curvature of the front from the
  /// interface's (Riccati equation of parallel curves, dκ/ds = −κ² − K, K the discrete Gaussian
  /// curvature) and update with circular fronts instead of straight ones. The planar update errs by
  /// O(h²κ) wherever the front is curved, which adds up to a first-order error far from the
  /// interface.
  bool front_curvature = true;
  /// φ mode: the vertices of the faces the zero set crosses keep their values of φ; only the
  /// vertices beyond get the distance. The exact initialisation gives those vertices the distance to
  /// the P1 zero set, whose own P1 zero set lies O(h²κ) elsewhere: redistancing once is harmless,
  /// but the CFL sub-steps of a step redistance tens of times, and on a front that moves slowly
  /// (the flanks of a head) the shifts add up to more than the motion (docs/validation/advection.md, "Sub-steps that converge").
  /// With it, redistancing leaves the zero set exactly where it was.
  bool keep_crossings = false;
};

struct DistanceReport {
  std::size_t initialised = 0;  ///< vertices given an exact value near the interface
  std::size_t marched = 0;      ///< vertices accepted by fast marching
  bool has_interface = true;    ///< false when φ does not change sign (result is all ±infinity)
  double setup_ms = 0;          ///< flat arrays, fans, obtuse-angle unfolding
  double init_ms = 0;           ///< interface segments (zero set of φ, or interface edges)
  double march_ms = 0;          ///< exact initialisation near the interface, then fast marching
};

/// Signed geodesic distance to the zero level set of the P1 function φ (any scale; negative inside).
/// When φ has no zero crossing, every vertex gets +infinity (φ > 0 everywhere) or −infinity.
ScalarField signed_distance(const SurfaceMesh& mesh, const ScalarField& phi,
                            const DistanceOptions& options = {}, DistanceReport* report = nullptr);

/// Signed geodesic distance to the region made of the faces labelled kInside (f:region): the
/// interface is the set of e:interface edges; inside vertices get negative values.
ScalarField signed_distance_to_region(const SurfaceMesh& mesh, const DistanceOptions& options = {},
                                      DistanceReport* report = nullptr);

/// Distances on one fixed mesh, its flat arrays and obtuse-angle unfoldings built once: the d of a
/// state and then the redistancing of each CFL sub-step, whose narrow-band calls cost what the
/// band holds, not the mesh. The mesh must outlive the solver, unchanged.
class DistanceSolver {
 public:
  explicit DistanceSolver(const SurfaceMesh& mesh);
  ~DistanceSolver();
  DistanceSolver(DistanceSolver&&) noexcept;

  /// As the free functions of the same names.
  ScalarField signed_distance(const ScalarField& phi, const DistanceOptions& options = {},
                              DistanceReport* report = nullptr);
  ScalarField signed_distance_to_region(const DistanceOptions& options = {}, DistanceReport* report = nullptr);

  /// Narrow-band redistancing in place: φ becomes its signed distance (φ-mode, as signed_distance)
  /// at the vertices within `width` of its zero set, which are returned (sorted); every other
  /// value is left as it is. The zero set is looked for in the faces around the vertices `near`,
  /// which must include every vertex of a face where φ changes sign. Of `options`, only
  /// keep_crossings applies.
  std::vector<int> redistance(ScalarField& phi, double width, std::span<const int> near,
                              DistanceReport* report = nullptr, const DistanceOptions& options = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace bodyfit
