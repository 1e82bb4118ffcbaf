#pragma once
// Surfaces the thermal model's tests share: a box gridded on its faces, a unit sphere, and a cube
// whose region G is a disk on its top face with the exact signed distance to that disk.
#include <bodyfit/generators.hpp>
#include <bodyfit/mesh.hpp>

#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace bodyfit::test {

/// The surface of the box [lo, hi] on an n×n grid per face (diagonals alternating), outward, all
/// faces outside G. Appended to `mesh` (a separate component) when given.
inline SurfaceMesh make_box(int n, Vec3 lo, Vec3 hi, SurfaceMesh mesh = {}) {
  std::map<std::array<int, 3>, VertexHandle> lattice;
  auto vertex = [&](std::array<int, 3> ijk) {
    auto it = lattice.find(ijk);
    if (it != lattice.end()) return it->second;
    Vec3 p;
    for (int k = 0; k < 3; ++k) p[k] = lo[k] + (hi[k] - lo[k]) * ijk[std::size_t(k)] / n;
    return lattice[ijk] = mesh.add_vertex(p);
  };
  for (int a = 0; a < 3; ++a)
    for (int side : {0, n}) {
      int b = (a + 1) % 3, c = (a + 2) % 3;
      auto at = [&](int u, int v) {
        std::array<int, 3> ijk{};
        ijk[std::size_t(a)] = side, ijk[std::size_t(b)] = u, ijk[std::size_t(c)] = v;
        return vertex(ijk);
      };
      for (int u = 0; u < n; ++u)
        for (int v = 0; v < n; ++v) {
          // (u,v) → (u+1,v) → (u+1,v+1) turns counterclockwise seen from +e_a (e_b × e_c = e_a).
          VertexHandle q[4] = {at(u, v), at(u + 1, v), at(u + 1, v + 1), at(u, v + 1)};
          std::array<std::array<int, 3>, 2> tris = (u + v) % 2 ? std::array<std::array<int, 3>, 2>{{{0, 1, 2}, {0, 2, 3}}}
                                                                : std::array<std::array<int, 3>, 2>{{{0, 1, 3}, {1, 2, 3}}};
          for (auto t : tris) {
            if (side == 0) std::swap(t[1], t[2]);
            auto f = mesh.add_face(q[t[0]], q[t[1]], q[t[2]]);
            mesh.region(f) = kOutside;
          }
        }
    }
  return mesh;
}

/// The unit sphere with `faces` faces, all outside G.
inline SurfaceMesh unit_sphere(std::size_t faces) {
  auto s = make_sphere({.faces = faces});
  for (auto f : s.faces()) s.region(f) = kOutside;
  return s;
}

/// Cube [−1,1]³ (16 cells a side) whose region G is the disk of radius R on the face z = 1, away
/// from the edges, so that d = r − R on that face and ≥ ε everywhere else (h_ε = 0 there: any value
/// ≥ ε will do).
struct DiskOnCube {
  SurfaceMesh surface;
  double R;
  explicit DiskOnCube(double radius) : surface(make_box(16, {-1, -1, -1}, {1, 1, 1})), R(radius) {
    for (auto f : surface.faces()) {
      const auto fv = surface.fv_range(f);
      std::vector<Vec3> p;
      for (auto v : fv) p.push_back(surface.point(v));
      const Vec3 centroid = (p[0] + p[1] + p[2]) / 3;
      const bool top = p[0][2] == 1 && p[1][2] == 1 && p[2][2] == 1;
      surface.region(f) = top && std::hypot(centroid[0], centroid[1]) < R ? kInside : kOutside;
    }
  }
  /// d for a disk of radius `radius` centred at (cx, 0, 1) (the labels stay those of R).
  std::vector<double> distance(double radius, double cx = 0) const {
    std::vector<double> d(surface.n_vertices());
    for (auto vh : surface.vertices()) {
      const Vec3& p = surface.point(vh);
      d[std::size_t(vh.idx())] = p[2] == 1 ? std::hypot(p[0] - cx, p[1]) - radius : 10.0;
    }
    return d;
  }
};

}  // namespace bodyfit::test
