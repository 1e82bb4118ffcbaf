// Geodesic sphere: each face of an icosahedron is subdivided into k² triangles and the points are
// mapped to the sphere. The lattice is laid out along great-circle arcs (slerp between edge
// points) rather than linearly in the flat face, which keeps the triangles near-equilateral.
#include <bodyfit/generators.hpp>
#include <bodyfit/error.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

namespace bodyfit {
namespace {

Vec3 slerp(const Vec3& a, const Vec3& b, double t) {
  double omega = std::acos(std::clamp(OpenMesh::dot(a, b), -1.0, 1.0));
  if (omega < 1e-15) return a;
  double s = std::sin(omega);
  return (std::sin((1 - t) * omega) / s) * a + (std::sin(t * omega) / s) * b;
}

// Point (i, j) of the k-lattice on the spherical triangle (a, b, c): i steps toward b, j toward c.
Vec3 lattice_point(const Vec3& a, const Vec3& b, const Vec3& c, int k, int i, int j) {
  if (i + j == 0) return a;
  int row = i + j;
  Vec3 p = slerp(a, b, double(row) / k);
  Vec3 q = slerp(a, c, double(row) / k);
  Vec3 x = slerp(p, q, double(j) / row);
  return x.normalized();
}

}  // namespace

SurfaceMesh make_sphere(const SphereOptions& options) {
  if (options.faces < 20) throw InputError("sphere: --faces must be at least 20");
  if (!(options.radius > 0)) throw InputError("sphere: --radius must be positive");
  const int k = std::max(1, int(std::lround(std::sqrt(double(options.faces) / 20.0))));

  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> ico = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                           {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : ico) p.normalize();
  const int tris[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                           {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                           {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                           {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};

  SurfaceMesh mesh;
  // Shared points (icosahedron vertices and edge points) are keyed by the icosahedron edge they
  // lie on, so neighbouring faces reuse the same vertex.
  std::map<std::tuple<int, int, int>, VertexHandle> shared;
  auto key_of = [&](const int f[3], int i, int j) -> std::tuple<int, int, int> {
    int l = k - i - j;  // weights (l, i, j) on (a, b, c)
    int w[3] = {l, i, j};
    int nz = (w[0] > 0) + (w[1] > 0) + (w[2] > 0);
    if (nz == 3) return {-1, -1, -1};
    if (nz == 1) {
      int m = w[0] ? 0 : w[1] ? 1 : 2;
      return {f[m], -1, 0};
    }
    int m0 = -1, m1 = -1;
    for (int m = 0; m < 3; ++m)
      if (w[m] > 0) (m0 < 0 ? m0 : m1) = m;
    int v0 = f[m0], v1 = f[m1], s = w[m1];
    if (v0 > v1) {
      std::swap(v0, v1);
      s = k - s;
    }
    return {v0, v1, s};
  };

  for (const auto& f : tris) {
    const Vec3 &a = ico[f[0]], &b = ico[f[1]], &c = ico[f[2]];
    std::vector<std::vector<VertexHandle>> grid(k + 1);
    for (int i = 0; i <= k; ++i) {
      grid[i].resize(k + 1 - i);
      for (int j = 0; i + j <= k; ++j) {
        auto key = key_of(f, i, j);
        if (std::get<0>(key) >= 0) {
          auto it = shared.find(key);
          if (it != shared.end()) {
            grid[i][j] = it->second;
            continue;
          }
        }
        auto v = mesh.add_vertex(options.center + options.radius * lattice_point(a, b, c, k, i, j));
        if (std::get<0>(key) >= 0) shared[key] = v;
        grid[i][j] = v;
      }
    }
    for (int i = 0; i < k; ++i)
      for (int j = 0; i + j < k; ++j) {
        mesh.add_face(grid[i][j], grid[i + 1][j], grid[i][j + 1]);
        if (i + j + 1 < k) mesh.add_face(grid[i + 1][j], grid[i + 1][j + 1], grid[i][j + 1]);
      }
  }
  for (auto f : mesh.faces()) mesh.region(f) = kOutside;
  return mesh;
}

}  // namespace bodyfit
