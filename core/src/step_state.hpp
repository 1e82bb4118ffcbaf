#pragma once
// The driver's side of StepContext: what a context is built from (private to the core).
#include <bodyfit/projection.hpp>
#include <bodyfit/velocity_model.hpp>

#include <filesystem>
#include <limits>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

namespace bodyfit {

/// Geometry shared by the contexts of one step on one mesh (the CFL sub-steps): computed once.
struct StepGeometry {
  std::mutex mutex;
  std::optional<VectorField> vertex_normals;
  /// S's normals, filled where a context of the step needed them (surface_known).
  VectorField surface_normals;
  std::vector<char> surface_known;
};

struct StepState {
  const SurfaceMesh* mesh = nullptr;      ///< T^n (garbage-collected)
  const ScalarField* distance = nullptr;  ///< d_{G^n} at the vertices
  /// d is a distance within this width of Σ and ± it beyond (EvolutionOptions::narrow_band).
  double distance_width = std::numeric_limits<double>::infinity();
  double time = 0, dt = 0;
  int iteration = 0;
  std::filesystem::path output_dir;
  bool height_field = false;              ///< S is a height field z(x, y)
  std::optional<double> clock_start;      ///< seconds since the epoch at t = 0 ([time] start)
  std::span<const int> active;            ///< narrow band: where V is needed (empty: every vertex)
  StepGeometry* geometry = nullptr;       ///< shared with the other contexts of the step (optional)
  const ReferenceSurface* surface = nullptr;  ///< the fixed input surface S (optional)
  /// Raised when the model asks for an operator that couples every vertex (mass, stiffness,
  /// smoothing): d must then be known on the whole surface (optional).
  bool* whole_surface_used = nullptr;
};

/// The context for one (sub-)step or candidate; `state`'s pointers must outlive it.
StepContext make_step_context(const StepState& state);

}  // namespace bodyfit
