// A flat square: the open surface of the plane cases (a disk growing, an interface sliding along a
// boundary).
#include <bodyfit/generators.hpp>
#include <bodyfit/guards.hpp>
#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace bodyfit {
namespace {

// Beyond this the mesh would not fit in memory anyway, and the row counts
// below must stay far from int overflow.
constexpr double kMaxVertices = 2e7;

}  // namespace

SurfaceMesh make_plane(const PlaneOptions& options) {
  const double size = options.size, h = options.h;
  auto positive = [](double x) { return std::isfinite(x) && x > 0; };
  if (!positive(size)) throw InputError(fmt::format("plane: the size must be positive (got {})", size));
  if (!positive(h)) throw InputError(fmt::format("plane: the edge length h must be positive (got {})", h));
  const double row_height = h * std::sqrt(3.0) / 2;
  check_face_budget(2 * (size / h) * (size / row_height), fmt::format("plane of size {} and edge length {}", size, h));
  if ((size / h + 2) * (size / row_height + 1) > kMaxVertices)
    throw InputError(fmt::format("plane: size {} with h {} is too many vertices; use a larger h", size, h));

  SurfaceMesh mesh;
  const int rows = std::max(1, int(std::lround(size / row_height)));
  const int cols = std::max(1, int(std::lround(size / h)));
  const double dy = size / rows, dx = size / cols;
  std::vector<std::vector<VertexHandle>> grid(rows + 1);
  for (int r = 0; r <= rows; ++r) {
    // Odd rows are shifted by half a cell, their end points on the boundary: a half cell at the
    // left end, one and a half at the right (the plane cases' meshes depend on it: kept as is).
    const bool odd = r % 2 == 1;
    const double y = -size / 2 + r * dy;
    grid[r].push_back(mesh.add_vertex(Vec3(-size / 2, y, 0)));
    for (int c = 0; c < cols - (odd ? 1 : 0); ++c) {
      double x = -size / 2 + (c + (odd ? 0.5 : 1.0)) * dx;
      if (!odd && c == cols - 1) x = size / 2;
      grid[r].push_back(mesh.add_vertex(Vec3(x, y, 0)));
    }
    if (odd) grid[r].push_back(mesh.add_vertex(Vec3(size / 2, y, 0)));
  }
  // Every row holds cols+1 points; zig-zag between consecutive rows (2·cols triangles).
  for (int r = 0; r < rows; ++r) {
    const auto& a = grid[r];
    const auto& b = grid[r + 1];
    std::size_t i = 0, j = 0;
    while (i + 1 < a.size() || j + 1 < b.size()) {
      // Advance on the row whose next point is further behind.
      bool advance_a;
      if (i + 1 >= a.size()) advance_a = false;
      else if (j + 1 >= b.size()) advance_a = true;
      else advance_a = mesh.point(a[i + 1])[0] <= mesh.point(b[j + 1])[0];
      if (advance_a) {
        mesh.add_face(a[i], a[i + 1], b[j]);
        ++i;
      } else {
        mesh.add_face(a[i], b[j + 1], b[j]);
        ++j;
      }
    }
  }
  for (auto f : mesh.faces()) mesh.region(f) = kOutside;
  return mesh;
}

}  // namespace bodyfit
