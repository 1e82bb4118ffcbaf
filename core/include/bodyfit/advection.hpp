#pragma once
// Advection of a level set on a surface by the method of characteristics (step 3 of Algorithm 1,
// paper §3.3): φ(T, x) = φ0(χ(0, T, x)), the foot of each vertex's characteristic found by tracing
// backwards along V on the triangulated surface.
#include <bodyfit/mesh.hpp>

#include <memory>
#include <span>

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
  /// Budget of one call: the sub-steps it would take are estimated before tracing (each vertex's
  /// |V|·T over the cells of its face, at least `steps`) and the call refused (InputError) above
  /// this many in total; 0: no limit. About 10⁸ sub-steps a second per core: the default is a
  /// minute or so, a few hundred times a CFL-sized step.
  double max_substeps = 1e9;
};

struct AdvectionReport {
  std::size_t traced = 0;            ///< characteristics traced (= vertices)
  std::size_t hit_boundary = 0;      ///< stopped on the boundary of an open surface
  std::size_t substeps = 0;          ///< total sub-steps over all vertices
  std::size_t lost = 0;              ///< characteristics that failed (must stay 0): a walk that
                                     ///< stalled, or a trace that reached its bound of sub-steps
  /// Band calls: reached a face where V is not known and stopped there (a characteristic running
  /// away from the front, whose sign the stop does not change).
  std::size_t outside_band = 0;
};

/// Solve ∂φ/∂t + V·∇_S φ = 0 on (0, T), V given at the vertices (projected on the tangent plane
/// where evaluated). Returns φ(T) at the vertices. Deterministic for any thread count. Every trace
/// is bounded: by the sub-steps its speed needs on the smallest face (and so is the call, by
/// AdvectionOptions::max_substeps, checked before tracing); V must be finite.
ScalarField advect(const SurfaceMesh& mesh, const ScalarField& phi, const VectorField& velocity, double T,
                   const AdvectionOptions& options = {}, AdvectionReport* report = nullptr);

/// Advections on one fixed mesh: its flat walking arrays are built once, so repeated calls (the
/// CFL sub-steps of a step) pay only for V and the traces; a band call traces only some vertices,
/// so its cost follows the band, not the mesh. The mesh must outlive the Advector, unchanged.
class Advector {
 public:
  explicit Advector(const SurfaceMesh& mesh);
  /// Only the faces `faces` (mesh indices), for band calls whose `known` vertices have all their
  /// faces among them: its cost follows the band, not the mesh, and its values are the whole
  /// mesh's band call's, bit for bit (its faces are stored in the same order). A trace reaching a
  /// face that is not built has left the band (AdvectionReport::outside_band). advect() refuses.
  Advector(const SurfaceMesh& mesh, std::span<const int> faces);
  ~Advector();
  Advector(Advector&&) noexcept;

  /// As advect(): φ(T) at every vertex.
  ScalarField advect(const ScalarField& phi, const VectorField& velocity, double T, const AdvectionOptions& options = {},
                     AdvectionReport* report = nullptr);
  /// Narrow band: φ(T) at the vertices `traced` only, written into `out` (its other values are left
  /// as they are). V (and φ's gradient) is read only on the faces whose three corners are in
  /// `known`, which should hold the faces the characteristics cross (`traced` plus the reach
  /// T·max|V| and a face); a trace leaving it stops at its edge (report->outside_band).
  void advect_band(const ScalarField& phi, const VectorField& velocity, double T, std::span<const int> traced,
                   std::span<const int> known, ScalarField& out, const AdvectionOptions& options = {},
                   AdvectionReport* report = nullptr);

  /// Composed sub-steps (EvolutionOptions::compose_substeps): the band calls that follow continue
  /// each vertex's characteristic back to the start of the step, where φ is `phi0`, and give φ0 at
  /// the composed foot; the foot map is interpolated every call instead of φ. φ interpolated at
  /// every sub-step's foot makes an O(h²) error each time, which adds up with the sub-steps; the
  /// foot map is smooth, so composing feet does not (docs/validation/advection.md, "Sub-steps that converge").
  void start_composition(const ScalarField& phi0);
  /// As advect_band, with the characteristics composed since start_composition. `phi` (the current
  /// φ, a distance near its zero set) places the feet of the vertices that no previous call traced
  /// (walking from them along −∇φ0 to where φ0 = φ) and gives the value where feet cannot be
  /// composed: the trace left the band, a corner of the foot's face has no foot, or the corners'
  /// feet spread far apart (characteristics that meet, as merging fronts do).
  void advect_band_composed(const ScalarField& phi, const VectorField& velocity, double T, std::span<const int> traced,
                            std::span<const int> known, ScalarField& out, const AdvectionOptions& options = {},
                            AdvectionReport* report = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The Hamilton–Jacobi form (3.3): V = v ∇_S φ/|∇_S φ| (per-face gradients of φ averaged to the
/// vertices, area-weighted), then advect().
ScalarField advect_normal(const SurfaceMesh& mesh, const ScalarField& phi, const ScalarField& normal_speed,
                          double T, const AdvectionOptions& options = {}, AdvectionReport* report = nullptr);

}  // namespace bodyfit
