// The halfedge connectivity built from triangle corners in array passes: add_face's arrays for
// every manifold surface, and a refusal (the mesh untouched) for everything add_face would
// diagnose.
#include <bodyfit/generators.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/mesh_connectivity.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

using namespace bodyfit;
namespace fs = std::filesystem;

namespace {

using Triangles = std::vector<std::array<std::int64_t, 3>>;

/// The corners of every face, in face order.
Triangles triangles_of(const SurfaceMesh& mesh) {
  Triangles triangles;
  for (auto f : mesh.faces()) {
    std::array<std::int64_t, 3> t{};
    int k = 0;
    for (auto v : mesh.fv_range(f)) t[std::size_t(k++)] = v.idx();
    triangles.push_back(t);
  }
  return triangles;
}

Triangles shuffled(Triangles triangles, unsigned seed) {
  std::shuffle(triangles.begin(), triangles.end(), std::mt19937(seed));
  return triangles;
}

/// A mesh with `n` vertices (on a circle: where they are plays no part) and no faces.
SurfaceMesh vertices_only(std::size_t n) {
  SurfaceMesh mesh;
  for (std::size_t i = 0; i < n; ++i) mesh.add_vertex(Vec3(std::cos(0.1 * double(i)), std::sin(0.1 * double(i)), 0));
  return mesh;
}

/// The mesh OpenMesh's add_face builds from these triangles, one after the other.
SurfaceMesh built_by_add_face(std::size_t vertices, const Triangles& triangles) {
  SurfaceMesh mesh = vertices_only(vertices);
  for (const auto& t : triangles)
    REQUIRE(mesh.add_face(VertexHandle(int(t[0])), VertexHandle(int(t[1])), VertexHandle(int(t[2]))).is_valid());
  return mesh;
}

/// Every connectivity array of the two meshes is the same.
void check_same_connectivity(const SurfaceMesh& a, const SurfaceMesh& b) {
  REQUIRE(a.n_vertices() == b.n_vertices());
  REQUIRE(a.n_edges() == b.n_edges());
  REQUIRE(a.n_faces() == b.n_faces());
  std::size_t differences = 0;
  for (auto h : a.halfedges()) {
    const HalfedgeHandle g(h.idx());
    differences += a.to_vertex_handle(h) != b.to_vertex_handle(g) ||
                   a.next_halfedge_handle(h) != b.next_halfedge_handle(g) ||
                   a.prev_halfedge_handle(h) != b.prev_halfedge_handle(g) || a.face_handle(h) != b.face_handle(g);
  }
  for (auto v : a.vertices()) differences += a.halfedge_handle(v) != b.halfedge_handle(VertexHandle(v.idx()));
  for (auto f : a.faces()) differences += a.halfedge_handle(f) != b.halfedge_handle(FaceHandle(f.idx()));
  CHECK(differences == 0);
}

/// The array passes accept the triangles and build what add_face builds.
void check_builds_as_add_face(std::size_t vertices, const Triangles& triangles) {
  SurfaceMesh built = vertices_only(vertices);
  REQUIRE(build_connectivity(built, triangles));
  check_same_connectivity(built, built_by_add_face(vertices, triangles));
}

/// The array passes refuse the triangles and leave the mesh without edges or faces.
bool refused(std::size_t vertices, const Triangles& triangles) {
  SurfaceMesh mesh = vertices_only(vertices);
  const bool built = build_connectivity(mesh, triangles);
  CHECK(mesh.n_edges() == (built ? mesh.n_edges() : 0));
  CHECK(mesh.n_faces() == (built ? triangles.size() : 0));
  return !built;
}

// A closed tetrahedron on vertices 0..3, outward.
const Triangles kTetrahedron = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};

}  // namespace

TEST_CASE("a mesh's connectivity from its corners is add_face's, array for array: closed, open, shuffled, real parts") {
  SUBCASE("closed sphere") {
    const SurfaceMesh sphere = make_sphere({.faces = 5000});
    check_builds_as_add_face(sphere.n_vertices(), triangles_of(sphere));
  }
  SUBCASE("open square") {
    const SurfaceMesh plane = make_plane({.h = 0.2});
    check_builds_as_add_face(plane.n_vertices(), triangles_of(plane));
  }
  SUBCASE("triangles in random order: vertices join several fans before they close") {
    for (const SurfaceMesh& shape : {make_sphere({.faces = 5000}), make_plane({.h = 0.2})})
      check_builds_as_add_face(shape.n_vertices(), shuffled(triangles_of(shape), 7));
  }
  SUBCASE("large enough for the sides to be sorted and numbered by several chunks, shuffled") {
    const SurfaceMesh sphere = make_sphere({.faces = 60000});  // 180k sides
    check_builds_as_add_face(sphere.n_vertices(), shuffled(triangles_of(sphere), 11));
  }
  SUBCASE("a single triangle, a strip, a vertex with one triangle and a vertex with many") {
    check_builds_as_add_face(3, {{0, 1, 2}});
    check_builds_as_add_face(4, {{0, 1, 2}, {2, 1, 3}});
    Triangles fan;  // vertex 0 at the centre of 40 triangles, closed; a cone
    for (std::int64_t i = 0; i < 40; ++i) fan.push_back({0, 1 + i, 1 + (i + 1) % 40});
    check_builds_as_add_face(41, fan);
    fan.pop_back();  // open: vertex 0 on the boundary
    check_builds_as_add_face(41, fan);
  }
  SUBCASE("public meshes with boundaries, handles and creases") {
    for (const char* name : {"anchor", "elephant-with-holes", "fandisk", "knot1"}) {
      const fs::path file = fs::path(BODYFIT_SOURCE_DIR) / "meshes/public" / (std::string(name) + ".off");
      REQUIRE_MESSAGE(fs::exists(file), file.string() << " is missing: run scripts/setup.sh");
      const SurfaceMesh shape = read_mesh(file);
      check_builds_as_add_face(shape.n_vertices(), triangles_of(shape));
    }
  }
}

TEST_CASE("the connectivity refuses what is not a manifold surface, and accepts it once mended") {
  SUBCASE("an edge used twice in one direction") {
    CHECK(refused(4, {{0, 1, 2}, {0, 1, 3}}));
    CHECK_FALSE(refused(4, {{0, 1, 2}, {1, 0, 3}}));
  }
  SUBCASE("an edge of three triangles") {
    CHECK(refused(5, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}}));
    CHECK(refused(5, {{0, 1, 2}, {1, 0, 3}, {1, 0, 4}}));
  }
  SUBCASE("a triangle repeated, either way round, alone or on a closed surface") {
    CHECK(refused(3, {{0, 1, 2}, {0, 1, 2}}));
    CHECK(refused(3, {{0, 1, 2}, {0, 2, 1}}));
    Triangles doubled = kTetrahedron;
    doubled.push_back({0, 1, 2});  // the first face the other way round
    CHECK(refused(4, doubled));
    CHECK_FALSE(refused(4, kTetrahedron));
  }
  SUBCASE("two fans at a vertex: open and open, closed and closed, closed and open") {
    // Two triangles touching at vertex 0 only (a bow tie), then mended by the triangle between them.
    CHECK(refused(5, {{0, 1, 2}, {0, 3, 4}}));
    CHECK_FALSE(refused(5, {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}}));
    // Two tetrahedra sharing vertex 0.
    Triangles pinched = kTetrahedron;
    for (const auto& t : kTetrahedron) {
      std::array<std::int64_t, 3> u = t;
      for (auto& v : u) v = v == 0 ? 0 : v + 3;
      pinched.push_back(u);
    }
    CHECK(refused(7, pinched));
    // A tetrahedron and a triangle touching it at vertex 0.
    Triangles touched = kTetrahedron;
    touched.push_back({0, 4, 5});
    CHECK(refused(6, touched));
  }
  SUBCASE("a vertex used by no triangle is left without a halfedge, not refused") {
    SurfaceMesh mesh = vertices_only(5);
    REQUIRE(build_connectivity(mesh, kTetrahedron));
    CHECK(mesh.is_isolated(VertexHandle(4)));
    CHECK_FALSE(mesh.is_isolated(VertexHandle(3)));
  }
}
