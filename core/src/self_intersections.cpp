// Pairs of triangles of a surface that intersect (self_intersections.hpp).
#include <bodyfit/self_intersections.hpp>

#include <bodyfit/geometry.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace bodyfit {

namespace {

struct Triangle {
  std::array<int, 3> v;
  std::array<Vec3, 3> p;
  Vec3 lo, hi;  // bounding box, inflated by the tolerance
  Vec3 normal;  // unit
};

double orient(const Vec3& n, const Vec3& a, const Vec3& x) { return OpenMesh::dot(n, x - a); }

/// Does the segment [p, q] meet the triangle t (closed: touching counts)? `tol` is a distance.
bool segment_meets_triangle(const Vec3& p, const Vec3& q, const Triangle& t, double tol) {
  double dp = orient(t.normal, t.p[0], p), dq = orient(t.normal, t.p[0], q);
  if ((dp > tol && dq > tol) || (dp < -tol && dq < -tol)) return false;
  if (std::abs(dp) <= tol && std::abs(dq) <= tol) return false;  // coplanar: the caller's 2d test
  // The point of the segment on the plane (clamped when one end is within the tolerance).
  double s = std::abs(dp - dq) > 0 ? std::clamp(dp / (dp - dq), 0.0, 1.0) : 0.0;
  Vec3 x = p + (q - p) * s;
  // Inside the triangle, edges included: the three edge-normal tests in the plane.
  for (int i = 0; i < 3; ++i) {
    const Vec3& a = t.p[i];
    const Vec3& b = t.p[(i + 1) % 3];
    Vec3 edge = b - a;
    double len = edge.norm();
    if (len == 0) return false;
    double side = OpenMesh::dot(OpenMesh::cross(edge, x - a), t.normal) / len;  // signed distance to the edge line
    if (side < -tol) return false;
  }
  return true;
}

/// Are two triangles of one plane overlapping with positive area or crossing edges? Projected on the
/// coordinate plane most orthogonal to the normal.
bool coplanar_overlap(const Triangle& a, const Triangle& b, double tol) {
  int drop = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(a.normal[i]) > std::abs(a.normal[drop])) drop = i;
  int ax = (drop + 1) % 3, ay = (drop + 2) % 3;
  auto pt = [&](const Vec3& p) { return std::array<double, 2>{p[ax], p[ay]}; };
  auto cross2 = [](std::array<double, 2> o, std::array<double, 2> a, std::array<double, 2> b) {
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
  };
  std::array<std::array<double, 2>, 3> A, B;
  for (int i = 0; i < 3; ++i) A[i] = pt(a.p[i]), B[i] = pt(b.p[i]);
  // Proper crossing of two edges.
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      auto p = A[i], q = A[(i + 1) % 3], r = B[j], s = B[(j + 1) % 3];
      double scale = tol * (std::hypot(q[0] - p[0], q[1] - p[1]) + std::hypot(s[0] - r[0], s[1] - r[1]));
      double d1 = cross2(p, q, r), d2 = cross2(p, q, s), d3 = cross2(r, s, p), d4 = cross2(r, s, q);
      if (((d1 > scale && d2 < -scale) || (d1 < -scale && d2 > scale)) &&
          ((d3 > scale && d4 < -scale) || (d3 < -scale && d4 > scale)))
        return true;
    }
  // One triangle inside the other: a vertex strictly inside.
  auto inside = [&](const std::array<std::array<double, 2>, 3>& T, std::array<double, 2> x) {
    double area = cross2(T[0], T[1], T[2]);
    double sign = area > 0 ? 1 : -1;
    for (int i = 0; i < 3; ++i)
      if (sign * cross2(T[i], T[(i + 1) % 3], x) <= tol * tol) return false;
    return true;
  };
  for (int i = 0; i < 3; ++i)
    if (inside(B, A[i]) || inside(A, B[i])) return true;
  return false;
}

/// Two triangles with no common vertex.
bool disjoint_pair_intersects(const Triangle& a, const Triangle& b, double tol) {
  bool coplanar = true;
  for (int i = 0; i < 3; ++i)
    if (std::abs(orient(b.normal, b.p[0], a.p[i])) > tol || std::abs(orient(a.normal, a.p[0], b.p[i])) > tol)
      coplanar = false;
  if (coplanar) return coplanar_overlap(a, b, tol);
  // Two non-coplanar triangles meet iff an edge of one meets the other.
  for (int i = 0; i < 3; ++i) {
    if (segment_meets_triangle(a.p[i], a.p[(i + 1) % 3], b, tol)) return true;
    if (segment_meets_triangle(b.p[i], b.p[(i + 1) % 3], a, tol)) return true;
  }
  return false;
}

/// Two triangles sharing exactly the vertex a.v[ia] = b.v[ib]. Not coplanar: their planes meet in a
/// line through the vertex, which each triangle cuts in a segment from it; the segments overlap
/// beyond the vertex iff the shorter one ends (on its triangle's opposite edge) inside the other
/// triangle. Coplanar: they overlap iff their angular sectors at the vertex do.
bool vertex_pair_intersects(const Triangle& a, int ia, const Triangle& b, int ib, double tol) {
  const Vec3& a1 = a.p[(ia + 1) % 3];
  const Vec3& a2 = a.p[(ia + 2) % 3];
  const Vec3& b1 = b.p[(ib + 1) % 3];
  const Vec3& b2 = b.p[(ib + 2) % 3];
  bool coplanar = std::abs(orient(b.normal, b.p[0], a1)) <= tol && std::abs(orient(b.normal, b.p[0], a2)) <= tol &&
                  std::abs(orient(a.normal, a.p[0], b1)) <= tol && std::abs(orient(a.normal, a.p[0], b2)) <= tol;
  if (!coplanar) return segment_meets_triangle(a1, a2, b, tol) || segment_meets_triangle(b1, b2, a, tol);
  const Vec3& v = a.p[ia];
  const Vec3& n = a.normal;
  auto s = [&](const Vec3& x, const Vec3& y) { return OpenMesh::dot(OpenMesh::cross(x, y), n); };
  // u strictly inside the sector spanned by x, y (less than π): on the inner side of both rays.
  auto strictly_inside = [&](const Vec3& x, const Vec3& y, const Vec3& u) {
    double span = s(x, y);
    double sign = span > 0 ? 1 : -1;
    double eps = 1e-12 * u.norm();
    return sign * s(x, u) > eps * x.norm() && sign * s(u, y) > eps * y.norm();
  };
  auto same_ray = [&](const Vec3& x, const Vec3& y) {
    return std::abs(s(x, y)) <= 1e-12 * x.norm() * y.norm() && OpenMesh::dot(x, y) > 0;
  };
  Vec3 x1 = a1 - v, y1 = a2 - v, x2 = b1 - v, y2 = b2 - v;
  return strictly_inside(x1, y1, x2) || strictly_inside(x1, y1, y2) || strictly_inside(x2, y2, x1) ||
         strictly_inside(x2, y2, y1) || same_ray(x1, x2) || same_ray(x1, y2) || same_ray(y1, x2) ||
         same_ray(y1, y2);
}

/// Two triangles sharing an edge (consistently oriented): they meet beyond it only when folded flat
/// onto each other, i.e. with opposite normals.
bool edge_pair_intersects(const Triangle& a, const Triangle& b) {
  return OpenMesh::dot(a.normal, b.normal) < -1 + 1e-12;
}

bool pair_intersects(const Triangle& a, const Triangle& b, double tol) {
  int shared = 0, ia = -1, ib = -1;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (a.v[i] == b.v[j]) ++shared, ia = i, ib = j;
  if (shared == 0) return disjoint_pair_intersects(a, b, tol);
  if (shared == 1) return vertex_pair_intersects(a, ia, b, ib, tol);
  if (shared == 2) return edge_pair_intersects(a, b);
  return true;  // the same three vertices twice
}

std::uint64_t cell_key(std::int64_t i, std::int64_t j, std::int64_t k) {
  // 21 bits per axis: plenty for the cell counts below (at most ~2·10⁶ cells per axis never happens).
  auto u = [](std::int64_t x) { return std::uint64_t(x + (1 << 20)) & 0x1FFFFF; };
  return (u(i) << 42) | (u(j) << 21) | u(k);
}

}  // namespace

namespace {

/// The crossing pairs, all of them (near == nullptr) or those with a face flagged in `near` (by face
/// index): the other faces then enter only the grid cells the flagged ones occupy.
std::vector<std::pair<int, int>> find_crossings(const SurfaceMesh& surface, const std::vector<char>* near,
                                                std::size_t limit) {
  std::vector<std::pair<int, int>> found;
  if (surface.n_faces() < 2 || limit == 0) return found;
  auto box = bounding_box(surface);
  double diagonal = (box.max - box.min).norm();
  double tol = 1e-10 * diagonal;

  std::vector<Triangle> tris;
  std::vector<int> face_of;  // the face index of each triangle (deleted faces are skipped)
  std::vector<char> flagged;  // the triangle's face is one of `near`
  tris.reserve(surface.n_faces());
  double edge_sum = 0;
  for (auto f : surface.faces()) {
    Triangle t;
    auto vs = face_vertices(surface, f);
    for (int i = 0; i < 3; ++i) t.v[i] = vs[i].idx(), t.p[i] = surface.point(vs[i]);
    Vec3 n = OpenMesh::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
    double len = n.norm();
    t.normal = len > 0 ? n / len : Vec3(0, 0, 0);
    t.lo = t.hi = t.p[0];
    for (int i = 1; i < 3; ++i) t.lo.minimize(t.p[i]), t.hi.maximize(t.p[i]);
    t.lo -= Vec3(tol, tol, tol);
    t.hi += Vec3(tol, tol, tol);
    edge_sum += (t.p[1] - t.p[0]).norm() + (t.p[2] - t.p[1]).norm() + (t.p[0] - t.p[2]).norm();
    tris.push_back(t);
    face_of.push_back(f.idx());
    flagged.push_back(!near || (std::size_t(f.idx()) < near->size() && (*near)[std::size_t(f.idx())]));
  }
  // A uniform grid of cells about twice the mean edge: a few triangles per cell on a well-spread
  // mesh. Each pair is tested once, in the cell holding the lower corner of their boxes' overlap.
  double cell = std::max(2 * edge_sum / (3.0 * double(tris.size())), diagonal * 1e-6);
  auto index = [&](double x, double origin) { return std::int64_t(std::floor((x - origin) / cell)); };
  std::unordered_map<std::uint64_t, std::vector<int>> grid;
  grid.reserve(tris.size() * 2);
  // The flagged triangles first; then the others, into the cells the flagged ones occupy only.
  for (int pass = 0; pass < 2; ++pass)
    for (int f = 0; f < int(tris.size()); ++f) {
      if (bool(flagged[std::size_t(f)]) != (pass == 0)) continue;
      const auto& t = tris[std::size_t(f)];
      for (auto i = index(t.lo[0], box.min[0]); i <= index(t.hi[0], box.min[0]); ++i)
        for (auto j = index(t.lo[1], box.min[1]); j <= index(t.hi[1], box.min[1]); ++j)
          for (auto k = index(t.lo[2], box.min[2]); k <= index(t.hi[2], box.min[2]); ++k) {
            if (pass == 0) {
              grid[cell_key(i, j, k)].push_back(f);
            } else if (auto it = grid.find(cell_key(i, j, k)); it != grid.end()) {
              it->second.push_back(f);
            }
          }
    }
  for (const auto& [key, members] : grid) {
    for (std::size_t m = 0; m < members.size(); ++m)
      for (std::size_t n = m + 1; n < members.size(); ++n) {
        if (!flagged[std::size_t(members[m])] && !flagged[std::size_t(members[n])]) continue;
        const auto& a = tris[std::size_t(members[m])];
        const auto& b = tris[std::size_t(members[n])];
        Vec3 lo = a.lo, hi = a.hi;
        lo.maximize(b.lo);
        hi.minimize(b.hi);
        if (lo[0] > hi[0] || lo[1] > hi[1] || lo[2] > hi[2]) continue;
        if (cell_key(index(lo[0], box.min[0]), index(lo[1], box.min[1]), index(lo[2], box.min[2])) != key) continue;
        if (pair_intersects(a, b, tol)) {
          const int f = face_of[std::size_t(members[m])], g = face_of[std::size_t(members[n])];
          found.emplace_back(std::min(f, g), std::max(f, g));
          if (found.size() >= limit) {
            std::sort(found.begin(), found.end());
            return found;
          }
        }
      }
  }
  std::sort(found.begin(), found.end());
  return found;
}

}  // namespace

std::vector<std::pair<int, int>> self_intersections(const SurfaceMesh& surface, std::size_t limit) {
  return find_crossings(surface, nullptr, limit);
}

std::vector<std::pair<int, int>> self_intersections_near(const SurfaceMesh& surface, std::span<const int> faces,
                                                         std::size_t limit) {
  std::vector<char> near(surface.n_faces(), 0);
  for (int f : faces)
    if (f >= 0 && std::size_t(f) < near.size()) near[std::size_t(f)] = 1;
  return find_crossings(surface, &near, limit);
}

}  // namespace bodyfit
