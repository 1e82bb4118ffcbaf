// A height field is recognised where it is one (a terrain, a tilted square, a shallow cap), and
// refused wherever the surface could fold over itself; on every surface recognised, the full search
// finds no crossing, and where a shadow overlaps itself it finds the crossings the test refused.
#include <doctest/doctest.h>

#include <bodyfit/app/terrain.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/height_field.hpp>
#include <bodyfit/remesh.hpp>
#include <bodyfit/self_intersections.hpp>

#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

using namespace bodyfit;

namespace {

/// The faces of `mesh` whose centroid passes `keep`, as a mesh of their own.
SurfaceMesh keep_faces(const SurfaceMesh& mesh, const std::function<bool(const Vec3&)>& keep) {
  SurfaceMesh out;
  std::vector<VertexHandle> copy(mesh.n_vertices());
  for (auto f : mesh.faces()) {
    const auto [a, b, c] = face_points(mesh, f);
    if (!keep((a + b + c) / 3.0)) continue;
    std::vector<VertexHandle> corners;
    for (auto v : mesh.fv_range(f)) {
      VertexHandle& w = copy[std::size_t(v.idx())];
      if (!w.is_valid()) w = out.add_vertex(mesh.point(v));
      corners.push_back(w);
    }
    out.add_face(corners);
  }
  return out;
}

/// A strip of width 0.4 winding 1.5 turns round the z axis (radius 1, growing by `spread` per
/// turn), rising by `rise` per radian: every face facing up, its shadow on z = 0 overlapping itself.
SurfaceMesh spiral_strip(double rise, double spread) {
  SurfaceMesh strip;
  const int segments = 120;
  std::vector<VertexHandle> inner, outer;
  for (int i = 0; i <= segments; ++i) {
    const double t = 3 * std::numbers::pi * i / segments;
    const double r = 1 + spread * t / (2 * std::numbers::pi);
    inner.push_back(strip.add_vertex(Vec3((r - 0.2) * std::cos(t), (r - 0.2) * std::sin(t), rise * t)));
    outer.push_back(strip.add_vertex(Vec3((r + 0.2) * std::cos(t), (r + 0.2) * std::sin(t), rise * t)));
  }
  for (int i = 0; i < segments; ++i) {
    const auto k = std::size_t(i);
    strip.add_face(inner[k], outer[k], outer[k + 1]);
    strip.add_face(inner[k], outer[k + 1], inner[k + 1]);
  }
  return strip;
}

}  // namespace

TEST_CASE("height fields: a terrain, a tilted square and a shallow cap, where the search finds no crossing") {
  const SurfaceMesh terrain = make_terrain({.extent = 10000, .h = 400});
  CHECK(is_height_field(terrain));
  CHECK(self_intersections(terrain).empty());

  // A square turned 50° about x and 20° about z: a height field over its own plane, not over z = 0.
  SurfaceMesh tilted = make_plane({.size = 2, .h = 0.1});
  const double a = 50 * std::numbers::pi / 180, b = 20 * std::numbers::pi / 180;
  for (auto v : tilted.vertices()) {
    const Vec3 p = tilted.point(v);
    const Vec3 q(p[0], std::cos(a) * p[1] - std::sin(a) * p[2], std::sin(a) * p[1] + std::cos(a) * p[2]);
    tilted.set_point(v, Vec3(std::cos(b) * q[0] - std::sin(b) * q[1], std::sin(b) * q[0] + std::cos(b) * q[1], q[2]));
  }
  CHECK(is_height_field(tilted));

  // A cap of the unit sphere down to 60° from its pole.
  const SurfaceMesh cap = keep_faces(make_sphere({.faces = 5000}), [](const Vec3& c) { return c[2] > 0.5; });
  CHECK(is_height_field(cap));
  CHECK(self_intersections(cap).empty());
}

TEST_CASE("not height fields: closed, two boundaries, faces turned edge-on, a shadow that overlaps itself") {
  CHECK_FALSE(is_height_field(make_sphere({.faces = 2000})));
  // A cap beyond the equator: its rim faces look sideways and down.
  CHECK_FALSE(is_height_field(keep_faces(make_sphere({.faces = 5000}), [](const Vec3& c) { return c[2] > -0.3; })));
  // A square with a hole, and two squares side by side: two boundary loops.
  const SurfaceMesh square = make_plane({.size = 2, .h = 0.1});
  CHECK_FALSE(is_height_field(keep_faces(square, [](const Vec3& c) { return c.norm() > 0.4; })));
  CHECK_FALSE(is_height_field(keep_faces(square, [](const Vec3& c) { return std::abs(c[0]) > 0.3; })));
  // A vertex on no face (the first one, where the boundary's walk starts): not one loop.
  SurfaceMesh lonely;
  lonely.add_vertex(Vec3(5, 5, 5));
  std::vector<VertexHandle> copy;
  for (auto v : square.vertices()) copy.push_back(lonely.add_vertex(square.point(v)));
  for (auto f : square.faces()) {
    std::vector<VertexHandle> corners;
    for (auto v : square.fv_range(f)) corners.push_back(copy[std::size_t(v.idx())]);
    lonely.add_face(corners);
  }
  CHECK(is_height_field(keep_faces(lonely, [](const Vec3&) { return true; })));
  CHECK_FALSE(is_height_field(lonely));
  // A ridge of slope 50 across the square, its faces within 2° of vertical: z(x, y) still, but
  // too steep to trust (a single wall would not do: the mean normal turns towards it, and the square
  // is a height field over the plane across that).
  SurfaceMesh ridge = square;
  for (auto v : ridge.vertices()) {
    const Vec3 p = ridge.point(v);
    ridge.set_point(v, Vec3(p[0], p[1], 50 * std::max(0.0, 0.2 - std::abs(p[0]))));
  }
  CHECK_FALSE(is_height_field(ridge));

  // A flat strip winding one and a half turns: faces all facing up, but its second turn lies on its
  // first. The search finds them crossing; the test must not call it a height field.
  const SurfaceMesh flat_spiral = spiral_strip(0, 0.1);
  CHECK_FALSE(is_height_field(flat_spiral));
  CHECK_FALSE(self_intersections(flat_spiral).empty());
  // The same strip rising as it winds (a ramp) does not cross itself, but nothing short of the
  // search can tell: refused as well.
  const SurfaceMesh ramp = spiral_strip(0.1, 0);
  CHECK_FALSE(is_height_field(ramp));
  CHECK(self_intersections(ramp).empty());
}

TEST_CASE("the remesh of a height field checked against its reference finds no crossing, as the search") {
  SurfaceMesh terrain = make_terrain({.extent = 10000, .h = 400});
  RemeshOptions options;
  options.hmax = 300;
  options.check_distance_to_reference = true;
  const RemeshReport report = remesh(terrain, options);
  CHECK(report.splits > 0);
  CHECK(report.self_intersections == 0);
  CHECK(is_height_field(terrain));
  CHECK(self_intersections(terrain).empty());
}
