// RemeshOptions::changed: a remesh told where its mesh changed since the last one starts work only
// there (and goes on wherever the elements it changes lead it). Invariants: nothing marked, nothing
// done (even on a mesh full of slivers); everything marked, the same bytes as no mark at all; a
// marked patch is remeshed as a whole remesh would, a patch of slivers apart is left as it is.
#include "support/test_support.hpp"

#include <doctest/doctest.h>

#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/remesh.hpp>
#include <bodyfit/validate.hpp>

#include <cmath>
#include <algorithm>
#include <functional>
#include <random>
#include <vector>

using namespace bodyfit;

namespace {

/// A blade 1 × 0.3 × 0.03 (the geodesic sphere scaled): triangles stretched 10:1 near its rim,
/// 28 % of them below quality 0.3: a remesh has work all around.
SurfaceMesh thin_blade() {
  SurfaceMesh mesh = make_sphere({.faces = 20000});
  for (auto v : mesh.vertices()) {
    const Vec3 p = mesh.point(v);
    mesh.point(v) = Vec3(p[0], 0.3 * p[1], 0.03 * p[2]);
  }
  return mesh;
}

bool same_mesh(const SurfaceMesh& a, const SurfaceMesh& b) {
  if (a.n_vertices() != b.n_vertices() || a.n_faces() != b.n_faces()) return false;
  for (auto v : a.vertices())
    if (a.point(v) != b.point(VertexHandle(v.idx()))) return false;
  for (auto f : a.faces()) {
    auto x = face_vertices(a, f), y = face_vertices(b, FaceHandle(f.idx()));
    if (x != y) return false;
  }
  return true;
}

double worst_quality_where(const SurfaceMesh& mesh, const std::function<bool(const Vec3&)>& where) {
  double worst = 1;
  for (auto f : mesh.faces()) {
    auto [a, b, c] = face_points(mesh, f);
    if (where((a + b + c) / 3.0)) worst = std::min(worst, triangle_quality(a, b, c));
  }
  return worst;
}

}  // namespace

TEST_CASE("RemeshOptions::changed: nothing marked leaves the mesh as it is, everything marked gives the bytes of no mark") {
  const SurfaceMesh blade = thin_blade();
  REQUIRE(quality_stats(blade).min < 0.1);

  SurfaceMesh untouched = blade;
  RemeshOptions nothing;
  nothing.changed = [](VertexHandle) { return false; };
  const RemeshReport none = remesh(untouched, nothing);
  CHECK(none.splits + none.collapses + none.flips + none.relocations == 0);
  CHECK(same_mesh(untouched, blade));

  SurfaceMesh whole = blade, marked = blade;
  const RemeshReport plain = remesh(whole, {});
  RemeshOptions everything;
  everything.changed = [](VertexHandle) { return true; };
  const RemeshReport all = remesh(marked, everything);
  CHECK(plain.collapses > 1000);
  CHECK(all.collapses == plain.collapses);
  CHECK(all.relocations == plain.relocations);
  CHECK(same_mesh(marked, whole));

  // Not incremental: every element is looked at whatever the mark says.
  SurfaceMesh full = blade;
  RemeshOptions not_incremental = nothing;
  not_incremental.incremental = false;
  remesh(full, not_incremental);
  CHECK(quality_stats(full).min > 0.3);
}

TEST_CASE("RemeshOptions::changed: a marked patch is remeshed as a whole remesh would, a patch apart is left") {
  // Two patches of poor triangles (vertices shuffled along the sphere) at either end of the x axis,
  // good triangles between them; only the first is marked.
  SurfaceMesh sphere = make_sphere({.faces = 20000});
  const double h = mean_edge_length(sphere);
  // mt19937's numbers are the same everywhere; uniform_real_distribution's are not.
  std::mt19937 random(5);
  auto noise = [&](std::mt19937& r) { return 0.38 * h * (2 * double(r()) / 4294967295.0 - 1); };
  for (auto v : sphere.vertices()) {
    const Vec3 p = sphere.point(v);
    if (std::abs(p[0]) < 0.6) continue;
    const double dy = noise(random), dz = noise(random);  // in this order on every compiler
    const Vec3 moved = p + Vec3(0, dy, dz);
    sphere.point(v) = moved / moved.norm();
    // A move that would turn a triangle more than 60° from the sphere's normal is not made: poor
    // triangles, never folded ones.
    for (auto f : sphere.vf_range(v)) {
      auto [a, b, c] = face_points(sphere, f);
      if ((face_normal(sphere, f) | ((a + b + c) / 3.0).normalized()) < 0.5) {
        sphere.point(v) = p;
        break;
      }
    }
  }
  auto right = [](const Vec3& p) { return p[0] > 0.6; };
  auto left = [](const Vec3& p) { return p[0] < -0.6; };
  REQUIRE(worst_quality_where(sphere, right) < 0.3);  // below the sliver repair's bound
  REQUIRE(worst_quality_where(sphere, left) < 0.3);
  REQUIRE_MESSAGE(validate_mesh(sphere).ok(), validate_mesh(sphere).summary());

  SurfaceMesh part = sphere, whole = sphere;
  RemeshOptions options;
  options.changed = [&part](VertexHandle v) { return part.point(v)[0] > 0.5; };
  remesh(part, options);
  remesh(whole, {});
  const double part_right = worst_quality_where(part, right), whole_right = worst_quality_where(whole, right);
  INFO("worst triangle right: " << part_right << " (whole remesh " << whole_right << "), left: "
                                << worst_quality_where(part, left) << " (whole remesh " << worst_quality_where(whole, left) << ")");
  CHECK(part_right > 0.4);
  CHECK(part_right >= whole_right - 0.05);
  CHECK(worst_quality_where(whole, left) > 0.4);
  // The left patch is as it was: its vertices where they were, its slivers still there.
  std::size_t left_vertices = 0, moved = 0;
  std::vector<Vec3> before;
  for (auto v : sphere.vertices())
    if (sphere.point(v)[0] < -0.6) before.push_back(sphere.point(v));
  for (auto v : part.vertices())
    if (part.point(v)[0] < -0.6) {
      ++left_vertices;
      moved += std::find(before.begin(), before.end(), part.point(v)) == before.end();
    }
  CHECK(left_vertices == before.size());
  CHECK(moved == 0);
  CHECK(worst_quality_where(part, left) == worst_quality_where(sphere, left));
  CHECK(validate_mesh(part).ok());
}
