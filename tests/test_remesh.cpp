// Remeshing keeps the surface, the interface, the features, the boundary and the topology, and
// leaves an already-good mesh alone. Exact references: the unit sphere, a cube, a plane square.
#include <doctest/doctest.h>

#include <bodyfit/evolution.hpp>
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/levelset_mesher.hpp>
#include <bodyfit/projection.hpp>
#include <bodyfit/remesh.hpp>
#include <bodyfit/self_intersections.hpp>
#include <bodyfit/validate.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <numeric>
#include <random>

#include "test_support.hpp"

using namespace bodyfit;

namespace {

double beta(const Vec3& p) { return std::acos(std::clamp(p[2] / p.norm(), -1.0, 1.0)); }

/// Square [0, side]² in the plane z = 0 (or on a gentle height field), n × n cells, two triangles each.
SurfaceMesh make_grid(int n, double side, bool curved = false) {
  SurfaceMesh mesh;
  std::vector<VertexHandle> vh;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      double x = side * i / n, y = side * j / n;
      double z = curved ? 0.05 * side * std::sin(3 * x / side) * std::cos(2 * y / side) : 0.0;
      vh.push_back(mesh.add_vertex(Vec3(x, y, z)));
    }
  auto id = [&](int i, int j) { return vh[std::size_t(j) * (n + 1) + i]; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      mesh.add_face(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      mesh.add_face(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  for (auto f : mesh.faces()) mesh.region(f) = kOutside;
  return mesh;
}

/// Cube [-1, 1]³, each side an n × n grid of cells with alternating diagonals, outward normals.
SurfaceMesh make_cube(int n) {
  SurfaceMesh mesh;
  std::map<std::array<long, 3>, VertexHandle> index;
  auto vertex = [&](const Vec3& p) -> VertexHandle {
    std::array<long, 3> key{std::lround(p[0] * n * 4), std::lround(p[1] * n * 4), std::lround(p[2] * n * 4)};
    auto it = index.find(key);
    if (it != index.end()) return it->second;
    auto v = mesh.add_vertex(p);
    index[key] = v;
    return v;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int sign = -1; sign <= 1; sign += 2) {
      int u = (axis + 1) % 3, w = (axis + 2) % 3;
      auto point = [&](int i, int j) {
        Vec3 p(0, 0, 0);
        p[axis] = sign;
        p[u] = -1 + 2.0 * i / n;
        p[w] = -1 + 2.0 * j / n;
        return vertex(p);
      };
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          auto a = point(i, j), b = point(i + 1, j), c = point(i + 1, j + 1), d = point(i, j + 1);
          // (u, w, axis) is right-handed, so a→b→c faces +axis; flip for the negative side.
          if (sign > 0) {
            mesh.add_face(a, b, c);
            mesh.add_face(a, c, d);
          } else {
            mesh.add_face(a, c, b);
            mesh.add_face(a, d, c);
          }
        }
    }
  for (auto f : mesh.faces()) mesh.region(f) = kOutside;
  return mesh;
}

ScalarField cap_phi(const SurfaceMesh& mesh, double radius) {
  ScalarField phi(mesh.n_vertices());
  for (auto v : mesh.vertices()) phi[v.idx()] = beta(mesh.point(v)) - radius;
  return phi;
}

std::string problems(const SurfaceMesh& mesh, ValidateOptions options = {}) {
  auto report = validate_mesh(mesh, options);
  return report.ok() ? std::string() : report.summary();
}

}  // namespace

TEST_CASE("reference polyline: a smoothed label follows the circle it samples, corners and other labels stay chords") {
  // A regular 16-gon inscribed in the unit circle (label 1) and the same 16-gon with one vertex
  // pulled out into a spike (label 2), plus a square (label 3) left as a polyline.
  const int n = 16;
  auto on_circle = [&](double k) { return Vec3(std::cos(2 * M_PI * k / n), std::sin(2 * M_PI * k / n), 0); };
  ReferencePolyline curves;
  for (int k = 0; k < n; ++k) curves.add(on_circle(k), on_circle(k + 1), 1);
  const Vec3 square[4] = {Vec3(3, 0, 0), Vec3(4, 0, 0), Vec3(4, 1, 0), Vec3(3, 1, 0)};
  for (int k = 0; k < 4; ++k) curves.add(square[k], square[(k + 1) % 4], 3);
  const double corner = M_PI / 4;
  curves.smooth(1, corner);
  curves.smooth(3, corner);  // every square vertex turns by 90° > 45°: all corners, so chords
  const double sagitta = 1 - std::cos(M_PI / n);
  double worst = 0;
  for (std::size_t i = 0; i < std::size_t(n); ++i)
    for (double t : {0.0, 0.25, 0.5, 0.75, 1.0}) worst = std::max(worst, std::abs(curves.point(i, t).norm() - 1));
  CHECK(worst < 0.02 * sagitta);  // the Hermite arcs are O(h⁴) off the circle, the chords O(h²)
  // Projection of a chord midpoint lands on the arc, near the circle, and its projection is itself.
  Vec3 mid = (on_circle(3) + on_circle(4)) * 0.5;
  Vec3 q = curves.closest(mid, 1);
  CHECK(std::abs(q.norm() - 1) < 0.02 * sagitta);
  CHECK((curves.closest(q, 1) - q).norm() < 1e-12);
  CHECK((curves.closest(on_circle(5), 1) - on_circle(5)).norm() < 1e-14);
  // The square keeps its straight sides and exact corners.
  CHECK((curves.closest(Vec3(3.5, -0.2, 0), 3) - Vec3(3.5, 0, 0)).norm() < 1e-14);
  CHECK((curves.closest(Vec3(4.3, -0.3, 0), 3) - Vec3(4, 0, 0)).norm() < 1e-14);
  CHECK((curves.point(std::size_t(n) + 1, 0.5) - Vec3(4, 0.5, 0)).norm() < 1e-14);
  // An open arc (ends with one segment): the one-sided end tangents still follow the circle.
  ReferencePolyline arc;
  for (int k = 0; k < 4; ++k) arc.add(on_circle(k), on_circle(k + 1), 0);
  arc.smooth(0, corner);
  CHECK(std::abs(arc.point(0, 0.5).norm() - 1) < 0.05 * sagitta);
  CHECK(std::abs(arc.point(3, 0.5).norm() - 1) < 0.05 * sagitta);
}

TEST_CASE("ReferenceSurface::smooth_normal: S's vertex normals at its vertices, continuous, converging on a sphere") {
  // One continuous field of position (docs/reference/fire_model.md, "Slope from the surface"): at a vertex of S it
  // is S's vertex normal, across an edge of S it does not jump, and on a triangulated sphere it
  // converges to the exact normal, several times closer than S's face normals. (Area-weighted vertex
  // normals are first order on the geodesic sphere's irregular valences, like the face normals.)
  struct Errors {
    double smooth = 0, face = 0;
  };
  auto errors = [](std::size_t faces) {
    const SurfaceMesh sphere = make_sphere({.faces = faces});
    const ReferenceSurface surface(sphere);
    for (auto v : sphere.vertices())
      CHECK((surface.smooth_normal(sphere.point(v)) - vertex_normal(sphere, v)).norm() < 1e-12);
    Errors e;
    for (auto f : sphere.faces()) {
      auto [a, b, c] = face_points(sphere, f);
      for (const Vec3& p : {(a + b + c) / 3.0, (a + b) / 2.0, 0.6 * a + 0.3 * b + 0.1 * c}) {
        const Vec3 exact = p / p.norm();
        e.smooth = std::max(e.smooth, (surface.smooth_normal(p) - exact).norm());
        e.face = std::max(e.face, (face_normal(sphere, f) - exact).norm());
      }
    }
    // Continuity: the two faces of an edge give the same normal at its points.
    for (auto edge : sphere.edges()) {
      const auto h0 = sphere.halfedge_handle(edge, 0), h1 = sphere.halfedge_handle(edge, 1);
      const Vec3 a = sphere.point(sphere.from_vertex_handle(h0)), b = sphere.point(sphere.to_vertex_handle(h0));
      const Vec3 across = sphere.point(sphere.to_vertex_handle(sphere.next_halfedge_handle(h0))) -
                          sphere.point(sphere.to_vertex_handle(sphere.next_halfedge_handle(h1)));
      const Vec3 p = 0.7 * a + 0.3 * b;
      CHECK((surface.smooth_normal(p + 1e-9 * across) - surface.smooth_normal(p - 1e-9 * across)).norm() < 1e-6);
    }
    return e;
  };
  const Errors coarse = errors(1280), fine = errors(5120);  // h halves
  INFO("smooth " << coarse.smooth << " -> " << fine.smooth << ", face " << coarse.face << " -> " << fine.face);
  CHECK(coarse.smooth / fine.smooth > 1.6);  // measured 1.8 (first order: 2)
  CHECK(fine.smooth < 0.2 * fine.face);      // measured 0.14
  // An exact sphere's smooth normal is its normal.
  const auto exact = ReferenceSurface::sphere(Vec3(0, 0, 0), 2);
  CHECK((exact->smooth_normal(Vec3(0.3, -4, 1)) - Vec3(0.3, -4, 1) / Vec3(0.3, -4, 1).norm()).norm() < 1e-15);
}

TEST_CASE("sphere cap: topology, regions, quality, surface and interface accuracy") {
  auto mesh = make_sphere({.faces = 5120});
  double h = edge_length_stats(mesh).mean;
  double radius = M_PI / 4;
  DiscretizeOptions cut;
  cut.snap_ratio = 0;
  discretize(mesh, cap_phi(mesh, radius), cut);
  RemeshOptions options;
  options.hmax = h;
  options.reference = ReferenceSurface::sphere(Vec3(0, 0, 0), 1);
  auto report = remesh(mesh, options);

  ValidateOptions vo;
  vo.euler_characteristic = 2;
  vo.boundary_loops = 0;
  CHECK(problems(mesh, vo) == "");
  CHECK(connected_components(mesh) == 1);
  CHECK(region_components(mesh, kInside) == 1);
  CHECK(region_components(mesh, kOutside) == 1);
  auto curves = interface_curves(mesh);
  CHECK(curves.closed == 1);
  CHECK(curves.open == 0);
  // Cap area 2π(1 − cos a) and its circle length 2π sin a, to O(h²).
  double cap = 2 * M_PI * (1 - std::cos(radius));
  CHECK(std::abs(region_area(mesh, kInside) - cap) < 0.5 * h * h * 4 * M_PI / 4);
  CHECK(std::abs(interface_length(mesh) - 2 * M_PI * std::sin(radius)) < 2 * M_PI * h * h);
  // Quality.
  CHECK(report.min_quality >= 0.5);
  CHECK(report.mean_quality >= 0.95);
  // Every vertex exactly on S; every edge midpoint within hausd (default D/1000).
  double hausd = 2 * std::sqrt(3.0) / 1000;
  for (auto v : mesh.vertices()) CHECK(std::abs(mesh.point(v).norm() - 1) < 1e-12);
  double worst_mid = 0;
  for (auto e : mesh.edges()) {
    auto hh = mesh.halfedge_handle(e, 0);
    Vec3 mid = (mesh.point(mesh.from_vertex_handle(hh)) + mesh.point(mesh.to_vertex_handle(hh))) * 0.5;
    worst_mid = std::max(worst_mid, 1 - mid.norm());
  }
  CHECK(worst_mid <= hausd);
  // Interface vertices on the circle to the accuracy of the linear cut, O(h²).
  for (auto e : mesh.edges())
    if (mesh.interface(e))
      for (auto v : {mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)), mesh.to_vertex_handle(mesh.halfedge_handle(e, 0))})
        CHECK(std::abs(beta(mesh.point(v)) - radius) < h * h);
}

TEST_CASE("hausd_interface bounds the interface alone: its edges shorten to the chord of that sag, the rest keeps hmax") {
  // The cap's circle (β = π/4 on the unit sphere) has curvature 1/sin β = √2. At the default hausd
  // (D/1000 = 3.5e-3) its chords of h ≈ 0.075 sag by h²κ/8 = 1e-3: hmax suffices. With
  // hausd_interface = 2e-5 the interface's target size is √(8·2e-5/√2) = 0.0106, and its edges may
  // reach √2 times that before a split.
  auto remeshed = [](double hausd_interface, double& h) {
    auto mesh = make_sphere({.faces = 5120});
    h = edge_length_stats(mesh).mean;
    DiscretizeOptions cut;
    cut.snap_ratio = 0;
    discretize(mesh, cap_phi(mesh, M_PI / 4), cut);
    RemeshOptions options;
    options.hmax = h;
    options.hausd_interface = hausd_interface;
    options.reference = ReferenceSurface::sphere(Vec3(0, 0, 0), 1);
    remesh(mesh, options);
    return mesh;
  };
  double h = 0;
  const SurfaceMesh loose = remeshed(0, h), tight = remeshed(2e-5, h);
  auto interface_edges = [](const SurfaceMesh& mesh, double& longest) {
    std::size_t count = 0;
    longest = 0;
    for (auto e : mesh.edges())
      if (mesh.interface(e)) ++count, longest = std::max(longest, edge_length(mesh, e));
    return count;
  };
  double longest_loose = 0, longest_tight = 0;
  const std::size_t n_loose = interface_edges(loose, longest_loose), n_tight = interface_edges(tight, longest_tight);
  const double target = std::sqrt(8 * 2e-5 / std::sqrt(2.0));
  MESSAGE("interface edges " << n_loose << " -> " << n_tight << ", longest " << longest_loose << " -> " << longest_tight
                             << " (target " << target << ")");
  CHECK(longest_tight <= std::sqrt(2.0) * target * 1.05);
  CHECK(longest_loose > 3 * longest_tight);
  CHECK(n_tight > 3 * n_loose);
  // The same circle and regions, a valid mesh, and the surface away from the front at hmax.
  ValidateOptions vo;
  vo.euler_characteristic = 2;
  vo.boundary_loops = 0;
  CHECK(problems(tight, vo) == "");
  CHECK(interface_curves(tight).closed == 1);
  CHECK(std::abs(interface_length(tight) - 2 * M_PI * std::sin(M_PI / 4)) < 2 * M_PI * h * h);
  CHECK(edge_length_stats(tight).max <= std::sqrt(2.0) * h * 1.05);
  CHECK(tight.n_faces() < loose.n_faces() * 3);
}

TEST_CASE("interface vertices stay on the smooth curve through the input interface, regions keep their labels") {
  auto mesh = make_grid(30, 1.0, true);
  ScalarField phi(mesh.n_vertices());
  for (auto v : mesh.vertices()) {
    auto p = mesh.point(v);
    phi[v.idx()] = std::hypot(p[0] - 0.5, p[1] - 0.45) - 0.27;
  }
  DiscretizeOptions cut;
  cut.snap_ratio = 0;
  discretize(mesh, phi, cut);
  ReferencePolyline input_curve;
  double longest = 0;
  for (auto e : mesh.edges())
    if (mesh.interface(e)) {
      auto hh = mesh.halfedge_handle(e, 0);
      input_curve.add(mesh.point(mesh.from_vertex_handle(hh)), mesh.point(mesh.to_vertex_handle(hh)), 0);
      longest = std::max(longest, edge_length(mesh, e));
    }
  double inside_before = region_area(mesh, kInside), outside_before = region_area(mesh, kOutside);
  RemeshOptions options;
  options.hmax = 1.0 / 20;  // coarser than the input: forces collapses along the curve
  auto reference = std::make_shared<ReferenceSurface>(mesh);
  options.reference = reference;
  auto report = remesh(mesh, options);
  CHECK(report.collapses > 0);
  ValidateOptions vo;
  vo.euler_characteristic = 1;
  vo.boundary_loops = 1;
  CHECK(problems(mesh, vo) == "");
  std::size_t on_curve = 0;
  double worst_off = 0;
  for (auto e : mesh.edges())
    if (mesh.interface(e))
      for (auto v : {mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)), mesh.to_vertex_handle(mesh.halfedge_handle(e, 0))}) {
        Vec3 p = mesh.point(v);
        // Moved vertices lie on a smooth curve through the input vertices, off the input chords by
        // at most their sagitta l²κ/8 (κ = 1/0.27 the curvature of the circle; ×2 for the tilt of
        // the height field and the projection back onto S) ...
        double off_polyline = (input_curve.closest(p, 0) - p).norm();
        CHECK(off_polyline < 2 * longest * longest / (8 * 0.27));
        worst_off = std::max(worst_off, off_polyline);
        // ... and closer to the exact circle than the chords' sagitta (the distance from the level
        // set of the piecewise-linear φ to the circle is O(h²) too, with h = 1/30 the input cells).
        CHECK(std::abs(std::hypot(p[0] - 0.5, p[1] - 0.45) - 0.27) < 1.0 / (30 * 30));
        ++on_curve;
      }
  CHECK(on_curve > 0);
  MESSAGE("interface vertices off the input polyline by at most " << worst_off << ", input chords up to " << longest);
  // Every vertex on the input surface.
  for (auto v : mesh.vertices()) CHECK((reference->closest(mesh.point(v)).point - mesh.point(v)).norm() < 1e-9);
  // Region areas change only by the chords of the coarser interface: O(h²) per unit length.
  double h = options.hmax;
  CHECK(std::abs(region_area(mesh, kInside) - inside_before) < 2 * M_PI * 0.27 * h * h);
  CHECK(std::abs(region_area(mesh, kOutside) - outside_before) < 2 * M_PI * 0.27 * h * h);
  CHECK(interface_curves(mesh).closed == 1);
}

TEST_CASE("cube: the 12 ridges and 8 corners survive exactly, vertices stay on the cube") {
  auto mesh = make_cube(12);
  RemeshOptions options;
  options.hmax = 2.0 / 5;  // coarsen: 12 cells per side towards 5
  auto report = remesh(mesh, options);
  CHECK(report.collapses > 0);
  ValidateOptions vo;
  vo.euler_characteristic = 2;
  CHECK(problems(mesh, vo) == "");
  int corners = 0;
  for (auto v : mesh.vertices()) {
    Vec3 p = mesh.point(v);
    double m = std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])});
    CHECK(std::abs(m - 1) < 1e-12);
    if (std::abs(std::abs(p[0]) - 1) < 1e-12 && std::abs(std::abs(p[1]) - 1) < 1e-12 && std::abs(std::abs(p[2]) - 1) < 1e-12)
      ++corners;
  }
  CHECK(corners == 8);
  // Edges on the cube's edges (two coordinates at ±1) are exactly the ridge edges, total length 24.
  double ridge_length = 0, cube_edge_length = 0;
  for (auto e : mesh.edges()) {
    auto hh = mesh.halfedge_handle(e, 0);
    Vec3 a = mesh.point(mesh.from_vertex_handle(hh)), b = mesh.point(mesh.to_vertex_handle(hh));
    int shared = 0;
    for (int k = 0; k < 3; ++k) shared += std::abs(std::abs(a[k]) - 1) < 1e-12 && std::abs(a[k] - b[k]) < 1e-12;
    if (shared == 2) cube_edge_length += (a - b).norm();
    if (mesh.ridge(e)) ridge_length += (a - b).norm();
    // No edge cuts across a cube edge (its endpoints on two different sides only if along an edge).
  }
  CHECK(ridge_length == doctest::Approx(24).epsilon(1e-12));
  CHECK(cube_edge_length == doctest::Approx(24).epsilon(1e-12));
  // Flat sides: every face normal is a coordinate axis.
  for (auto f : mesh.faces()) {
    Vec3 n = face_normal(mesh, f);
    double m = std::max({std::abs(n[0]), std::abs(n[1]), std::abs(n[2])});
    CHECK(m == doctest::Approx(1).epsilon(1e-9));
  }
}

TEST_CASE("open surface: the boundary loop keeps its position, length and corners") {
  auto mesh = make_grid(24, 2.0);
  ScalarField phi(mesh.n_vertices());
  for (auto v : mesh.vertices()) phi[v.idx()] = mesh.point(v)[0] - 0.73;  // a straight front reaching the boundary
  discretize(mesh, phi);
  RemeshOptions options;
  options.hmax = 2.0 / 10;
  remesh(mesh, options);
  ValidateOptions vo;
  vo.euler_characteristic = 1;
  vo.boundary_loops = 1;
  CHECK(problems(mesh, vo) == "");
  auto loops = boundary_loops(mesh);
  REQUIRE(loops.size() == 1);
  double length = 0;
  int corners = 0;
  for (std::size_t i = 0; i < loops[0].size(); ++i) {
    Vec3 a = mesh.point(loops[0][i]), b = mesh.point(loops[0][(i + 1) % loops[0].size()]);
    length += (a - b).norm();
    bool on_side = std::abs(a[0]) < 1e-12 || std::abs(a[0] - 2) < 1e-12 || std::abs(a[1]) < 1e-12 || std::abs(a[1] - 2) < 1e-12;
    CHECK(on_side);
    CHECK(std::abs(a[2]) < 1e-12);
    corners += (std::abs(a[0]) < 1e-12 || std::abs(a[0] - 2) < 1e-12) && (std::abs(a[1]) < 1e-12 || std::abs(a[1] - 2) < 1e-12);
  }
  CHECK(length == doctest::Approx(8).epsilon(1e-12));
  CHECK(corners == 4);
  CHECK(interface_curves(mesh).open == 1);
}

TEST_CASE("an already-good mesh comes back nearly untouched") {
  auto mesh = make_sphere({.faces = 20000});
  auto original = mesh;
  RemeshOptions options;
  options.hmax = edge_length_stats(mesh).mean;
  auto report = remesh(mesh, options);
  CHECK(report.splits + report.collapses + report.flips == 0);
  CHECK(report.relocations == 0);
  REQUIRE(mesh.n_vertices() == original.n_vertices());
  for (auto v : mesh.vertices()) CHECK((mesh.point(v) - original.point(v)).norm() == 0);
}

TEST_CASE("required vertices are never moved or removed") {
  auto mesh = make_grid(20, 1.0, true);
  std::vector<Vec3> required;
  std::mt19937 rng(3);
  for (auto v : mesh.vertices())
    if (rng() % 17 == 0) {
      mesh.required(v) = 1;
      required.push_back(mesh.point(v));
    }
  RemeshOptions options;
  options.hmax = 1.0 / 8;  // strong coarsening
  auto report = remesh(mesh, options);
  CHECK(report.collapses > 0);
  CHECK(problems(mesh) == "");
  std::size_t found = 0;
  for (auto v : mesh.vertices())
    if (mesh.required(v))
      for (const auto& p : required) found += (mesh.point(v) - p).norm() == 0;
  CHECK(found == required.size());
}

TEST_CASE("discretize + remesh of random level sets never produces an invalid mesh") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uni(-1, 1);
  for (int trial = 0; trial < 6; ++trial) {
    SurfaceMesh mesh = trial % 3 == 0 ? make_sphere({.faces = 2000}) : trial % 3 == 1 ? make_grid(25, 1.0, true) : make_cube(8);
    long chi = euler_characteristic(mesh);
    std::size_t loops = boundary_loops(mesh).size();
    // A sum of random plane waves: several components, saddles, curves touching the boundary.
    Vec3 k[3];
    double phase[3];
    for (int i = 0; i < 3; ++i) {
      k[i] = Vec3(uni(rng), uni(rng), uni(rng)) * 9.0;
      phase[i] = 3 * uni(rng);
    }
    ScalarField phi(mesh.n_vertices());
    for (auto v : mesh.vertices()) {
      Vec3 p = mesh.point(v);
      phi[v.idx()] = std::sin((k[0] | p) + phase[0]) + std::sin((k[1] | p) + phase[1]) + 0.5 * std::sin((k[2] | p) + phase[2]) + 0.3;
    }
    discretize(mesh, phi);
    double hmax = edge_length_stats(mesh).mean * (trial < 3 ? 1.0 : 1.7);
    RemeshOptions options;
    options.hmax = hmax;
    remesh(mesh, options);
    ValidateOptions vo;
    vo.euler_characteristic = chi;
    vo.boundary_loops = loops;
    INFO("trial " << trial);
    CHECK(problems(mesh, vo) == "");
  }
}

TEST_CASE("bodyfit remesh: reads a Medit mesh, writes a valid remeshed one, rejects a missing file") {
  test::TempDir dir("remesh_cli");
  auto mesh = make_sphere({.faces = 2000});
  discretize(mesh, cap_phi(mesh, 1.0));
  write_mesh(mesh, dir / "cut.mesh");
  auto run = test::run_bodyfit("remesh " + (dir / "cut.mesh").string() + " -o " + (dir / "out.mesh").string() + " --hmax 0.15");
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  auto out = read_mesh(dir / "out.mesh");
  ValidateOptions vo;
  vo.euler_characteristic = 2;
  CHECK(problems(out, vo) == "");
  CHECK(out.has_regions());
  CHECK(interface_curves(out).closed == 1);
  CHECK(test::run_bodyfit("remesh " + (dir / "missing.mesh").string() + " -o " + (dir / "x.mesh").string()).exit_code != 0);
}

TEST_CASE("a cap remeshed many times keeps its area: the interface is not re-inscribed at every pass") {
  // Alternating coarse and fine sizes force splits, collapses and relocations along the interface at
  // every pass. A polyline reference would move vertices onto chords each time (inside the convex
  // cap), losing about one inscribed-polygon deficit L·h²·κ_g/12 per pass; the smooth reference curve
  // keeps the total loss at the level of one such deficit.
  auto mesh = make_sphere({.faces = 5120});
  double h = edge_length_stats(mesh).mean;
  double radius = M_PI / 4;
  DiscretizeOptions cut;
  cut.snap_ratio = 0;
  discretize(mesh, cap_phi(mesh, radius), cut);
  const double cap = 2 * M_PI * (1 - std::cos(radius));
  const double circle = 2 * M_PI * std::sin(radius), geodesic_curvature = 1 / std::tan(radius);
  RemeshOptions options;
  options.reference = ReferenceSurface::sphere(Vec3(0, 0, 0), 1);
  const double sizes[] = {1.0, 1.8, 0.7, 1.8, 0.7, 1.8, 1.0};
  double coarsest = 0;
  for (double s : sizes) {
    options.hmax = s * h;
    coarsest = std::max(coarsest, options.hmax);
    remesh(mesh, options);
  }
  ValidateOptions vo;
  vo.euler_characteristic = 2;
  CHECK(problems(mesh, vo) == "");
  CHECK(interface_curves(mesh).closed == 1);
  const double one_deficit = circle * coarsest * coarsest * geodesic_curvature / 12;
  MESSAGE("area error after " << std::size(sizes) << " passes " << region_area(mesh, kInside) - cap << ", one deficit " << one_deficit);
  CHECK(std::abs(region_area(mesh, kInside) - cap) < one_deficit);
  // Interface vertices on the exact circle to O(h²) (the cut) — not drifting inward pass after pass.
  for (auto e : mesh.edges())
    if (mesh.interface(e))
      for (auto v : {mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)), mesh.to_vertex_handle(mesh.halfedge_handle(e, 0))})
        CHECK(std::abs(beta(mesh.point(v)) - radius) < h * h);
}

TEST_CASE("jagged fronts: no sliver survives where a noisy level set meets the boundary and itself") {
  // A fire front after many steps: the zero set of a φ with noise at the element scale, so the cut
  // leaves interface vertices a hair apart, turning by arbitrary angles, next to each other across
  // thin strips and next to boundary vertices. On this family of inputs the remesher used to leave
  // triangles of quality 1e-2 … 1e-4 (interface vertices locked as 45° corners, collapses refused
  // because every single one made some triangle worse); it must now keep them all above 0.3.
  const int n = 40;
  const double h = 1.0 / n;
  double worst = 1;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> noise(-0.4 * h, 0.4 * h);
    SurfaceMesh mesh = make_grid(n, 1.0, seed % 2 == 0);
    const long chi = euler_characteristic(mesh);
    // Three disks, two of them overlapping and one reaching past the boundary; noise of 0.4 h.
    const Vec3 centres[] = {Vec3(0.3, 0.35, 0), Vec3(0.62, 0.4, 0), Vec3(0.5, 0.92, 0)};
    ScalarField phi(mesh.n_vertices());
    for (auto v : mesh.vertices()) {
      Vec3 p = mesh.point(v);
      p[2] = 0;
      double d = 1e9;
      for (const auto& c : centres) d = std::min(d, (p - c).norm() - 0.2);
      phi[v.idx()] = d + noise(rng);
    }
    discretize(mesh, phi, EvolutionOptions{}.discretize);  // as in an evolution
    RemeshOptions options;
    options.hmax = h;
    options.feature_angle = 0;
    remesh(mesh, options);
    ValidateOptions vo;
    vo.euler_characteristic = chi;
    vo.boundary_loops = 1;
    INFO("seed " << seed);
    CHECK(problems(mesh, vo) == "");
    worst = std::min(worst, quality_stats(mesh).min);
  }
  MESSAGE("worst quality over the 12 jagged fronts: " << worst);
  CHECK(worst >= 0.3);
}

TEST_CASE("a surface far more curved than the mesh: cuts, splits and moves projected onto it never fold the mesh") {
  // A steep landscape (3 km heights over 3 km features) meshed at 800 m, whose chords sag by
  // hundreds of metres below the true surface (a 100 m mesh of the same heights): every point the
  // remesher puts on S moves far from the chord it came from. Each change must be checked against
  // the neighbouring triangles, not only against its own old normal (before: folds of 162–176°).
  const TerrainOptions fine{.extent = 20000, .h = 100, .seed = 7, .max_height = 3000, .feature_size = 3000};
  TerrainOptions coarse = fine;
  coarse.h = 800;
  auto surface = std::make_shared<const ReferenceSurface>(make_terrain(fine));
  for (unsigned seed = 1; seed <= 6; ++seed) {
    SurfaceMesh mesh = make_terrain(coarse);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> centre(6000, 14000), noise(-150, 150);
    const double cx = centre(rng), cy = centre(rng);
    ScalarField phi(mesh.n_vertices());
    for (auto v : mesh.vertices()) {
      auto p = mesh.point(v);
      phi[v.idx()] = std::hypot(p[0] - cx, p[1] - cy) - 2500 + noise(rng);
    }
    discretize(mesh, phi, EvolutionOptions{}.discretize);
    RemeshOptions options;
    options.hmax = coarse.h;
    options.feature_angle = 0;
    options.reference = surface;
    remesh(mesh, options);
    ValidateOptions vo;
    vo.euler_characteristic = 1;
    vo.boundary_loops = 1;
    INFO("seed " << seed);
    CHECK(problems(mesh, vo) == "");
  }
}

namespace {

/// A mesh from points and triangles (all outside).
SurfaceMesh build_mesh(const std::vector<Vec3>& points, const std::vector<std::array<int, 3>>& triangles) {
  SurfaceMesh mesh;
  std::vector<VertexHandle> vh;
  for (const auto& p : points) vh.push_back(mesh.add_vertex(p));
  for (const auto& t : triangles) mesh.add_face(vh[std::size_t(t[0])], vh[std::size_t(t[1])], vh[std::size_t(t[2])]);
  for (auto f : mesh.faces()) mesh.region(f) = kOutside;
  return mesh;
}

/// Rotation about the unit axis u by angle a (Rodrigues), applied to p.
Vec3 rotate(const Vec3& p, const Vec3& u, double a) {
  return p * std::cos(a) + (u % p) * std::sin(a) + u * ((u | p) * (1 - std::cos(a)));
}

}  // namespace

TEST_CASE("a cap whose apex lies on its own ridge edge is repaired: the ridge runs through the apex") {
  // The cube's ridge edge ab on the cube edge y = z = 1 loses one of its two triangles, (a, b, e), to
  // (a, c, e) + (c, b, e) + the cap (a, b, c), with c on ab: a zero-area triangle. c is required (it
  // cannot move or go), a and b slide only along the ridge: no collapse or move can repair the cap.
  // Flipping ab to cd splits (b, a, d) at c; the ridge then runs a-c-b through the same points. As
  // found on the thermal bracket (an interface vertex on a ridge, on the ridge edge of its cap). Also
  // in a rotated copy, where the cap's area is rounding noise rather than 0, and with the top side
  // z = 1 as G, so that ab is an interface edge too.
  for (int variant = 0; variant < 3; ++variant) {
    const bool rotated = variant == 1, with_interface = variant == 2;
    INFO("variant " << variant);
    const Vec3 axis = Vec3(1, 2, 3).normalized();
    const double angle = rotated ? 0.7 : 0.0;
    auto to_cube = [&](const Vec3& p) { return rotate(p, axis, -angle); };  // back to the axis-aligned cube
    SurfaceMesh cube = make_cube(6);
    std::vector<Vec3> points;
    for (auto v : cube.vertices()) points.push_back(rotate(cube.point(v), axis, angle));
    std::vector<std::array<int, 3>> triangles;
    std::vector<int> inside;
    int a = -1, b = -1;
    for (auto v : cube.vertices()) {
      Vec3 p = cube.point(v);
      if (std::abs(p[1] - 1) < 1e-12 && std::abs(p[2] - 1) < 1e-12 && std::abs(p[0] + 1.0 / 3) < 1e-12) a = v.idx();
      if (std::abs(p[1] - 1) < 1e-12 && std::abs(p[2] - 1) < 1e-12 && std::abs(p[0]) < 1e-12) b = v.idx();
    }
    REQUIRE(a >= 0);
    REQUIRE(b >= 0);
    const int c = int(points.size());
    points.push_back(points[std::size_t(a)] + (points[std::size_t(b)] - points[std::size_t(a)]) * 0.4);
    bool capped = false;
    for (auto f : cube.faces()) {
      auto vs = face_vertices(cube, f);
      std::array<int, 3> t{vs[0].idx(), vs[1].idx(), vs[2].idx()};
      const int top = with_interface && std::abs(face_normal(cube, f)[2] - 1) < 1e-9;
      // The face holding the halfedge a→b becomes (a, c, e), (c, b, e) and the cap (a, b, c).
      int k = 0;
      while (k < 3 && !(t[std::size_t(k)] == a && t[std::size_t((k + 1) % 3)] == b)) ++k;
      if (k == 3) {
        triangles.push_back(t);
        inside.push_back(top);
        continue;
      }
      const int e = t[std::size_t((k + 2) % 3)];
      triangles.push_back({a, c, e});
      triangles.push_back({c, b, e});
      triangles.push_back({a, b, c});
      inside.insert(inside.end(), 3, top);
      capped = true;
    }
    REQUIRE(capped);
    SurfaceMesh mesh = build_mesh(points, triangles);
    mesh.required(VertexHandle(c)) = 1;
    for (auto f : mesh.faces()) mesh.region(f) = inside[std::size_t(f.idx())] ? kInside : kOutside;
    // The cube's edges are ridges (as a file's Ridges; the cap is a sliver: no ridge is detected
    // next to it), the cap's sides a-c and c-b are not; the interface: between the two regions.
    auto on_cube_edge = [&](const Vec3& p) {
      Vec3 q = to_cube(p);
      int at_one = 0;
      for (int k = 0; k < 3; ++k) at_one += std::abs(std::abs(q[k]) - 1) < 1e-9;
      return at_one >= 2;
    };
    for (auto e : mesh.edges()) {
      auto h = mesh.halfedge_handle(e, 0);
      Vec3 p = mesh.point(mesh.from_vertex_handle(h)), q = mesh.point(mesh.to_vertex_handle(h));
      Vec3 pc = to_cube(p), qc = to_cube(q);
      int shared = 0;
      for (int k = 0; k < 3; ++k) shared += std::abs(std::abs(pc[k]) - 1) < 1e-9 && std::abs(pc[k] - qc[k]) < 1e-9;
      bool at_c = mesh.from_vertex_handle(h).idx() == c || mesh.to_vertex_handle(h).idx() == c;
      if (on_cube_edge(p) && on_cube_edge(q) && shared == 2 && !at_c) mesh.ridge(e) = 1;
      if (mesh.region(mesh.face_handle(h)) != mesh.region(mesh.face_handle(mesh.opposite_halfedge_handle(h)))) {
        mesh.interface(e) = 1;
        mesh.edge_ref(e) = kInterfaceRef;
      }
    }
    const Vec3 pc = mesh.point(VertexHandle(c));
    {
      auto before = validate_mesh(mesh);
      REQUIRE(!before.ok());  // the cap is degenerate
      CHECK(quality_stats(mesh).min < 1e-12);
    }

    RemeshOptions options;
    options.hmax = 2.0 / 6;
    auto report = remesh(mesh, options);

    ValidateOptions vo;
    vo.euler_characteristic = 2;
    CHECK(problems(mesh, vo) == "");
    CHECK(report.flips > 0);
    CHECK(report.min_quality > 0.3);
    // c is still there, where it was, on exactly two ridge edges, one on each side along the cube edge.
    VertexHandle vc;
    for (auto v : mesh.vertices())
      if (mesh.point(v) == pc) vc = v;
    REQUIRE(vc.is_valid());
    std::vector<Vec3> ridge_ends;
    int interface_edges = 0;
    for (auto h : mesh.voh_range(vc)) {
      if (mesh.ridge(mesh.edge_handle(h))) ridge_ends.push_back(mesh.point(mesh.to_vertex_handle(h)) - pc);
      interface_edges += mesh.interface(mesh.edge_handle(h));
    }
    REQUIRE(ridge_ends.size() == 2);
    CHECK((ridge_ends[0] | ridge_ends[1]) < 0);
    CHECK((ridge_ends[0] % ridge_ends[1]).norm() < 1e-9 * ridge_ends[0].norm() * ridge_ends[1].norm());
    // The ridges are still the cube's 12 edges, every vertex is on the cube; G is still the top side.
    double ridge_length = 0;
    for (auto e : mesh.edges())
      if (mesh.ridge(e)) ridge_length += edge_length(mesh, e);
    CHECK(ridge_length == doctest::Approx(24).epsilon(1e-9));
    for (auto v : mesh.vertices()) {
      Vec3 q = to_cube(mesh.point(v));
      CHECK(std::max({std::abs(q[0]), std::abs(q[1]), std::abs(q[2])}) == doctest::Approx(1).epsilon(1e-9));
    }
    if (with_interface) {
      CHECK(interface_edges == 2);
      CHECK(interface_curves(mesh).closed == 1);
      CHECK(region_area(mesh, kInside) == doctest::Approx(4).epsilon(1e-12));
      CHECK(interface_length(mesh) == doctest::Approx(8).epsilon(1e-12));
    }
  }
}

TEST_CASE("an interface vertex projected onto a crease of S never makes a zero-area triangle with an edge on the crease") {
  // S: a sheet folded by 30° along the x axis. The mesh: the same sheet, except that one interface
  // vertex v (also the end of a ridge-tagged edge: locked, as cut vertices on the spurious ridges of
  // the thermal bracket were) stands a little above the crease, on the triangle (k1, k0, v) whose
  // side k0k1 lies on the crease (tagged as a ridge). The remesher puts the interface on S first:
  // v's closest point on S is on the crease, on the segment k0k1, so that triangle would become a
  // zero-area one whose normal is rounding noise, which passed the orientation test by chance (in
  // 12 of the 24 rotations below). That move must be refused and no such triangle come out.
  const double bend = M_PI / 6;
  auto sheet = [&](double x, double u) {  // u < 0: the plane z = 0; u > 0: the plane bent down by 30°
    return u <= 0 ? Vec3(x, u, 0) : Vec3(x, u * std::cos(bend), -u * std::sin(bend));
  };
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uni(-1, 1);
  int refused = 0;
  for (int trial = 0; trial < 24; ++trial) {
    INFO("trial " << trial);
    Vec3 axis(uni(rng), uni(rng), uni(rng));
    axis.normalize();
    const double angle = 3 * uni(rng);
    const Vec3 shift(uni(rng), uni(rng), uni(rng));
    auto place = [&](const Vec3& p) { return rotate(p, axis, angle) + shift; };
    // S: two triangles per half.
    std::vector<Vec3> s_points;
    for (double u : {-3.0, 0.0, 3.0})
      for (double x : {-3.0, 4.0}) s_points.push_back(place(sheet(x, u)));
    auto reference = std::make_shared<const ReferenceSurface>(
        build_mesh(s_points, {{0, 1, 3}, {0, 3, 2}, {2, 3, 5}, {2, 5, 4}}));
    // The mesh: unit cells (x, u) ∈ [-3, 4] × [-3, 3], the cell [0, 1] × [-1, 0] a fan around v.
    const int nx = 8, nu = 7;
    std::vector<Vec3> points;
    for (int j = 0; j < nu; ++j)
      for (int i = 0; i < nx; ++i) points.push_back(place(sheet(i - 3, j - 3)));
    auto id = [&](int x, int u) { return (u + 3) * nx + (x + 3); };
    const int v = int(points.size());
    points.push_back(place(Vec3(0.5, 0.005, 0.05)));  // above the crease, inside the wedge of its normals
    std::vector<std::array<int, 3>> triangles;
    std::vector<int> inside;  // G: left of the curve (0, -3) … (0, -1) → v → (1, 0) … (1, 3)
    for (int u = -3; u < 3; ++u)
      for (int x = -3; x < 4; ++x) {
        const int p00 = id(x, u), p10 = id(x + 1, u), p11 = id(x + 1, u + 1), p01 = id(x, u + 1);
        if (x == 0 && u == -1) {
          // k0 = (0, 0), k1 = (1, 0), r0 = (0, -1), r1 = (1, -1)
          triangles.push_back({p01, p00, v});
          inside.push_back(1);
          triangles.push_back({p00, p10, v});
          inside.push_back(0);
          triangles.push_back({p10, p11, v});
          inside.push_back(0);
          triangles.push_back({p11, p01, v});
          inside.push_back(1);
          continue;
        }
        const int in = u < 0 ? x < 0 : x < 1;
        triangles.push_back({p00, p10, p11});
        triangles.push_back({p00, p11, p01});
        inside.push_back(in);
        inside.push_back(in);
      }
    SurfaceMesh mesh = build_mesh(points, triangles);
    for (auto f : mesh.faces()) mesh.region(f) = inside[std::size_t(f.idx())] ? kInside : kOutside;
    for (auto e : mesh.edges()) {
      auto f0 = mesh.face_handle(mesh.halfedge_handle(e, 0)), f1 = mesh.face_handle(mesh.halfedge_handle(e, 1));
      if (f0.is_valid() && f1.is_valid() && mesh.region(f0) != mesh.region(f1)) {
        mesh.interface(e) = 1;
        mesh.edge_ref(e) = kInterfaceRef;
      }
    }
    for (auto w : mesh.vertices()) {
      bool on_interface = false, in = false;
      for (auto e : mesh.ve_range(w)) on_interface |= mesh.interface(e);
      for (auto f : mesh.vf_range(w)) in |= mesh.region(f) == kInside;
      mesh.phi(w) = on_interface ? 0.0 : in ? -1.0 : 1.0;
    }
    // The crease and the edge (v, r1) are ridges (v: interface and ridge, locked).
    for (int x = -3; x < 4; ++x) mesh.ridge(mesh.edge_handle(mesh.find_halfedge(VertexHandle(id(x, 0)), VertexHandle(id(x + 1, 0))))) = 1;
    mesh.ridge(mesh.edge_handle(mesh.find_halfedge(VertexHandle(v), VertexHandle(id(1, -1))))) = 1;
    REQUIRE(problems(mesh) == "");
    const Vec3 v_before = mesh.point(VertexHandle(v));

    RemeshOptions options;
    options.hmax = 1;
    options.reference = reference;
    remesh(mesh, options);
    ValidateOptions vo;
    vo.euler_characteristic = 1;
    vo.boundary_loops = 1;
    CHECK(problems(mesh, vo) == "");
    CHECK(quality_stats(mesh).min > 1e-3);
    for (auto w : mesh.vertices()) refused += mesh.point(w) == v_before;
  }
  MESSAGE(refused << " of 24 projections onto the crease refused");
}

TEST_CASE("ridges are detected only where S has a crease too: a bump of the mesh over a flat S adds none") {
  // An evolving mesh can have sharp dihedral angles where S is smooth (triangles standing across a
  // curved wall after cuts and moves, as on the bolt holes of the thermal bracket). Tagged as ridges,
  // which are kept from step to step, they locked vertices off S and blocked the flips and collapses
  // that repair such triangles: over the steps the mesh drifted off S by up to 3 hausd, grew fins and
  // intersected itself. Here: a flat grid as S, and the mesh a copy with one vertex lifted by 1.5 h
  // (its triangles at 56° to their flat neighbours, above the 45° feature angle).
  SurfaceMesh flat = make_grid(10, 1.0);
  auto reference = std::make_shared<const ReferenceSurface>(flat);
  SurfaceMesh mesh = flat;
  VertexHandle apex;
  for (auto v : mesh.vertices())
    if ((mesh.point(v) - Vec3(0.5, 0.5, 0)).norm() < 1e-12) apex = v;
  REQUIRE(apex.is_valid());
  mesh.set_point(apex, Vec3(0.5, 0.5, 0.15));
  RemeshOptions options;
  options.hmax = 0.1;
  options.reference = reference;
  remesh(mesh, options);
  ValidateOptions vo;
  vo.euler_characteristic = 1;
  vo.boundary_loops = 1;
  CHECK(problems(mesh, vo) == "");
  std::size_t ridges = 0;
  for (auto e : mesh.edges()) ridges += mesh.ridge(e);
  CHECK(ridges == 0);
  // Where the mesh is S itself, the dihedral test alone decides: the cube's 12 edges.
  SurfaceMesh cube = make_cube(4);
  RemeshOptions cube_options;
  cube_options.hmax = 0.5;
  remesh(cube, cube_options);
  double ridge_length = 0;
  for (auto e : cube.edges())
    if (cube.ridge(e)) ridge_length += edge_length(cube, e);
  CHECK(ridge_length == doctest::Approx(24).epsilon(1e-12));
}

TEST_CASE("a faceted part: triangles never cut across its creases below the ridge angle by more than hausd") {
  // A prism of 10 facets (creases of 36°, below the 45° ridge angle: no feature) with open ends, each
  // facet a strip of long thin triangles as CAD tessellations are, coarsened 3×: the curvature
  // estimated at the vertices does not see the creases, and triangles across them would pass 8 hausd
  // from the facets.
  const int sides = 10, across = 1, along = 24;
  const double length = 2;
  SurfaceMesh mesh;
  std::vector<VertexHandle> vh;
  for (int j = 0; j <= along; ++j)
    for (int i = 0; i < sides * across; ++i) {
      const int side = i / across, k = i % across;
      auto corner = [&](int s) {
        const double angle = 2 * std::numbers::pi * s / sides;
        return Vec3(std::cos(angle), std::sin(angle), 0);
      };
      Vec3 p = corner(side) + (corner(side + 1) - corner(side)) * (double(k) / across);
      p[2] = length * j / along;
      vh.push_back(mesh.add_vertex(p));
    }
  const int ring = sides * across;
  for (int j = 0; j < along; ++j)
    for (int i = 0; i < ring; ++i) {
      auto a = vh[std::size_t(j * ring + i)], b = vh[std::size_t(j * ring + (i + 1) % ring)];
      auto c = vh[std::size_t((j + 1) * ring + (i + 1) % ring)], d = vh[std::size_t((j + 1) * ring + i)];
      mesh.add_face(a, b, c);
      mesh.add_face(a, c, d);
    }
  for (auto f : mesh.faces()) mesh.region(f) = kOutside;
  const ReferenceSurface facets(mesh);
  const double hausd = bounding_box(mesh).diagonal() / 1000;
  // How far the mesh strays from the facets: its vertices, edge middles and face centroids.
  auto strays = [&](const SurfaceMesh& m) {
    double worst = 0;
    auto from_facets = [&](const Vec3& p) { worst = std::max(worst, (facets.closest(p).point - p).norm()); };
    for (auto v : m.vertices()) from_facets(m.point(v));
    for (auto e : m.edges()) {
      auto h = m.halfedge_handle(e, 0);
      from_facets((m.point(m.from_vertex_handle(h)) + m.point(m.to_vertex_handle(h))) / 2.0);
    }
    for (auto f : m.faces()) {
      Vec3 c(0, 0, 0);
      for (auto v : m.fv_range(f)) c += m.point(v) / 3.0;
      from_facets(c);
    }
    return worst;
  };
  RemeshOptions options;
  options.hmax = 3 * edge_length_stats(mesh).mean;
  SurfaceMesh checked = mesh, unchecked = mesh;
  const auto report = remesh(checked, options);
  CHECK(report.collapses > 0);
  CHECK(problems(checked) == "");
  options.check_distance_to_reference = false;
  remesh(unchecked, options);
  const double with = strays(checked), without = strays(unchecked);
  MESSAGE("strays " << with / hausd << " hausd with the checks, " << without / hausd << " without");
  CHECK(with <= 1.5 * hausd);
  CHECK(without > 5 * hausd);  // what the checks prevent: the sizes alone do not see the creases
  CHECK(total_area(checked) == doctest::Approx(total_area(mesh)).epsilon(1e-3));
}

TEST_CASE("ReferenceSurface::max_curvature: 1/R on a fine sphere, 0 on a plane, large across a crease") {
  for (double radius : {0.5, 2.0}) {
    const ReferenceSurface sphere(make_sphere({.faces = 20000, .radius = radius}));
    CHECK(sphere.max_curvature() == doctest::Approx(1 / radius).epsilon(0.1));
  }
  CHECK(ReferenceSurface(make_grid(8, 1.0)).max_curvature() == 0);
  const ReferenceSurface cube(make_cube(4));  // 90° creases between triangles 0.5 / 3 · √5 apart at most
  CHECK(cube.max_curvature() > 3);
  CHECK(ReferenceSurface::sphere(Vec3(0, 0, 0), 4)->max_curvature() == 0.25);
}

TEST_CASE("self-intersections near some faces: exactly the pairs of the whole search that have one of them, and a limit that stops early") {
  // Two spheres crossing along a circle, as one surface.
  SurfaceMesh one = make_sphere({.faces = 2000});
  SurfaceMesh two = one;
  std::vector<VertexHandle> copy;
  for (auto v : one.vertices()) copy.push_back(two.add_vertex(one.point(v) + Vec3(0.9, 0.2, 0.1)));
  for (auto f : one.faces()) {
    std::vector<VertexHandle> corners;
    for (auto v : one.fv_range(f)) corners.push_back(copy[std::size_t(v.idx())]);
    two.add_face(corners);
  }
  const auto all = self_intersections(two);
  REQUIRE(all.size() > 100);
  CHECK(std::is_sorted(all.begin(), all.end()));
  // The same with a lone triangle far away: a box of too many cells for the table of occupied
  // cells, which the search then looks up in its grid.
  SurfaceMesh far = two;
  far.add_face(far.add_vertex(Vec3(1e4, 1e4, 1e4)), far.add_vertex(Vec3(1e4 + 0.1, 1e4, 1e4)),
               far.add_vertex(Vec3(1e4, 1e4 + 0.1, 1e4)));
  CHECK(self_intersections(far) == all);
  for (const SurfaceMesh* mesh : {&two, &far})
    for (int stride : {1, 3, 7}) {
      CAPTURE(stride);
      std::vector<int> faces;
      for (int f = 0; f < int(mesh->n_faces()); f += stride) faces.push_back(f);
      std::vector<std::pair<int, int>> expected;
      for (const auto& [f, g] : all)
        if (f % stride == 0 || g % stride == 0) expected.push_back({f, g});
      CHECK(self_intersections_near(*mesh, faces) == expected);
    }
  // A patch of one sphere only (its first 200 faces): no pair without one of them.
  std::vector<int> patch(200);
  std::iota(patch.begin(), patch.end(), 0);
  for (const auto& pair : self_intersections_near(two, patch)) CHECK((pair.first < 200 || pair.second < 200));
  const auto first = self_intersections(two, 1);
  REQUIRE(first.size() == 1);
  CHECK(std::binary_search(all.begin(), all.end(), first.front()));
}

TEST_CASE("self-intersections of a creased part are looked for, and those no operation separates are reported") {
  // Two cubes crossing each other, as one surface: the remesh cannot separate them (they are the
  // input's), and says so; one cube alone has none.
  SurfaceMesh one = make_cube(6);
  RemeshOptions options;
  options.hmax = 2.0 / 4;
  SurfaceMesh alone = one;
  CHECK(remesh(alone, options).self_intersections == 0);
  SurfaceMesh two = one;
  std::vector<VertexHandle> copy;
  for (auto v : one.vertices()) copy.push_back(two.add_vertex(one.point(v) + Vec3(1.0, 0.5, 0.3)));
  for (auto f : one.faces()) {
    std::vector<VertexHandle> corners;
    for (auto v : one.fv_range(f)) corners.push_back(copy[std::size_t(v.idx())]);
    two.region(two.add_face(corners)) = kOutside;
  }
  REQUIRE(self_intersections(two).size() > 0);
  SurfaceMesh unchecked = two;
  const auto report = remesh(two, options);
  CHECK(report.self_intersections > 0);
  CHECK(report.self_intersections == self_intersections(two).size());
  // Not looked for without the distance checks (nor on an analytic or smooth reference).
  options.check_distance_to_reference = false;
  CHECK(remesh(unchecked, options).self_intersections == 0);
  CHECK(self_intersections(unchecked).size() > 0);
}
