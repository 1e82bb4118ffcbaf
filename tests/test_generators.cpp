// Generators: geodesic spheres (counts, quality, radius, topology), procedural terrains
// (boundary, topology, heights, reproducibility, edge lengths), DEM rasters (.asc, GeoTIFF).
#include <bodyfit/config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>

using namespace bodyfit;

namespace {

void check_sphere(std::size_t n, double radius) {
  CAPTURE(n);
  auto mesh = make_sphere({.faces = n, .radius = radius, .center = {1, -2, 3}});
  const double count = double(mesh.n_faces());
  CHECK(std::abs(count - double(n)) <= 0.1 * double(n));
  CHECK(quality_stats(mesh).min >= 0.7);
  double worst = 0;
  for (auto v : mesh.vertices()) worst = std::max(worst, std::abs((mesh.point(v) - Vec3(1, -2, 3)).norm() - radius));
  CHECK(worst <= 1e-12 * radius);
  CHECK(euler_characteristic(mesh) == 2);
  CHECK(connected_components(mesh) == 1);
  CHECK(boundary_loops(mesh).empty());
  // Outward orientation: every face normal points away from the centre.
  int inward = 0;
  for (auto f : mesh.faces()) {
    auto p = face_points(mesh, f);
    if (OpenMesh::dot(face_normal(mesh, f), (p[0] + p[1] + p[2]) / 3 - Vec3(1, -2, 3)) <= 0) ++inward;
  }
  CHECK(inward == 0);
}

}  // namespace

TEST_CASE("sphere: every face count from 20 to 330 within 10 %, quality >= 0.7, on the sphere") {
  // Below ~300 some counts have no geodesic sphere within 10 % (e.g. 40, 290): all are checked.
  for (std::size_t n = 20; n <= 330; ++n) check_sphere(n, 2.5);
  for (std::size_t n = 331; n <= 1500; n += 13) check_sphere(n, 0.5);
}

TEST_CASE("sphere: larger counts up to 100k") {
  for (std::size_t n : {450, 600, 777, 1000, 1500, 2000, 3001, 5000, 7777, 12000, 20000, 33333, 50000, 100000})
    check_sphere(n, 1.0);
}

TEST_CASE("sphere: benchmark sizes are exactly the class-I spheres") {
  for (int k : {11, 22, 44, 88}) {
    std::size_t n = 20u * std::size_t(k) * std::size_t(k);
    auto mesh = make_sphere({.faces = n});
    CHECK(mesh.n_faces() == n);
    CHECK(mesh.n_vertices() == 10u * std::size_t(k) * std::size_t(k) + 2u);
    // Class I: exactly 12 vertices of valence 5, the others 6.
    int five = 0, six = 0;
    for (auto v : mesh.vertices()) {
      auto val = mesh.valence(v);
      five += val == 5;
      six += val == 6;
    }
    CHECK(five == 12);
    CHECK(six == int(mesh.n_vertices()) - 12);
  }
}

TEST_CASE("sphere: the area converges to 4 pi r^2 from below") {
  auto mesh = make_sphere({.faces = 20000, .radius = 3.0});
  const double exact = 4 * M_PI * 9.0;
  CHECK(total_area(mesh) < exact);
  CHECK(total_area(mesh) > 0.998 * exact);
}

TEST_CASE("sphere: bad options are input errors") {
  CHECK_THROWS_AS(make_sphere({.faces = 19}), InputError);
  CHECK_THROWS_AS(make_sphere({.faces = 100, .radius = 0}), InputError);
}
