// The projection onto S is the nearest point of all its triangles, with or without a hint, near S
// or far from it: checked against the brute-force minimum over every triangle, on meshes with
// creases, holes, triangles of very different sizes and sheets a hair apart.
#include <doctest/doctest.h>

#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/projection.hpp>

#include <tbb/global_control.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "test_support.hpp"

using namespace bodyfit;
namespace fs = std::filesystem;

namespace {

/// Squared distance from p to the nearest of all the triangles of `mesh`.
double brute_force_distance2(const SurfaceMesh& mesh, const Vec3& p) {
  double best = std::numeric_limits<double>::max();
  for (auto f : mesh.faces()) {
    auto [a, b, c] = face_points(mesh, f);
    best = std::min(best, (closest_point_on_triangle(p, a, b, c) - p).sqrnorm());
  }
  return best;
}

/// Points near and far from every kind of place of S, asked with no hint, with the right one and
/// with a wrong one: the distance found is the brute-force minimum and the point lies on the face
/// reported.
void check_nearest(const SurfaceMesh& mesh, int samples) {
  const ReferenceSurface surface(mesh);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const int nf = int(mesh.n_faces());
  double size = 0;  // the bounding box's diagonal
  {
    Vec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (auto v : mesh.vertices()) {
      lo.minimize(mesh.point(v));
      hi.maximize(mesh.point(v));
    }
    size = (hi - lo).norm();
  }
  int checked = 0;
  for (int s = 0; s < samples; ++s) {
    const FaceHandle f(int(random() % std::uint32_t(nf)));
    auto [a, b, c] = face_points(mesh, f);
    double u = unit(random), v = unit(random);
    if (u + v > 1) u = 1 - u, v = 1 - v;
    const Vec3 on = a + (b - a) * u + (c - a) * v;
    const double edge = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    // Off S along its normal and sideways, from a thousandth of an edge to far outside the part.
    const Vec3 n = face_normal(mesh, f);
    const Vec3 side = Vec3(unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5);
    const double scales[] = {0.0, 1e-3 * edge, 0.3 * edge, 2 * edge, 0.05 * size, 3 * size};
    const double scale = scales[s % 6];
    const Vec3 p = on + n * (scale * (unit(random) - 0.5) * 2) + side * scale;
    const double exact = brute_force_distance2(mesh, p);
    for (int hint : {-1, f.idx(), int(random() % std::uint32_t(nf))}) {
      const SurfacePoint q = surface.closest(p, hint);
      REQUIRE(q.face >= 0);
      // The same distance, to rounding (a triangle's vertices may be taken in another order here).
      const double found = (q.point - p).norm();
      INFO("sample " << s << " scale " << scale << " hint " << hint);
      CHECK(std::abs(found - std::sqrt(exact)) <= 1e-13 * size);
      auto [qa, qb, qc] = face_points(mesh, FaceHandle(q.face));
      CHECK((closest_point_on_triangle(q.point, qa, qb, qc) - q.point).norm() <= 1e-12 * size);
      // The distance to one triangle, from above: what the remesher refuses moves and accepts
      // chords by without a search.
      const double to_hint = surface.distance_to_triangle(p, hint);
      if (hint < 0) {
        CHECK(std::isinf(to_hint));
      } else {
        auto [ha, hb, hc] = face_points(mesh, FaceHandle(hint));
        CHECK(std::abs(to_hint - (closest_point_on_triangle(p, ha, hb, hc) - p).norm()) <= 1e-13 * size);
        CHECK(found <= to_hint * (1 + 1e-12) + 1e-15 * size);
      }
      // ... and to the triangles across the hint's sides, found here by the mesh's own adjacency
      // (none on a boundary side): the next bounds the remesher tries.
      double across = std::numeric_limits<double>::infinity();
      if (hint >= 0)
        for (auto g : mesh.ff_range(FaceHandle(hint))) {
          auto [ga, gb, gc] = face_points(mesh, g);
          across = std::min(across, (closest_point_on_triangle(p, ga, gb, gc) - p).norm());
        }
      const double to_neighbours = surface.distance_to_neighbours(p, hint);
      if (std::isinf(across)) {
        CHECK(std::isinf(to_neighbours));
      } else {
        CHECK(std::abs(to_neighbours - across) <= 1e-13 * size);
        CHECK(found <= to_neighbours * (1 + 1e-12) + 1e-15 * size);
      }
      ++checked;
    }
  }
  CHECK(checked == 3 * samples);
}

}  // namespace

TEST_CASE("ReferenceSurface::closest is the nearest of all the triangles: a sphere, a creased part, meshes with holes") {
  SUBCASE("a geodesic sphere") { check_nearest(make_sphere({.faces = 20000}), 600); }
  SUBCASE("the exact sphere has no triangles to bound by") {
    CHECK(std::isinf(ReferenceSurface::sphere(Vec3(0, 0, 0), 1)->distance_to_triangle(Vec3(0, 0, 2), 0)));
    CHECK(std::isinf(ReferenceSurface::sphere(Vec3(0, 0, 0), 1)->distance_to_neighbours(Vec3(0, 0, 2), 0)));
  }
  SUBCASE("public meshes: creases, boundaries, handles, very uneven triangles") {
    for (const char* name : {"fandisk", "anchor", "knot1", "elephant-with-holes"}) {
      const fs::path file = fs::path(BODYFIT_SOURCE_DIR) / "meshes/public" / (std::string(name) + ".off");
      REQUIRE_MESSAGE(fs::exists(file), file.string() << " is missing: run scripts/setup.sh");
      check_nearest(read_mesh(file), 300);
    }
  }
}

TEST_CASE("ReferenceSurface::closest among triangles of very different sizes, and two sheets a hair apart") {
  // A plane square of two huge triangles beside a finely tessellated patch (triangles 600 times
  // smaller), a second sheet 1e-3 above the patch and a parallel plane above the big square.
  SurfaceMesh mesh;
  auto quad = [&](Vec3 o, Vec3 du, Vec3 dv, int n) {
    std::vector<VertexHandle> vh;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) vh.push_back(mesh.add_vertex(o + du * (double(i) / n) + dv * (double(j) / n)));
    auto id = [&](int i, int j) { return vh[std::size_t(j) * std::size_t(n + 1) + std::size_t(i)]; };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        mesh.add_face(id(i, j), id(i + 1, j), id(i + 1, j + 1));
        mesh.add_face(id(i, j), id(i + 1, j + 1), id(i, j + 1));
      }
  };
  quad(Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(0, 10, 0), 1);       // two triangles of side 10
  quad(Vec3(11, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), 60);       // 7,200 triangles of side 1/60
  quad(Vec3(11, 0, 1e-3), Vec3(1, 0, 0), Vec3(0, 1, 0), 7);     // a second sheet 1e-3 above
  quad(Vec3(0, 0, 2), Vec3(10, 0, 0), Vec3(0, 10, 0), 25);      // a parallel plane above the big one
  check_nearest(mesh, 1800);
}

TEST_CASE("ReferenceSurface: the same bits with 1 and 2 threads, and deleted faces left out as in a compacted copy") {
  // A remesh projects onto it and sizes by its curvature: its results must not depend on the
  // thread count, nor on whether the mesh it was copied from was compacted.
  const SurfaceMesh part = read_mesh(fs::path(BODYFIT_SOURCE_DIR) / "meshes/public/fandisk.off");
  auto built_with = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    return std::make_unique<ReferenceSurface>(part);
  };
  const auto one = built_with(1), two = built_with(2);
  CHECK(one->max_curvature() == two->max_curvature());
  CHECK(one->max_curvature() > 0);
  int same = 0;
  for (auto v : part.vertices()) {
    const Vec3 p = part.point(v) + Vec3(1e-3, -2e-3, 3e-3);
    same += one->smooth_normal(p) == two->smooth_normal(p) && one->closest(p).point == two->closest(p).point;
  }
  CHECK(same == int(part.n_vertices()));

  // A third of the faces deleted (not collected): the reference is made of the others.
  SurfaceMesh holes = part;
  for (auto f : holes.faces())
    if (f.idx() % 3 == 0) holes.delete_face(f, true);
  SurfaceMesh compact = holes;
  compact.garbage_collection();
  const ReferenceSurface with_deleted(holes), compacted(compact);
  REQUIRE(with_deleted.n_triangles() == compact.n_faces());
  CHECK(with_deleted.max_curvature() == doctest::Approx(compacted.max_curvature()).epsilon(1e-12));
  // The same distances off S, and at S's vertices the same smooth normals (elsewhere a point halfway
  // between two sheets may take either).
  double worst = 0;
  for (auto v : compact.vertices()) {
    const Vec3 at = compact.point(v), p = at + Vec3(2e-3, 1e-3, -1e-3);
    worst = std::max({worst, std::abs((with_deleted.closest(p).point - p).norm() - (compacted.closest(p).point - p).norm()),
                      (with_deleted.smooth_normal(at) - compacted.smooth_normal(at)).norm()});
  }
  CHECK(worst < 1e-12);
}
