// validate_mesh(): valid meshes pass, and each kind of deliberate damage is reported.
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/levelset_mesher.hpp>
#include <bodyfit/validate.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>

#include <string>

using namespace bodyfit;

namespace {

/// The unit square in n × n cells split along the (0,0)-(1,1) diagonals; the corner (1, 0)
/// belongs to a single face.
SurfaceMesh make_square(int n) { return test::grid_square(n); }

/// A sphere with a polar cap cut in as the inside region.
SurfaceMesh sphere_with_cap() {
  SurfaceMesh mesh = make_sphere({.faces = 1280});
  ScalarField phi(mesh.n_vertices());
  for (auto v : mesh.vertices()) phi[v.idx()] = mesh.point(v)[2] - 0.3;
  discretize(mesh, phi);
  return mesh;
}

bool mentions(const ValidationReport& report, const std::string& text) {
  for (const auto& line : report.problems)
    if (line.find(text) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST_CASE("valid meshes pass, with their expected topology") {
  ValidateOptions options;
  options.euler_characteristic = 2;
  options.boundary_loops = 0;
  auto report = validate_mesh(sphere_with_cap(), options);
  INFO(report.summary());
  CHECK(report.ok());
  CHECK(report.summary() == "valid\n");

  SurfaceMesh square = make_square(6);
  for (auto f : square.faces()) square.region(f) = kOutside;
  options.euler_characteristic = 1;
  options.boundary_loops = 1;
  CHECK(validate_mesh(square, options).ok());
}

TEST_CASE("wrong expected topology is reported") {
  ValidateOptions options;
  options.euler_characteristic = 0;
  options.boundary_loops = 1;
  auto report = validate_mesh(sphere_with_cap(), options);
  CHECK(report.problem_count == 2);
  CHECK(mentions(report, "Euler characteristic 2 instead of 0"));
  CHECK(mentions(report, "0 boundary loops instead of 1"));
}

TEST_CASE("a face flipped over its opposite edge is reported as folded") {
  SurfaceMesh mesh = make_square(4);
  for (auto f : mesh.faces()) mesh.region(f) = kOutside;
  REQUIRE(validate_mesh(mesh).ok());
  // The corner (1, 0) is in one face only: mirroring it across the face's opposite edge, the line
  // from (0.75, 0) to (1, 0.25), inverts that face and nothing else.
  VertexHandle corner;
  for (auto v : mesh.vertices())
    if (mesh.point(v) == Vec3(1, 0, 0)) corner = v;
  REQUIRE(corner.is_valid());
  REQUIRE(mesh.valence(corner) == 2);
  mesh.point(corner) = Vec3(0.75, 0.25, 0) + 0.2 * (Vec3(0.75, 0.25, 0) - Vec3(1, 0, 0));
  auto report = validate_mesh(mesh);
  INFO(report.summary());
  CHECK(report.problem_count >= 1);
  CHECK(mentions(report, "folded"));
}

TEST_CASE("a duplicated face is reported") {
  SurfaceMesh mesh = sphere_with_cap();
  auto f = *mesh.faces().begin();
  auto p = face_points(mesh, f);
  auto copy = mesh.add_face(mesh.add_vertex(p[0]), mesh.add_vertex(p[1]), mesh.add_vertex(p[2]));
  mesh.region(copy) = mesh.region(f);
  for (auto e : mesh.fe_range(copy)) mesh.interface(e) = 0;
  auto report = validate_mesh(mesh);
  INFO(report.summary());
  CHECK(report.problem_count == 1);
  CHECK(mentions(report, "duplicated"));
}

TEST_CASE("a wrong region label is reported") {
  SurfaceMesh mesh = sphere_with_cap();
  // A face inside the cap, away from the interface, relabelled outside.
  FaceHandle target;
  for (auto f : mesh.faces()) {
    bool all_inside_neighbours = mesh.inside(f);
    for (auto g : mesh.ff_range(f)) all_inside_neighbours &= mesh.inside(g);
    if (all_inside_neighbours) target = f;
  }
  REQUIRE(target.is_valid());
  mesh.region(target) = kOutside;
  auto report = validate_mesh(mesh);
  INFO(report.summary());
  // Its three edges now separate inside from outside without being tagged.
  CHECK(report.problem_count == 3);
  CHECK(mentions(report, "not tagged interface"));

  mesh.region(target) = 5;
  CHECK(mentions(validate_mesh(mesh), "region label 5"));
}

TEST_CASE("a broken interface curve is reported") {
  SurfaceMesh mesh = sphere_with_cap();
  // Untagging one interface edge leaves two vertices with one interface edge each, and the label
  // check sees an edge between inside and outside that is not tagged.
  EdgeHandle target;
  for (auto e : mesh.edges())
    if (mesh.interface(e)) target = e;
  REQUIRE(target.is_valid());
  mesh.interface(target) = 0;
  auto report = validate_mesh(mesh);
  INFO(report.summary());
  CHECK(report.problem_count == 3);
  CHECK(mentions(report, "1 interface edges"));
}

TEST_CASE("deleted elements, degenerate faces, non-manifold vertices, far vertices") {
  SUBCASE("deleted face left in place") {
    SurfaceMesh mesh = sphere_with_cap();
    mesh.delete_face(*mesh.faces().begin(), false);
    CHECK(mentions(validate_mesh(mesh, {.check_regions = false}), "not garbage-collected"));
  }
  SUBCASE("zero-area face") {
    SurfaceMesh mesh = make_square(2);
    for (auto f : mesh.faces()) mesh.region(f) = kOutside;
    for (auto v : mesh.vertices())
      if (mesh.point(v) == Vec3(1, 0, 0)) mesh.point(v) = Vec3(0.75, 0.25, 0);  // onto the opposite edge
    auto report = validate_mesh(mesh);
    INFO(report.summary());
    CHECK(report.problem_count == 1);
    CHECK(mentions(report, "degenerate"));
  }
  SUBCASE("two triangles sharing only a vertex") {
    SurfaceMesh mesh;
    auto o = mesh.add_vertex(Vec3(0, 0, 0));
    auto a = mesh.add_vertex(Vec3(1, 0, 0)), b = mesh.add_vertex(Vec3(0, 1, 0));
    auto c = mesh.add_vertex(Vec3(-1, 0, 0)), d = mesh.add_vertex(Vec3(0, -1, 0));
    mesh.add_face(o, a, b);
    mesh.add_face(o, c, d);
    for (auto f : mesh.faces()) mesh.region(f) = kOutside;
    auto report = validate_mesh(mesh);
    INFO(report.summary());
    CHECK(report.problem_count == 1);
    CHECK(mentions(report, "vertex 0: non-manifold"));
  }
  SUBCASE("vertices away from the reference surface") {
    SurfaceMesh mesh = make_sphere({.faces = 320});
    for (auto f : mesh.faces()) mesh.region(f) = kOutside;
    ValidateOptions options;
    options.distance_to_reference = [](const Vec3& p) { return std::abs(p.norm() - 1); };
    options.max_reference_distance = 1e-12;
    CHECK(validate_mesh(mesh, options).ok());
    mesh.point(VertexHandle(3)) *= 1.01;
    auto report = validate_mesh(mesh, options);
    CHECK(report.problem_count == 1);
    CHECK(mentions(report, "vertex 3: at distance"));
  }
  SUBCASE("the number of listed problems is bounded, all are counted") {
    SurfaceMesh mesh = make_sphere({.faces = 320});
    for (auto f : mesh.faces()) mesh.region(f) = 7;
    auto report = validate_mesh(mesh, {.max_problems = 5});
    CHECK(report.problems.size() == 5);
    CHECK(report.problem_count == mesh.n_faces());
    CHECK(report.summary().find("and 315 more") != std::string::npos);
  }
}
