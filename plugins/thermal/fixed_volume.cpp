#include "fixed_volume.hpp"

#include <chrono>

namespace bodyfit::thermal {

FixedVolume::FixedVolume(SurfaceMesh surface, const TetrahedralizeOptions& tetgen, ThermalProblem problem,
                         const ThermalOptions& options)
    : surface_(std::move(surface)), points_(vertex_points(surface_)) {
  const auto start = std::chrono::steady_clock::now();
  volume_ = tetrahedralize(surface_, tetgen);
  ms_tetrahedralize_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  reference_ = std::make_unique<ReferenceSurface>(surface_);
  problem.robin_field.assign(points_.size(), 0.0);
  solver_ = std::make_unique<ThermalSolver>(volume_, std::move(problem), options);
}

std::vector<double> FixedVolume::carry(const SurfaceMesh& mesh, const std::vector<double>& field) const {
  const ReferenceSurface reference(mesh);
  return interpolate(locate(mesh, reference, points_), field);
}

SurfaceLocations FixedVolume::locate_vertices_of(const SurfaceMesh& mesh) const {
  return locate(surface_, *reference_, vertex_points(mesh));
}

ThermalSolution FixedVolume::solve(const std::vector<double>& field_on_s0) { return solver_->solve(field_on_s0); }

}  // namespace bodyfit::thermal
