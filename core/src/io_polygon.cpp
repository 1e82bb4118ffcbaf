// Polygons as triangles (io_polygon.hpp): ear clipping.
#include "io_polygon.hpp"

#include <algorithm>
#include <cmath>

namespace bodyfit::io_detail {
namespace {

struct Point2 {
  double x, y;
};

double cross(const Point2& a, const Point2& b, const Point2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

/// Whether p lies inside or on the triangle (a, b, c) turning counterclockwise.
bool inside_or_on(const Point2& p, const Point2& a, const Point2& b, const Point2& c, double tolerance) {
  return cross(a, b, p) >= -tolerance && cross(b, c, p) >= -tolerance && cross(c, a, p) >= -tolerance;
}

}  // namespace

std::vector<std::array<int, 3>> triangulate_polygon(std::span<const Vec3> corners) {
  const int n = int(corners.size());
  if (n < 3) return {};
  Vec3 normal(0, 0, 0);  // Newell's: twice the area vector of the outline
  double size = 0;
  for (int i = 0; i < n; ++i) {
    const Vec3 &a = corners[std::size_t(i)], &b = corners[std::size_t((i + 1) % n)];
    normal += Vec3(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]);
    size = std::max(size, (b - a).norm());
  }
  const double area2 = normal.norm();
  if (!(area2 > 1e-12 * size * size)) return {};
  // Drop the normal's largest axis; the others, ordered so the outline turns counterclockwise.
  int k = 0;
  for (int a = 1; a < 3; ++a)
    if (std::abs(normal[a]) > std::abs(normal[k])) k = a;
  int u = (k + 1) % 3, v = (k + 2) % 3;
  if (normal[k] < 0) std::swap(u, v);
  std::vector<Point2> p(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) p[std::size_t(i)] = {corners[std::size_t(i)][u], corners[std::size_t(i)][v]};
  const double tolerance = 1e-12 * size * size;

  std::vector<int> ring(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) ring[std::size_t(i)] = i;
  std::vector<std::array<int, 3>> triangles;
  double clipped = 0;  // twice the area of the triangles, in the plane
  while (ring.size() > 3) {
    const std::size_t m = ring.size();
    bool found = false;
    for (std::size_t i = 0; i < m && !found; ++i) {
      const int a = ring[(i + m - 1) % m], b = ring[i], c = ring[(i + 1) % m];
      const double turn = cross(p[std::size_t(a)], p[std::size_t(b)], p[std::size_t(c)]);
      if (turn <= tolerance) continue;  // reflex or flat: not an ear
      bool empty = true;
      for (int q : ring)
        if (q != a && q != b && q != c &&
            inside_or_on(p[std::size_t(q)], p[std::size_t(a)], p[std::size_t(b)], p[std::size_t(c)], tolerance)) {
          empty = false;
          break;
        }
      if (!empty) continue;
      triangles.push_back({a, b, c});
      clipped += turn;
      ring.erase(ring.begin() + std::ptrdiff_t(i));
      found = true;
    }
    if (!found) return {};  // no ear: the outline crosses itself
  }
  const double last = cross(p[std::size_t(ring[0])], p[std::size_t(ring[1])], p[std::size_t(ring[2])]);
  if (last <= tolerance) return {};
  triangles.push_back({ring[0], ring[1], ring[2]});
  clipped += last;
  // A simple outline is covered exactly once; one that winds twice or crosses itself is not.
  const double outline = std::abs(normal[k]);
  if (std::abs(clipped - outline) > 1e-9 * std::max(outline, size * size)) return {};
  return triangles;
}

}  // namespace bodyfit::io_detail
