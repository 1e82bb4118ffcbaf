#pragma once
// The smoothed problem on one volume mesh for the whole run. S does not move, only G does, and the
// smoothed problem sees G through d_G alone: so Ω is tetrahedralised once, from a surface mesh S⁰
// of S, its stiffness, loads and symbolic factorisation are kept, and each state's d_G is carried
// from the state's own mesh T^n to S⁰'s vertices (surface_transfer.hpp). Only the sharp problem,
// whose u = 0 needs Σ in the mesh, is tetrahedralised anew.
#include "surface_transfer.hpp"
#include "thermal_fem.hpp"
#include "volume_mesh.hpp"

#include <bodyfit/mesh.hpp>
#include <bodyfit/projection.hpp>

#include <functional>
#include <memory>
#include <vector>

namespace bodyfit::thermal {

class FixedVolume {
 public:
  /// Tetrahedralises `surface` (S⁰: a garbage-collected mesh of S) and sets up the solver for
  /// `problem` (its robin_field is ignored: each solve gives its own).
  FixedVolume(SurfaceMesh surface, const TetrahedralizeOptions& tetgen, ThermalProblem problem,
              const ThermalOptions& options);

  const SurfaceMesh& surface() const { return surface_; }
  const VolumeMesh& volume() const { return volume_; }
  const std::vector<Vec3>& points() const { return points_; }
  double ms_tetrahedralize() const { return ms_tetrahedralize_; }

  /// A P1 field of `mesh` (another mesh of S) at S⁰'s vertices.
  std::vector<double> carry(const SurfaceMesh& mesh, const std::vector<double>& field) const;
  /// Where `mesh`'s vertices lie on S⁰ (to bring fields of S⁰ back with interpolate()).
  SurfaceLocations locate_vertices_of(const SurfaceMesh& mesh) const;
  ThermalSolver& solver() { return *solver_; }
  const ThermalSolver& solver() const { return *solver_; }
  /// κ as a function of d (a new ε).
  void set_robin_coefficient(std::function<double(double)> coefficient) { solver_->set_robin_coefficient(std::move(coefficient)); }
  /// The smoothed problem with the Robin field `field_on_s0` (d_G at S⁰'s vertices).
  ThermalSolution solve(const std::vector<double>& field_on_s0);

 private:
  SurfaceMesh surface_;
  std::vector<Vec3> points_;
  VolumeMesh volume_;
  double ms_tetrahedralize_ = 0;
  std::unique_ptr<ReferenceSurface> reference_;  ///< of S⁰
  std::unique_ptr<ThermalSolver> solver_;        ///< points to volume_: the object does not move
};

}  // namespace bodyfit::thermal
