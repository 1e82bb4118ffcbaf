#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

using namespace bodyfit;

TEST_CASE("triangle quality is 1 for an equilateral triangle and 0 for a degenerate one") {
  Vec3 a(0, 0, 0), b(1, 0, 0), c(0.5, std::sqrt(3.0) / 2, 0);
  CHECK(triangle_quality(a, b, c) == doctest::Approx(1.0).epsilon(1e-12));
  CHECK(triangle_quality(a, b, Vec3(2, 0, 0)) == doctest::Approx(0.0));
  // Right isosceles: area 1/2, Σl² = 1 + 1 + 2 → q = 4√3·0.5/4 = √3/2.
  CHECK(triangle_quality(a, b, Vec3(0, 1, 0)) == doctest::Approx(std::sqrt(3.0) / 2));
}

TEST_CASE("P1 gradients reproduce an affine function exactly") {
  Vec3 a(0.1, 0.2, 0.3), b(1.3, -0.2, 0.5), c(0.4, 0.9, -0.1);
  Vec3 g(0.7, -1.1, 2.0);
  auto grads = p1_basis_gradients(a, b, c);
  Vec3 n = OpenMesh::cross(b - a, c - a).normalized();
  Vec3 reconstructed = OpenMesh::dot(g, a) * grads[0] + OpenMesh::dot(g, b) * grads[1] + OpenMesh::dot(g, c) * grads[2];
  Vec3 expected = project_tangent(g, n);
  CHECK((reconstructed - expected).norm() == doctest::Approx(0.0).epsilon(1e-12));
}

TEST_CASE("geodesic sphere: face count, radius, quality, topology") {
  for (std::size_t target : {320u, 2420u, 9680u}) {
    SphereOptions options;
    options.faces = target;
    options.radius = 2.5;
    SurfaceMesh mesh = make_sphere(options);
    CHECK(std::abs(double(mesh.n_faces()) - double(target)) <= 0.1 * double(target));
    for (auto v : mesh.vertices()) CHECK(mesh.point(v).norm() == doctest::Approx(2.5).epsilon(1e-12));
    CHECK(quality_stats(mesh).min >= 0.7);
    CHECK(euler_characteristic(mesh) == 2);
    CHECK(connected_components(mesh) == 1);
    CHECK(boundary_loops(mesh).empty());
    // Outward orientation: every face normal points away from the centre.
    for (auto f : mesh.faces()) {
      auto p = face_points(mesh, f);
      CHECK(OpenMesh::dot(face_normal(mesh, f), p[0] + p[1] + p[2]) > 0);
    }
  }
}

TEST_CASE("area of the inscribed geodesic sphere converges at order 2") {
  // The polyhedron's area deficit is O(h²): quadrupling the faces (h/2) divides it by about 4.
  double previous = 0;
  for (std::size_t k : {8u, 16u, 32u}) {
    SphereOptions options;
    options.faces = 20 * k * k;
    double deficit = 4 * M_PI - total_area(make_sphere(options));
    CHECK(deficit > 0);
    if (previous > 0) CHECK(std::log2(previous / deficit) == doctest::Approx(2.0).epsilon(0.05));
    previous = deficit;
  }
}

TEST_CASE("l2_difference integrates squared P1 differences exactly (midpoint rule is exact for quadratics)") {
  SurfaceMesh square = test::grid_square(7);
  ScalarField zero(square.n_vertices(), 0.0);
  // Over [0,1]²: ∫ x² = 1/3; ∫ (x + 2y)² = 1/3 + ∫ 4xy + ∫ 4y² = 1/3 + 1 + 4/3 = 8/3.
  CHECK(l2_difference(square, zero, [](const Vec3& p) { return p[0]; }) == doctest::Approx(std::sqrt(1.0 / 3)).epsilon(1e-13));
  CHECK(l2_difference(square, zero, [](const Vec3& p) { return p[0] + 2 * p[1]; }) ==
        doctest::Approx(std::sqrt(8.0 / 3)).epsilon(1e-13));
  // A P1 field equal to the exact affine function has no error.
  ScalarField affine(square.n_vertices());
  for (auto v : square.vertices()) affine[v.idx()] = 3 * square.point(v)[0] - square.point(v)[1];
  CHECK(l2_difference(square, affine, [](const Vec3& p) { return 3 * p[0] - p[1]; }) == doctest::Approx(0.0).epsilon(1e-14));
}

TEST_CASE("vertex gradients: exact for an affine function on a plane, tangential and convergent on the sphere") {
  // Plane: the area-weighted average of exact face gradients is exact.
  const SurfaceMesh square = test::grid_square(8);
  ScalarField affine(square.n_vertices());
  for (auto v : square.vertices()) affine[v.idx()] = 2.0 * square.point(v)[0] - 3.0 * square.point(v)[1] + 1.0;
  const VectorField all = vertex_gradients(square, affine);
  for (auto v : square.vertices()) {
    CHECK((all[v.idx()] - Vec3(2, -3, 0)).norm() < 1e-12);
    CHECK((vertex_gradient(square, v, affine) - all[v.idx()]).norm() < 1e-12);
  }
  // Sphere, u = z: the surface gradient is e_z − z n (n = x). The one-vertex and the one-pass
  // forms agree, and the max error falls at first order (the valence-5 vertices).
  auto worst_error = [](std::size_t faces) {
    const SurfaceMesh sphere = make_sphere({.faces = faces});
    ScalarField z(sphere.n_vertices());
    for (auto v : sphere.vertices()) z[v.idx()] = sphere.point(v)[2];
    const VectorField g = vertex_gradients(sphere, z);
    double worst = 0, disagreement = 0;
    for (auto v : sphere.vertices()) {
      const Vec3 n = sphere.point(v).normalized();
      const Vec3 exact = Vec3(0, 0, 1) - n[2] * n;
      worst = std::max(worst, (g[v.idx()] - exact).norm());
      CHECK(std::abs(OpenMesh::dot(g[v.idx()], vertex_normal(sphere, v))) < 1e-12);  // tangent to the mesh
      disagreement = std::max(disagreement, (vertex_gradient(sphere, v, z) - g[v.idx()]).norm());
    }
    CHECK(disagreement < 1e-12);
    return worst;
  };
  const double coarse = worst_error(1280), fine = worst_error(5120);
  MESSAGE("max error " << coarse << " -> " << fine);
  CHECK(std::log(coarse / fine) / std::log(2.0) > 0.9);  // h halves from 1280 to 5120 faces
}

TEST_CASE("vertex gradients at some vertices are the whole-surface ones bit for bit, zero elsewhere") {
  // A narrow band computes the front's normal at its own vertices only; it must see the values the
  // whole surface does, to the last bit, or the two computations part by rounding.
  const SurfaceMesh sphere = make_sphere({.faces = 1280});
  ScalarField u(sphere.n_vertices());
  for (auto v : sphere.vertices()) u[v.idx()] = std::sin(3 * sphere.point(v)[0]) + sphere.point(v)[1] * sphere.point(v)[2];
  const VectorField all = vertex_gradients(sphere, u);
  std::vector<int> some;
  for (int v = 0; v < int(sphere.n_vertices()); v += 3) some.push_back(v);
  const VectorField part = vertex_gradients(sphere, u, some);
  std::size_t same = 0, zero = 0;
  for (int v = 0; v < int(sphere.n_vertices()); ++v)
    if (v % 3 == 0)
      same += part[v] == all[v];
    else
      zero += part[v] == Vec3(0, 0, 0);
  CHECK(same == some.size());
  CHECK(zero == sphere.n_vertices() - some.size());
}

TEST_CASE("z_order is a deterministic permutation that keeps consecutive points close") {
  // Points of a 32 × 32 × 32 lattice in a scrambled order: consecutive points in the scrambled order
  // are far apart; in Z-order they are neighbours most of the time.
  std::vector<Vec3> points;
  for (int k = 0; k < 32768; ++k) {
    const int scrambled = int((std::uint64_t(k) * 2654435761u) % 32768u);  // a bijection (odd multiplier)
    points.emplace_back(scrambled % 32, (scrambled / 32) % 32, scrambled / 1024);
  }
  const std::vector<int> order = z_order(points);
  REQUIRE(order.size() == points.size());
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (int i = 0; i < int(sorted.size()); ++i) CHECK_UNARY(sorted[i] == i);
  CHECK(z_order(points) == order);
  auto mean_step = [&](auto index_of) {
    double sum = 0;
    for (std::size_t i = 1; i < points.size(); ++i) sum += (points[index_of(i)] - points[index_of(i - 1)]).norm();
    return sum / double(points.size() - 1);
  };
  const double scrambled_step = mean_step([](std::size_t i) { return i; });
  const double z_step = mean_step([&](std::size_t i) { return std::size_t(order[i]); });
  MESSAGE("mean step: scrambled " << scrambled_step << ", Z-order " << z_step);
  CHECK(z_step < 2.0);
  CHECK(z_step < 0.2 * scrambled_step);
}
