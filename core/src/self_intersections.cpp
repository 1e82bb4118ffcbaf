// Pairs of triangles of a surface that intersect (self_intersections.hpp).
#include <bodyfit/self_intersections.hpp>

#include <bodyfit/geometry.hpp>

#include "blocks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

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
/// index): the other faces then enter only the grid cells the flagged ones occupy, and only those
/// that do are made into Triangles (a remesh checks the few thousand faces it changed, not the
/// whole surface: building a record per face was most of the cost).
std::vector<std::pair<int, int>> find_crossings(const SurfaceMesh& surface, const std::vector<char>* near,
                                                std::size_t limit) {
  std::vector<std::pair<int, int>> found;
  if (surface.n_faces() < 2 || limit == 0) return found;
  auto box = bounding_box(surface);
  double diagonal = (box.max - box.min).norm();
  double tol = 1e-10 * diagonal;
  const int nf = int(surface.n_faces());
  auto is_flagged = [&](int f) { return !near || (std::size_t(f) < near->size() && (*near)[std::size_t(f)]); };
  auto corners = [&](int f) {
    const auto vs = face_vertices(surface, FaceHandle(f));
    return std::array<Vec3, 3>{surface.point(vs[0]), surface.point(vs[1]), surface.point(vs[2])};
  };
  auto bounds = [&](const std::array<Vec3, 3>& p, Vec3& lo, Vec3& hi) {
    lo = hi = p[0];
    for (int i = 1; i < 3; ++i) lo.minimize(p[i]), hi.maximize(p[i]);
    lo -= Vec3(tol, tol, tol);
    hi += Vec3(tol, tol, tol);
  };
  // The cell: about twice the mean edge, a few triangles per cell on a well-spread mesh (summed in
  // fixed blocks: the same for any number of threads).
  constexpr int kBlock = 4096;
  const int blocks = (nf + kBlock - 1) / kBlock;
  std::vector<double> edge_sums(std::size_t(blocks), 0.0);
  std::vector<int> live_counts(std::size_t(blocks), 0);
  tbb::parallel_for(0, blocks, [&](int b) {
    for (int f = b * kBlock; f < std::min(nf, (b + 1) * kBlock); ++f) {
      if (surface.status(FaceHandle(f)).deleted()) continue;
      const auto p = corners(f);
      edge_sums[std::size_t(b)] += (p[1] - p[0]).norm() + (p[2] - p[1]).norm() + (p[0] - p[2]).norm();
      ++live_counts[std::size_t(b)];
    }
  });
  double edge_sum = 0;
  int live = 0;
  for (int b = 0; b < blocks; ++b) edge_sum += edge_sums[std::size_t(b)], live += live_counts[std::size_t(b)];
  if (live < 2) return found;
  const double cell = std::max(2 * edge_sum / (3.0 * double(live)), diagonal * 1e-6);
  auto index = [&](double x, double origin) { return std::int64_t(std::floor((x - origin) / cell)); };
  auto for_cell_indices = [&](const Vec3& lo, const Vec3& hi, auto&& visit) {
    for (auto i = index(lo[0], box.min[0]); i <= index(hi[0], box.min[0]); ++i)
      for (auto j = index(lo[1], box.min[1]); j <= index(hi[1], box.min[1]); ++j)
        for (auto k = index(lo[2], box.min[2]); k <= index(hi[2], box.min[2]); ++k) visit(i, j, k);
  };
  auto for_cells = [&](const Vec3& lo, const Vec3& hi, auto&& visit) {
    for_cell_indices(lo, hi, [&](std::int64_t i, std::int64_t j, std::int64_t k) { visit(cell_key(i, j, k)); });
  };

  // The faces searched: the flagged ones in face order, then (with `near`) the others that share a
  // grid cell with a flagged one, in face order; triangle i is faces[i].
  std::vector<int> faces = collect<int>(nf, [&](int f, int& item) {
    item = f;
    return !surface.status(FaceHandle(f)).deleted() && is_flagged(f);
  });
  const std::size_t n_flagged = faces.size();
  auto box_of = [&](int f, Vec3& lo, Vec3& hi) { bounds(corners(f), lo, hi); };
  // The cells the flagged triangles occupy, each with its triangles, as (cell, triangle) pairs:
  // made in parallel (a count per triangle, then its slots), sorted by cell then triangle.
  using Entry = std::pair<std::uint64_t, int>;
  auto cell_entries = [&](std::size_t first, std::size_t count, auto&& boxes, auto&& keep) {
    std::vector<std::size_t> offset(count + 1, 0);
    tbb::parallel_for(std::size_t(0), count, [&](std::size_t i) {
      Vec3 lo, hi;
      boxes(first + i, lo, hi);
      std::size_t n = 0;
      for_cells(lo, hi, [&](std::uint64_t key) { n += keep(key); });
      offset[i + 1] = n;
    });
    for (std::size_t i = 0; i < count; ++i) offset[i + 1] += offset[i];
    std::vector<Entry> entries(offset[count]);
    tbb::parallel_for(std::size_t(0), count, [&](std::size_t i) {
      Vec3 lo, hi;
      boxes(first + i, lo, hi);
      std::size_t at = offset[i];
      for_cells(lo, hi, [&](std::uint64_t key) {
        if (keep(key)) entries[at++] = {key, int(first + i)};
      });
    });
    return entries;
  };
  std::vector<Entry> grid = cell_entries(0, n_flagged, [&](std::size_t i, Vec3& lo, Vec3& hi) { box_of(faces[i], lo, hi); },
                                         [](std::uint64_t) { return true; });
  tbb::parallel_sort(grid.begin(), grid.end());
  if (near) {
    // The cells the flagged triangles occupy, as a table over the box's cells (one more on each
    // side for the tolerance) when it is small, else their sorted keys: the sweep below looks the
    // others' cells up in it.
    std::vector<std::uint64_t> flagged_cells(grid.size());
    for (std::size_t k = 0; k < grid.size(); ++k) flagged_cells[k] = grid[k].first;
    flagged_cells.erase(std::unique(flagged_cells.begin(), flagged_cells.end()), flagged_cells.end());
    auto is_flagged_cell = [&](std::uint64_t key) {
      return std::binary_search(flagged_cells.begin(), flagged_cells.end(), key);
    };
    const std::int64_t nx = index(box.max[0], box.min[0]) + 3, ny = index(box.max[1], box.min[1]) + 3,
                       nz = index(box.max[2], box.min[2]) + 3;
    auto in_table = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
      return i >= -1 && i < nx - 1 && j >= -1 && j < ny - 1 && k >= -1 && k < nz - 1;
    };
    auto cell_of = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
      return std::size_t((i + 1) + nx * ((j + 1) + ny * (k + 1)));
    };
    // The table is made from the flagged cells' keys, which name their cells unambiguously while
    // every index is within 21 bits (cell_key); a flagged cell outside it (not expected: every
    // triangle is in the box) leaves the keys.
    constexpr std::int64_t kKeyRange = (1 << 20) - 2;
    auto decode = [](std::uint64_t key, int shift) { return std::int64_t((key >> shift) & 0x1FFFFF) - (1 << 20); };
    auto key_in_table = [&](std::uint64_t key) { return in_table(decode(key, 42), decode(key, 21), decode(key, 0)); };
    const bool whole_table = nx > 0 && ny > 0 && nz > 0 && nx < kKeyRange && ny < kKeyRange && nz < kKeyRange &&
                             nx * ny * nz <= (std::int64_t(1) << 26) &&
                             std::all_of(flagged_cells.begin(), flagged_cells.end(), key_in_table);
    std::vector<char> occupied;
    auto occupied_at = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
      return in_table(i, j, k) && occupied[cell_of(i, j, k)];
    };
    if (whole_table) {
      occupied.assign(std::size_t(nx * ny * nz), 0);
      tbb::parallel_for(std::size_t(0), flagged_cells.size(), [&](std::size_t c) {
        const std::uint64_t key = flagged_cells[c];
        occupied[cell_of(decode(key, 42), decode(key, 21), decode(key, 0))] = 1;
      });
    }
    auto meets_flagged = [&](const Vec3& lo, const Vec3& hi) {
      bool meets = false;
      if (!whole_table) {
        for_cells(lo, hi, [&](std::uint64_t key) { meets = meets || is_flagged_cell(key); });
      } else {
        for_cell_indices(lo, hi, [&](std::int64_t i, std::int64_t j, std::int64_t k) {
          meets = meets || occupied_at(i, j, k);
        });
      }
      return meets;
    };
    const std::vector<int> meeting = collect<int>(nf, [&](int f, int& item) {
      item = f;
      if (surface.status(FaceHandle(f)).deleted() || is_flagged(f)) return false;
      Vec3 lo, hi;
      box_of(f, lo, hi);
      return meets_flagged(lo, hi);
    });
    faces.insert(faces.end(), meeting.begin(), meeting.end());
    // Their entries only in the cells that hold a flagged triangle: a pair of two others is not
    // looked at.
    std::vector<Entry> more = cell_entries(n_flagged, meeting.size(),
                                           [&](std::size_t i, Vec3& lo, Vec3& hi) { box_of(faces[i], lo, hi); },
                                           [&](std::uint64_t key) {
                                             return whole_table ? occupied_at(decode(key, 42), decode(key, 21), decode(key, 0))
                                                                : is_flagged_cell(key);
                                           });
    tbb::parallel_sort(more.begin(), more.end());
    const std::size_t before = grid.size();
    grid.insert(grid.end(), more.begin(), more.end());
    std::inplace_merge(grid.begin(), grid.begin() + std::ptrdiff_t(before), grid.end());
  }
  std::vector<Triangle> tris(faces.size());
  tbb::parallel_for(std::size_t(0), faces.size(), [&](std::size_t i) {
    Triangle& t = tris[i];
    const auto vs = face_vertices(surface, FaceHandle(faces[i]));
    for (int k = 0; k < 3; ++k) t.v[k] = vs[k].idx(), t.p[k] = surface.point(vs[k]);
    const Vec3 n = OpenMesh::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
    const double len = n.norm();
    t.normal = len > 0 ? n / len : Vec3(0, 0, 0);
    bounds(t.p, t.lo, t.hi);
  });
  const std::vector<int>& face_of = faces;
  auto flagged = [&](int id) { return std::size_t(id) < n_flagged; };
  // The cells: runs of one key in the sorted entries.
  std::vector<std::size_t> cell_start;
  for (std::size_t k = 0; k < grid.size(); ++k)
    if (k == 0 || grid[k].first != grid[k - 1].first) cell_start.push_back(k);
  cell_start.push_back(grid.size());
  const std::size_t n_cells = cell_start.size() - 1;
  // The pairs of cell c, into `out`; false once `out` holds `limit`. Each pair is tested once, in
  // the cell holding the lower corner of their boxes' overlap.
  auto test_cell = [&](std::size_t c, std::vector<std::pair<int, int>>& out) {
    const std::uint64_t key = grid[cell_start[c]].first;
    for (std::size_t m = cell_start[c]; m < cell_start[c + 1]; ++m)
      for (std::size_t n = m + 1; n < cell_start[c + 1]; ++n) {
        const int ia = grid[m].second, ib = grid[n].second;
        if (!flagged(ia) && !flagged(ib)) continue;
        const auto& a = tris[std::size_t(ia)];
        const auto& b = tris[std::size_t(ib)];
        Vec3 lo = a.lo, hi = a.hi;
        lo.maximize(b.lo);
        hi.minimize(b.hi);
        if (lo[0] > hi[0] || lo[1] > hi[1] || lo[2] > hi[2]) continue;
        if (cell_key(index(lo[0], box.min[0]), index(lo[1], box.min[1]), index(lo[2], box.min[2])) != key) continue;
        if (pair_intersects(a, b, tol)) {
          const int f = face_of[std::size_t(ia)], g = face_of[std::size_t(ib)];
          out.emplace_back(std::min(f, g), std::max(f, g));
          if (out.size() >= limit) return false;
        }
      }
    return true;
  };
  if (limit < std::numeric_limits<std::size_t>::max()) {  // stops at the limit: one cell after the other
    for (std::size_t c = 0; c < n_cells; ++c)
      if (!test_cell(c, found)) break;
  } else {  // every pair: the cells in parallel (the set found is the same in any order)
    tbb::enumerable_thread_specific<std::vector<std::pair<int, int>>> local;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n_cells, 256), [&](const auto& range) {
      auto& out = local.local();
      for (std::size_t c = range.begin(); c < range.end(); ++c) test_cell(c, out);
    });
    for (const auto& part : local) found.insert(found.end(), part.begin(), part.end());
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
