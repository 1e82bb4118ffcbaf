// Temporary: returns the mesh unchanged (valid), replaced by the full remesher shortly.
#include <bodyfit/remesh.hpp>
#include <bodyfit/geometry.hpp>

#include <chrono>

namespace bodyfit {

RemeshReport remesh(SurfaceMesh& mesh, const RemeshOptions&) {
  auto start = std::chrono::steady_clock::now();
  mesh.garbage_collection();
  RemeshReport report;
  auto q = quality_stats(mesh);
  report.min_quality = q.min;
  report.mean_quality = q.mean;
  report.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace bodyfit
