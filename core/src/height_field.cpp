// Whether a surface is a height field over a plane (height_field.hpp).
#include <bodyfit/height_field.hpp>

#include <bodyfit/geometry.hpp>
#include <bodyfit/projection.hpp>

#include "blocks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace bodyfit {
namespace {

constexpr double kFacing = 0.1;        // cos 84°: a face steeper than that is not trusted to face d
constexpr double kTouching = 1e-9;     // of the shadow's size: closer than that counts as touching

// The boundary's shadow: points of the plane as Vec3 with z = 0, so that the segment helpers of
// the projection serve.
double cross2(const Vec3& o, const Vec3& a, const Vec3& b) { return ((a - o) % (b - o))[2]; }

double distance_to_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  return (closest_point_on_segment(p, a, b) - p).norm();
}

/// Whether the segments ab and cd cross or come within `tol` of each other.
bool segments_meet(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, double tol) {
  const double o1 = cross2(a, b, c), o2 = cross2(a, b, d), o3 = cross2(c, d, a), o4 = cross2(c, d, b);
  if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0))) return true;
  return distance_to_segment(c, a, b) <= tol || distance_to_segment(d, a, b) <= tol ||
         distance_to_segment(a, c, d) <= tol || distance_to_segment(b, c, d) <= tol;
}

/// Whether the closed polygon is simple: no two sides meet but neighbours at their common corner
/// (and those do not fold back onto each other). Sides are paired through a grid of cells about a
/// side long; false also when that grid would be too large to tell (sides of very unequal lengths).
bool is_simple_polygon(const std::vector<Vec3>& corners) {
  const std::size_t n = corners.size();
  if (n < 3) return false;
  Vec3 lo = corners[0], hi = corners[0];
  double perimeter = 0;
  for (std::size_t i = 0; i < n; ++i) {
    lo.minimize(corners[i]);
    hi.maximize(corners[i]);
    perimeter += (corners[(i + 1) % n] - corners[i]).norm();
  }
  const double tol = kTouching * (hi - lo).norm();
  if (!(tol > 0)) return false;
  auto side = [&](std::size_t i) { return std::pair{corners[i], corners[(i + 1) % n]}; };
  for (std::size_t i = 0; i < n; ++i) {  // neighbours: only their common corner
    const auto [a, b] = side(i);
    const Vec3& c = corners[(i + 2) % n];
    if (distance_to_segment(c, a, b) <= tol || distance_to_segment(a, b, c) <= tol) return false;
  }
  const double cell = std::max(perimeter / double(n), tol);
  auto index = [&](double x, double origin) { return std::int64_t(std::floor((x - origin) / cell)); };
  struct Cells {
    std::int64_t x0, x1, y0, y1;  // the side's box, in cells
  };
  auto cells_of = [&](std::size_t i) {
    const auto [a, b] = side(i);
    return Cells{index(std::min(a[0], b[0]) - tol, lo[0]), index(std::max(a[0], b[0]) + tol, lo[0]),
                 index(std::min(a[1], b[1]) - tol, lo[1]), index(std::max(a[1], b[1]) + tol, lo[1])};
  };
  // A side may cover many cells when the sides' lengths differ wildly: past a few per side on
  // average the grid is not worth making, and the answer is "cannot tell".
  double count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Cells c = cells_of(i);
    count += double(c.x1 - c.x0 + 1) * double(c.y1 - c.y0 + 1);
  }
  if (count > 64.0 * double(n)) return false;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> entries;  // (cell, side), sorted by cell
  entries.reserve(std::size_t(count));
  for (std::size_t i = 0; i < n; ++i) {
    const Cells c = cells_of(i);
    for (auto x = c.x0; x <= c.x1; ++x)
      for (auto y = c.y0; y <= c.y1; ++y)
        entries.emplace_back((std::uint64_t(x + 1) << 32) | std::uint64_t(y + 1), std::uint32_t(i));
  }
  std::sort(entries.begin(), entries.end());
  for (std::size_t first = 0; first < entries.size();) {
    std::size_t last = first;
    while (last < entries.size() && entries[last].first == entries[first].first) ++last;
    if (last - first > 256) return false;  // a crowd of tiny sides: not worth every pair
    for (std::size_t m = first; m < last; ++m)
      for (std::size_t k = m + 1; k < last; ++k) {
        const std::size_t i = entries[m].second, j = entries[k].second;
        if ((i + 1) % n == j || (j + 1) % n == i) continue;  // neighbours: checked above
        const auto [a, b] = side(i);
        const auto [c, d] = side(j);
        if (segments_meet(a, b, c, d, tol)) return false;
      }
    first = last;
  }
  return true;
}

}  // namespace

bool is_height_field(const SurfaceMesh& mesh) {
  const int nf = int(mesh.n_faces());
  auto twice_area_normal = [&](int f) {
    const auto [a, b, c] = face_points(mesh, FaceHandle(f));
    return Vec3((b - a) % (c - a));
  };
  auto live = [&](int f) { return !mesh.status(FaceHandle(f)).deleted(); };
  // d: the mean normal, summed by fixed blocks (the same for any number of threads). Faces that
  // all face d give |Σ n| = Σ n·d ≥ cos 84° Σ |n|: a closed surface (Σ n = 0) fails here.
  struct Sums {
    Vec3 normal{0, 0, 0};
    double area = 0;
  };
  const Sums sums = reduce(
      nf, Sums{},
      [&](int f, Sums& s) {
        if (!live(f)) return;
        const Vec3 n = twice_area_normal(f);
        s.normal += n;
        s.area += n.norm();
      },
      [](Sums& total, const Sums& part) {
        total.normal += part.normal;
        total.area += part.area;
      });
  const double length = sums.normal.norm();
  if (!(length > 0) || length < kFacing * sums.area) return false;
  const Vec3 d = sums.normal / length;
  const int turned_away = reduce(
      nf, 0,
      [&](int f, int& count) {
        if (count > 0 || !live(f)) return;
        const Vec3 n = twice_area_normal(f);
        const double len = n.norm();
        count += !(len > 0 && (n | d) >= kFacing * len);
      },
      [](int& total, int part) { total += part; });
  if (turned_away > 0) return false;

  // The boundary: one loop through every boundary vertex once.
  const std::vector<int> boundary = collect<int>(int(mesh.n_vertices()), [&](int v, int& item) {
    item = v;
    const VertexHandle vh(v);
    return !mesh.status(vh).deleted() && mesh.is_boundary(vh);
  });
  if (boundary.size() < 3) return false;
  const HalfedgeHandle start = mesh.halfedge_handle(VertexHandle(boundary.front()));
  if (!start.is_valid() || !mesh.is_boundary(start)) return false;  // an isolated vertex
  // Its shadow, in a frame (u, v) of the plane normal to d.
  const Vec3 u = (std::abs(d[0]) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0)) % d;
  const Vec3 e1 = u / u.norm(), e2 = d % e1;
  std::vector<Vec3> shadow;
  shadow.reserve(boundary.size());
  HalfedgeHandle h = start;
  do {
    if (shadow.size() == boundary.size()) return false;  // a vertex twice: not one simple loop
    const Vec3& p = mesh.point(mesh.from_vertex_handle(h));
    shadow.emplace_back(p | e1, p | e2, 0.0);
    h = mesh.next_halfedge_handle(h);
  } while (h != start);
  if (shadow.size() != boundary.size()) return false;  // more than one loop
  return is_simple_polygon(shadow);
}

}  // namespace bodyfit
