// discretize(): marching triangles of the zero level set, checked against exact crossing points,
// exact areas (second-order convergence), topology of the interface, and the validity checker on
// many random level sets.
#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/levelset_mesher.hpp>
#include <bodyfit/validate.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>
#include <test_support.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>

using namespace bodyfit;

namespace {

constexpr double pi = std::numbers::pi;

/// The unit square [0, 1]² cut into n × n cells, each split along its (0,0)-(1,1) diagonal,
/// oriented with normals +z.
SurfaceMesh make_square(int n) { return test::grid_square(n); }

ScalarField sample(const SurfaceMesh& mesh, const std::function<double(const Vec3&)>& f) {
  ScalarField values(mesh.n_vertices());
  for (auto v : mesh.vertices()) values[v.idx()] = f(mesh.point(v));
  return values;
}

/// Polar angle from the +z axis.
double polar_angle(const Vec3& p) { return std::acos(std::clamp(p[2] / p.norm(), -1.0, 1.0)); }

ValidateOptions strict(long euler, std::size_t loops) {
  ValidateOptions options;
  options.check_phi_on_interface = true;
  options.euler_characteristic = euler;
  options.boundary_loops = loops;
  return options;
}

void require_valid(const SurfaceMesh& mesh, const ValidateOptions& options) {
  auto report = validate_mesh(mesh, options);
  INFO(report.summary());
  REQUIRE(report.ok());
}

/// Vertices of the mesh on an interface edge.
std::vector<VertexHandle> interface_vertices(const SurfaceMesh& mesh) {
  std::vector<char> on(mesh.n_vertices(), 0);
  for (auto e : mesh.edges())
    if (mesh.interface(e))
      for (int s = 0; s < 2; ++s) on[mesh.to_vertex_handle(mesh.halfedge_handle(e, s)).idx()] = 1;
  std::vector<VertexHandle> result;
  for (auto v : mesh.vertices())
    if (on[v.idx()]) result.push_back(v);
  return result;
}

double min_quality(const SurfaceMesh& mesh) { return quality_stats(mesh).min; }

}  // namespace

TEST_CASE("spherical cap: with linear crossings, the points are exactly the zeros of the linear interpolant") {
  SurfaceMesh mesh = make_sphere({.faces = 5120});
  const std::size_t n0 = mesh.n_vertices();
  ScalarField phi = sample(mesh, [](const Vec3& p) { return polar_angle(p) - pi / 4; });
  // Expected crossing points, computed from the original edges.
  std::vector<Vec3> expected;
  for (auto e : mesh.edges()) {
    auto h = mesh.halfedge_handle(e, 0);
    auto a = mesh.from_vertex_handle(h), b = mesh.to_vertex_handle(h);
    double fa = phi[a.idx()], fb = phi[b.idx()];
    if (fa * fb < 0) expected.push_back(mesh.point(a) + fa / (fa - fb) * (mesh.point(b) - mesh.point(a)));
  }
  REQUIRE(expected.size() > 50);

  auto report = discretize(mesh, phi, {.snap_ratio = 0, .hermite_crossings = false});
  require_valid(mesh, strict(2, 0));
  CHECK(report.crossed_edges == expected.size());
  CHECK(report.inserted_vertices == expected.size());
  CHECK(mesh.n_vertices() == n0 + expected.size());
  auto curves = interface_curves(mesh);
  CHECK(curves.closed == 1);
  CHECK(curves.open == 0);
  // Every inserted vertex is one expected point (they are distinct), every interface vertex is new.
  auto on_interface = interface_vertices(mesh);
  CHECK(on_interface.size() == expected.size());
  for (auto v : on_interface) {
    CHECK(std::size_t(v.idx()) >= n0);
    double nearest = 1e300;
    for (const auto& p : expected) nearest = std::min(nearest, (mesh.point(v) - p).norm());
    CHECK(nearest < 1e-15);
    CHECK(mesh.phi(v) == 0);
  }
  // Original vertices keep φ; faces are labelled by the sign of φ at their vertices.
  for (std::size_t i = 0; i < n0; ++i) CHECK(mesh.phi(VertexHandle(int(i))) == phi[i]);
  for (auto f : mesh.faces()) {
    double lo = 1e300, hi = -1e300;
    for (auto v : mesh.fv_range(f)) lo = std::min(lo, mesh.phi(v)), hi = std::max(hi, mesh.phi(v));
    CHECK(lo * hi >= 0);
    CHECK(mesh.region(f) == (lo < 0 ? kInside : kOutside));
  }
  CHECK(region_components(mesh, kInside) == 1);
  CHECK(region_components(mesh, kOutside) == 1);
}

TEST_CASE("spherical cap: Hermite crossings are an order of magnitude closer to the level set than linear ones") {
  // φ = β − π/4 sampled at the vertices; the exact cut is the circle β = π/4. A chord point p has
  // the polar angle of its radial projection, so |β(p) − π/4| is its angular distance to the circle.
  auto worst_error = [](std::size_t faces, bool hermite) {
    SurfaceMesh mesh = make_sphere({.faces = faces});
    ScalarField phi = sample(mesh, [](const Vec3& p) { return polar_angle(p) - pi / 4; });
    discretize(mesh, phi, {.snap_ratio = 0, .hermite_crossings = hermite});
    double worst = 0;
    for (auto v : interface_vertices(mesh)) worst = std::max(worst, std::abs(polar_angle(mesh.point(v)) - pi / 4));
    return std::pair{worst, edge_length_stats(mesh).mean};
  };
  const auto [linear_coarse, h_coarse] = worst_error(5120, false);
  const auto [linear_fine, h_fine] = worst_error(20480, false);
  const auto [hermite_coarse, h2] = worst_error(5120, true);
  const auto [hermite_fine, h3] = worst_error(20480, true);
  const double ratio = h_coarse / h_fine;
  MESSAGE("linear " << linear_coarse << " -> " << linear_fine << ", Hermite " << hermite_coarse << " -> " << hermite_fine);
  CHECK(std::log(linear_coarse / linear_fine) / std::log(ratio) > 1.7);
  // Both second order (the vertex gradients limit the cubic), the Hermite constant ≈ 30× smaller.
  CHECK(std::log(hermite_coarse / hermite_fine) / std::log(ratio) > 1.7);
  CHECK(hermite_coarse < 0.1 * linear_coarse);
  CHECK(hermite_fine < 0.1 * linear_fine);
}

namespace {

/// make_square(20) with every interior vertex moved by up to a quarter edge (a fixed seed): an
/// irregular mesh, on which the averaged face gradients are only first order.
SurfaceMesh jittered_square() {
  SurfaceMesh mesh = make_square(20);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> shift(-0.0125, 0.0125);
  for (auto v : mesh.vertices())
    if (!mesh.is_boundary(v)) {
      const double dx = shift(random), dy = shift(random);
      mesh.set_point(v, mesh.point(v) + Vec3(dx, dy, 0));
    }
  return mesh;
}

}  // namespace

TEST_CASE("fitted Hermite slopes: exact for a quadratic φ on an irregular mesh, refused across a kink") {
  // φ = |p − c|² − r²: the quadratic through two rings reproduces it, so along every edge the cubic
  // Hermite interpolant is φ itself and its zero is on the circle to rounding; the averaged face
  // gradients are off by O(h) on this mesh and so are the cut points (by O(h²)).
  const Vec3 centre(0.5, 0.5, 0);
  auto circle = [&](const Vec3& p) { return (p - centre).sqrnorm() - 0.09; };
  auto worst_offset = [&](bool fitted, DiscretizeReport& report) {
    SurfaceMesh mesh = jittered_square();
    const ScalarField phi = sample(mesh, circle);
    DiscretizeOptions options;
    options.snap_ratio = 0, options.fitted_slopes = fitted;
    report = discretize(mesh, phi, options);
    double worst = 0;
    for (auto v : interface_vertices(mesh)) worst = std::max(worst, std::abs((mesh.point(v) - centre).norm() - 0.3));
    return worst;
  };
  DiscretizeReport fitted_report, face_report;
  const double fitted = worst_offset(true, fitted_report), faces = worst_offset(false, face_report);
  MESSAGE("circle on a jittered grid: cut points off the circle by " << fitted << " (fitted) and " << faces << " (faces)");
  CHECK(fitted < 1e-12);
  CHECK(faces > 1e-6);
  CHECK(fitted_report.refused_fits == 0);
  CHECK(fitted_report.fitted_slopes > 0);
  CHECK(face_report.fitted_slopes + face_report.refused_fits == 0);

  // φ = |x − 1/2| − 0.03, a band 1.2 edges wide: linear on each side of its ridge x = 1/2, so a fit
  // whose rings stay on one side is exact (residual 0, accepted), and only the vertices whose two
  // rings straddle the ridge can be refused — some must be, or the kink would go undetected.
  SurfaceMesh mesh = jittered_square();
  const ScalarField phi = sample(mesh, [](const Vec3& p) { return std::abs(p[0] - 0.5) - 0.03; });
  std::size_t ends = 0, straddling = 0;
  for (auto v : mesh.vertices()) {
    bool crossed = false;
    for (auto w : mesh.vv_range(v)) crossed = crossed || (phi[v.idx()] < 0) != (phi[w.idx()] < 0);
    if (!crossed) continue;
    ++ends;
    bool left = false, right = false;
    for (auto w : mesh.vv_range(v))
      for (auto x : mesh.vv_range(w)) (mesh.point(x)[0] < 0.5 ? left : right) = true;
    straddling += left && right;
  }
  DiscretizeOptions options;
  options.snap_ratio = 0;
  const DiscretizeReport report = discretize(mesh, phi, options);
  MESSAGE("band: " << report.refused_fits << " fits refused of " << ends << " (" << straddling << " straddle the ridge)");
  CHECK(report.fitted_slopes + report.refused_fits == ends);
  CHECK(report.refused_fits > 0);
  CHECK(report.refused_fits <= straddling);
}

TEST_CASE("Hermite and linear crossings agree when φ is affine along the edges") {
  SurfaceMesh a = test::grid_square(12), b = test::grid_square(12);
  ScalarField phi = sample(a, [](const Vec3& p) { return 0.7 * p[0] - 0.4 * p[1] - 0.1234; });
  discretize(a, phi, {.snap_ratio = 0, .hermite_crossings = true});
  discretize(b, phi, {.snap_ratio = 0, .hermite_crossings = false});
  REQUIRE(a.n_vertices() == b.n_vertices());
  double worst = 0;
  for (auto v : a.vertices()) worst = std::max(worst, (a.point(v) - b.point(v)).norm());
  CHECK(worst < 1e-14);
}

// The cutting rules alone, with snapping at 5 % of an edge (mmgs-like) and every part kept: the
// defaults (snap at 1e-3, specks removed) are those of the evolution, tested through it.
const DiscretizeOptions kSnapping{.snap_ratio = 0.05, .speck_area = 0};

TEST_CASE("spherical cap: region areas converge to the exact cap area at order 2") {
  const double a = pi / 4;
  const double cap = 2 * pi * (1 - std::cos(a)), rest = 4 * pi - cap;
  std::vector<double> inside_error, outside_error;
  for (std::size_t faces : {5120u, 20480u, 81920u}) {
    SurfaceMesh mesh = make_sphere({.faces = faces});
    const SurfaceMesh original = mesh;
    auto phi = sample(mesh, [&](const Vec3& p) { return polar_angle(p) - a; });
    discretize(mesh, phi, {.snap_ratio = 0});
    require_valid(mesh, strict(2, 0));
    inside_error.push_back(std::abs(region_area(mesh, kInside) - cap));
    outside_error.push_back(std::abs(region_area(mesh, kOutside) - rest));

    // Snapping only relabels parts of the faces around the snapped vertices.
    SurfaceMesh snapped = original;
    auto report = discretize(snapped, phi, kSnapping);
    require_valid(snapped, strict(2, 0));
    CHECK(report.snapped_vertices > 0);
    double star_area = 0;
    for (auto v : original.vertices())
      if (snapped.phi(v) == 0)
        for (auto f : original.vf_range(v)) star_area += face_area(original, f);
    CHECK(std::abs(region_area(snapped, kInside) - region_area(mesh, kInside)) <= star_area);
  }
  for (int k = 0; k < 2; ++k) {
    CAPTURE(k);
    CHECK(inside_error[std::size_t(k)] / inside_error[std::size_t(k) + 1] == doctest::Approx(4).epsilon(0.15));
    CHECK(outside_error[std::size_t(k)] / outside_error[std::size_t(k) + 1] == doctest::Approx(4).epsilon(0.15));
  }
}

TEST_CASE("two disks on a flat square: separate, then merged when they overlap") {
  const int n = 64;
  const double h = 1.0 / n, r = 0.2;
  for (double gap : {0.5, 0.3}) {  // distance between the centres: 2r = 0.4
    CAPTURE(gap);
    SurfaceMesh mesh = make_square(n);
    Vec3 c1(0.5 - gap / 2, 0.5, 0), c2(0.5 + gap / 2, 0.5, 0);
    auto phi = sample(mesh, [&](const Vec3& p) { return std::min((p - c1).norm(), (p - c2).norm()) - r; });
    discretize(mesh, phi);
    require_valid(mesh, strict(1, 1));
    auto curves = interface_curves(mesh);
    CHECK(curves.open == 0);
    bool merged = gap < 2 * r;
    CHECK(curves.closed == (merged ? 1 : 2));
    CHECK(region_components(mesh, kInside) == (merged ? 1 : 2));
    CHECK(region_components(mesh, kOutside) == 1);
    double exact = 2 * pi * r * r;
    if (merged) exact -= 2 * r * r * std::acos(gap / (2 * r)) - gap / 2 * std::sqrt(4 * r * r - gap * gap);
    // Chords of length s ≤ √2 h cut circular segments of area ≈ s³/(12r): the polygon misses at
    // most π s²/6 per circle, and snapping moves the curve by ≤ 5 % of an edge at a few vertices.
    CHECK(std::abs(region_area(mesh, kInside) - exact) < 2 * (pi * 2 * h * h / 6 + 2 * pi * r * 0.05 * h * 0.05));
    CHECK(total_area(mesh) == doctest::Approx(1.0).epsilon(1e-13));
  }
}

TEST_CASE("level set through vertices: zero vertices are used, nothing inserted next to them") {
  const int n = 16;
  const double h = 1.0 / n;
  SUBCASE("a grid line: no crossing at all") {
    SurfaceMesh mesh = make_square(n);
    auto report = discretize(mesh, sample(mesh, [](const Vec3& p) { return p[0] - 0.5; }));
    require_valid(mesh, strict(1, 1));
    CHECK(report.inserted_vertices == 0);
    CHECK(mesh.n_faces() == std::size_t(2 * n * n));
    CHECK(interface_length(mesh) == doctest::Approx(1.0).epsilon(1e-14));
    CHECK(region_area(mesh, kInside) == doctest::Approx(0.5).epsilon(1e-14));
    auto curves = interface_curves(mesh);
    CHECK(curves.open == 1);
    CHECK(curves.closed == 0);
  }
  SUBCASE("the cell diagonals") {
    SurfaceMesh mesh = make_square(n);
    auto report = discretize(mesh, sample(mesh, [](const Vec3& p) { return p[0] - p[1]; }));
    require_valid(mesh, strict(1, 1));
    CHECK(report.inserted_vertices == 0);
    CHECK(interface_length(mesh) == doctest::Approx(std::sqrt(2.0)).epsilon(1e-14));
    CHECK(region_area(mesh, kInside) == doctest::Approx(0.5).epsilon(1e-14));
  }
  SUBCASE("a line through every other vertex of its path, crossing edges in between") {
    SurfaceMesh mesh = make_square(n);
    const std::size_t n0 = mesh.n_vertices();
    auto line = [](const Vec3& p) { return p[0] + 2 * p[1] - 1; };
    auto phi = sample(mesh, line);
    std::vector<Vec3> zeros;
    for (auto v : mesh.vertices())
      if (phi[v.idx()] == 0) zeros.push_back(mesh.point(v));
    REQUIRE(zeros.size() == 9);  // (1 − 2j/n, j/n), j = 0..8
    auto report = discretize(mesh, phi);
    require_valid(mesh, strict(1, 1));
    CHECK(report.snapped_vertices == 0);
    CHECK(report.inserted_vertices > 0);
    for (std::size_t i = n0; i < mesh.n_vertices(); ++i) {
      Vec3 p = mesh.point(VertexHandle(int(i)));
      CHECK(std::abs(line(p)) < 1e-15);
      for (const auto& z : zeros) CHECK((p - z).norm() > 0.25 * h);
    }
    auto curves = interface_curves(mesh);
    CHECK(curves.open == 1);
    CHECK(region_area(mesh, kInside) == doctest::Approx(0.25).epsilon(1e-13));
  }
}

TEST_CASE("level sets crossing and touching the boundary of an open surface") {
  const int n = 32;
  SUBCASE("a quarter disk around a corner: one open curve") {
    SurfaceMesh mesh = make_square(n);
    discretize(mesh, sample(mesh, [](const Vec3& p) { return p.norm() - 0.5; }));
    require_valid(mesh, strict(1, 1));
    auto curves = interface_curves(mesh);
    CHECK(curves.open == 1);
    CHECK(curves.closed == 0);
    // Interface ends are on boundary edges, at x = 0.5 and y = 0.5.
    int ends = 0;
    for (auto v : interface_vertices(mesh))
      if (mesh.is_boundary(v)) {
        ++ends;
        Vec3 p = mesh.point(v);
        CHECK(p.norm() == doctest::Approx(0.5).epsilon(1e-12));
      }
    CHECK(ends == 2);
  }
  SUBCASE("a band across the square: two open curves, an inside strip") {
    SurfaceMesh mesh = make_square(n);
    discretize(mesh, sample(mesh, [](const Vec3& p) { return std::abs(p[1] - 0.51) - 0.2; }));
    require_valid(mesh, strict(1, 1));
    auto curves = interface_curves(mesh);
    CHECK(curves.open == 2);
    CHECK(region_area(mesh, kInside) == doctest::Approx(0.4).epsilon(1e-12));
    CHECK(region_components(mesh, kOutside) == 2);
  }
  SUBCASE("a disk touching the boundary edge from inside at one vertex") {
    SurfaceMesh mesh = make_square(n);
    // φ = 0 exactly at (0.5, 0) and positive at the other boundary vertices.
    discretize(mesh, sample(mesh, [](const Vec3& p) { return (p - Vec3(0.5, 0.25, 0)).norm() - 0.25; }));
    require_valid(mesh, strict(1, 1));
    CHECK(interface_curves(mesh).closed == 1);
  }
}

TEST_CASE("several components on a sphere") {
  SurfaceMesh mesh = make_sphere({.faces = 5120});
  std::vector<Vec3> centres{Vec3(0, 0, 1), Vec3(1, 0, 0), Vec3(0, -1, 0), Vec3(0, 0, -1)};
  auto phi = sample(mesh, [&](const Vec3& p) {
    double d = 1e300;
    for (const auto& c : centres) d = std::min(d, std::acos(std::clamp(OpenMesh::dot(p.normalized(), c), -1.0, 1.0)) - 0.5);
    return d;
  });
  discretize(mesh, phi);
  require_valid(mesh, strict(2, 0));
  CHECK(interface_curves(mesh).closed == 4);
  CHECK(interface_curves(mesh).open == 0);
  CHECK(region_components(mesh, kInside) == 4);
  CHECK(region_components(mesh, kOutside) == 1);
}

TEST_CASE("no crossing: one label everywhere, old interface tags removed, tags kept") {
  SurfaceMesh mesh = make_sphere({.faces = 1280});
  // A first cut leaves an interface; a level set with no zero must remove it.
  discretize(mesh, sample(mesh, [](const Vec3& p) { return p[2] - 0.1; }));
  REQUIRE(interface_length(mesh) > 0);
  for (double sign : {1.0, -1.0}) {
    const std::size_t faces = mesh.n_faces(), vertices = mesh.n_vertices();
    auto report = discretize(mesh, ScalarField(mesh.n_vertices(), sign));
    require_valid(mesh, strict(2, 0));
    CHECK(report.crossed_edges == 0);
    CHECK(report.interface_edges == 0);
    CHECK(mesh.n_faces() == faces);
    CHECK(mesh.n_vertices() == vertices);
    for (auto f : mesh.faces()) CHECK(mesh.region(f) == (sign < 0 ? kInside : kOutside));
    for (auto e : mesh.edges()) CHECK(mesh.edge_ref(e) != kInterfaceRef);
  }
}

TEST_CASE("split edges keep ridge, required and ref tags on both halves, orientation is kept") {
  SurfaceMesh mesh = make_square(8);
  // Tag the boundary edges and the line y = 0.5 as ridges, the line x = 0.25 as required.
  for (auto e : mesh.edges()) {
    auto h = mesh.halfedge_handle(e, 0);
    Vec3 a = mesh.point(mesh.from_vertex_handle(h)), b = mesh.point(mesh.to_vertex_handle(h));
    if (a[1] == 0.5 && b[1] == 0.5) mesh.ridge(e) = 1, mesh.edge_ref(e) = 7;
    if (a[0] == 0.25 && b[0] == 0.25) mesh.required(e) = 1;
    if (mesh.is_boundary(e)) mesh.edge_ref(e) = 4;
  }
  auto phi = sample(mesh, [](const Vec3& p) { return (p - Vec3(0.3, 0.45, 0)).norm() - 0.3; });
  auto report = discretize(mesh, phi, {.snap_ratio = 0});
  require_valid(mesh, strict(1, 1));
  REQUIRE(report.inserted_vertices > 0);
  double ridge_length = 0, required_length = 0, boundary_ref_length = 0;
  for (auto e : mesh.edges()) {
    auto h = mesh.halfedge_handle(e, 0);
    Vec3 a = mesh.point(mesh.from_vertex_handle(h)), b = mesh.point(mesh.to_vertex_handle(h));
    bool on_ridge_line = a[1] == 0.5 && b[1] == 0.5, on_required_line = a[0] == 0.25 && b[0] == 0.25;
    CHECK(bool(mesh.ridge(e)) == on_ridge_line);
    CHECK(bool(mesh.required(e)) == on_required_line);
    if (mesh.ridge(e)) {
      ridge_length += edge_length(mesh, e);
      CHECK(mesh.edge_ref(e) == 7);
    }
    if (mesh.required(e)) required_length += edge_length(mesh, e);
    if (mesh.is_boundary(e)) {
      boundary_ref_length += edge_length(mesh, e);
      CHECK(mesh.edge_ref(e) == 4);
    }
  }
  CHECK(ridge_length == doctest::Approx(1.0).epsilon(1e-14));
  CHECK(required_length == doctest::Approx(1.0).epsilon(1e-14));
  CHECK(boundary_ref_length == doctest::Approx(4.0).epsilon(1e-14));
  for (auto f : mesh.faces()) CHECK(face_normal(mesh, f)[2] == doctest::Approx(1.0));
}

TEST_CASE("snapping: a level set passing within a hair of vertices makes no sliver") {
  const int n = 16;
  const double h = 1.0 / n;
  // A slanted line shifted so that it passes 1e-4·h from a column of vertices.
  auto phi_of = [&](const Vec3& p) { return p[0] - 0.5 - 1e-4 * h + 0.01 * (p[1] - 0.5); };
  SurfaceMesh reference = make_square(n);
  const double q0 = min_quality(reference);
  const double r = kSnapping.snap_ratio;
  // Every piece of a face cut at fractions in [r, 1 − r] has area ≥ r²·A and edges ≤ its longest
  // edge L, hence quality ≥ 4√3 r² A / (3 L²) ≥ r² q0 / 3.
  const double bound = r * r * q0 / 3;

  SurfaceMesh unsnapped = make_square(n);
  discretize(unsnapped, sample(unsnapped, phi_of), {.snap_ratio = 0});
  CHECK(min_quality(unsnapped) < bound);  // the test can fail: without snapping, slivers appear

  SurfaceMesh mesh = make_square(n);
  auto report = discretize(mesh, sample(mesh, phi_of), kSnapping);
  require_valid(mesh, strict(1, 1));
  CHECK(report.snapped_vertices > 0);
  CHECK(report.rejected_snaps == 0);
  CHECK(min_quality(mesh) >= bound);
  for (auto v : mesh.vertices())
    if (mesh.phi(v) == 0 && std::size_t(v.idx()) < reference.n_vertices())
      // Only vertices within r of a crossing snap: |φ(v)| < r |φ(v) − φ(w)| ≤ r |∇φ| √2 h.
      CHECK(std::abs(phi_of(mesh.point(v))) < r * std::sqrt(1 + 0.01 * 0.01) * std::sqrt(2.0) * h);
  CHECK(interface_curves(mesh).open == 1);
}

namespace {

/// φ = c + Σ aₖ exp(−|x − xₖ|² / (2σₖ²)) with random centres on the given points, random signs.
ScalarField random_gaussians(const SurfaceMesh& mesh, std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<VertexHandle> all(mesh.vertices().begin(), mesh.vertices().end());
  int count = 1 + int(unit(rng) * 6);
  std::vector<Vec3> centre;
  std::vector<double> amplitude, sigma;
  for (int k = 0; k < count; ++k) {
    centre.push_back(mesh.point(all[std::size_t(unit(rng) * double(all.size())) % all.size()]));
    amplitude.push_back((unit(rng) < 0.5 ? -1 : 1) * (0.5 + unit(rng)));
    sigma.push_back(scale * (0.1 + 0.4 * unit(rng)));
  }
  double offset = 0.3 * (unit(rng) - 0.5);
  return sample(mesh, [&](const Vec3& p) {
    double value = offset;
    for (int k = 0; k < count; ++k)
      value += amplitude[std::size_t(k)] * std::exp(-(p - centre[std::size_t(k)]).sqrnorm() / (2 * sigma[std::size_t(k)] * sigma[std::size_t(k)]));
    return value;
  });
}

/// Run discretize on `mesh` and check everything that must hold for any level set.
DiscretizeReport check_random_cut(SurfaceMesh mesh, const ScalarField& phi, long euler, std::size_t loops,
                                  const std::function<bool(const SurfaceMesh&, FaceHandle)>& oriented) {
  const double area = total_area(mesh), q0 = min_quality(mesh);
  const std::size_t n0 = mesh.n_vertices();
  auto report = discretize(mesh, phi, kSnapping);
  require_valid(mesh, strict(euler, loops));
  CHECK(report.pinched_vertices == 0);
  CHECK(total_area(mesh) == doctest::Approx(area).epsilon(1e-12));
  CHECK(region_area(mesh, kInside) + region_area(mesh, kOutside) == doctest::Approx(area).epsilon(1e-12));
  if (report.rejected_snaps == 0 && report.separated_vertices == 0)
    CHECK(min_quality(mesh) >= kSnapping.snap_ratio * kSnapping.snap_ratio * q0 / 3);
  for (auto f : mesh.faces()) CHECK(oriented(mesh, f));
  // φ is kept, snapped to 0, or (separated vertices) moved from 0 to the positive side.
  std::size_t separated = 0;
  for (std::size_t i = 0; i < n0; ++i) {
    double now = mesh.phi(VertexHandle(int(i)));
    bool moved_out = phi[i] == 0 && now > 0;
    separated += moved_out;
    CHECK((now == phi[i] || now == 0 || moved_out));
  }
  CHECK(separated == report.separated_vertices);
  return report;
}

}  // namespace

TEST_CASE("a saddle of φ exactly at a vertex: the two inside parts are separated there") {
  const int n = 16;
  const double h = 1.0 / n;
  SurfaceMesh mesh = make_square(n);
  // Inside: the quadrants x, y > 1/2 and x, y < 1/2, which meet at the centre vertex, where four
  // interface edges would meet. The centre moves to φ = h² (geometric mean of its negative
  // neighbours (±h, ±h)), and the cut crosses the two diagonal edges at their midpoints.
  auto report = discretize(mesh, sample(mesh, [](const Vec3& p) { return -(p[0] - 0.5) * (p[1] - 0.5); }));
  require_valid(mesh, strict(1, 1));
  CHECK(report.separated_vertices == 1);
  CHECK(report.inserted_vertices == 2);
  CHECK(region_components(mesh, kInside) == 2);
  CHECK(interface_curves(mesh).open == 2);
  CHECK(interface_curves(mesh).closed == 0);
  CHECK(region_area(mesh, kInside) == doctest::Approx(0.5 - h * h).epsilon(1e-13));
  for (auto v : mesh.vertices())
    if (mesh.point(v) == Vec3(0.5, 0.5, 0)) CHECK(mesh.phi(v) == doctest::Approx(h * h).epsilon(1e-14));
}

TEST_CASE("two inside parts meeting at a boundary vertex are separated there") {
  const int n = 16;
  const double h = 1.0 / n;
  SurfaceMesh mesh = make_square(n);
  // Inside: below the parabola y = 3(x − 1/2)², which touches the boundary y = 0 at a vertex.
  auto report = discretize(mesh, sample(mesh, [](const Vec3& p) { return p[1] - 3 * (p[0] - 0.5) * (p[0] - 0.5); }));
  require_valid(mesh, strict(1, 1));
  CHECK(report.separated_vertices == 1);
  CHECK(region_components(mesh, kInside) == 2);
  CHECK(interface_curves(mesh).open == 2);
  for (auto v : mesh.vertices())
    if (mesh.point(v) == Vec3(0.5, 0, 0)) CHECK(mesh.phi(v) == doctest::Approx(3 * h * h).epsilon(1e-14));
}

TEST_CASE("random level sets never produce an invalid mesh") {
  std::mt19937 rng(20261122);
  SUBCASE("sphere") {
    const SurfaceMesh sphere = make_sphere({.faces = 2420});
    auto outward = [](const SurfaceMesh& m, FaceHandle f) {
      auto p = face_points(m, f);
      return OpenMesh::dot(face_normal(m, f), p[0] + p[1] + p[2]) > 0;
    };
    for (int trial = 0; trial < 60; ++trial) {
      CAPTURE(trial);
      check_random_cut(sphere, random_gaussians(sphere, rng, 1.0), 2, 0, outward);
    }
  }
  SUBCASE("plane") {
    const SurfaceMesh square = make_square(40);
    auto upward = [](const SurfaceMesh& m, FaceHandle f) { return face_normal(m, f)[2] > 0.999; };
    for (int trial = 0; trial < 60; ++trial) {
      CAPTURE(trial);
      check_random_cut(square, random_gaussians(square, rng, 0.5), 1, 1, upward);
    }
  }
  SUBCASE("plane, φ rounded so that many vertices and edges are exactly at zero") {
    const SurfaceMesh square = make_square(40);
    std::size_t separated = 0;
    auto upward = [](const SurfaceMesh& m, FaceHandle f) { return face_normal(m, f)[2] > 0.999; };
    for (int trial = 0; trial < 60; ++trial) {
      CAPTURE(trial);
      // Rounding to a coarse step makes plateaus of zeros, whole edges and faces at zero, saddles.
      auto phi = sample(square, [&](const Vec3& p) { return std::round(8 * (p[0] + 0.3 * p[1] - 0.6)) / 8; });
      if (trial > 0) {
        auto random = random_gaussians(square, rng, 0.5);
        for (std::size_t i = 0; i < phi.size(); ++i) phi[i] = std::round(4 * (phi[i] + 0.5 * random[i])) / 4;
      }
      separated += check_random_cut(square, phi, 1, 1, upward).separated_vertices;
    }
    CHECK(separated > 0);  // saddles at zero vertices occurred and were handled
  }
}

TEST_CASE("bodyfit discretize: cut (and remesh) from Medit files") {
  test::TempDir dir("discretize_cli");
  SurfaceMesh sphere = make_sphere({.faces = 1280});
  write_mesh(sphere, dir / "sphere.mesh");
  write_scalar_sol(dir / "phi.sol", sample(sphere, [](const Vec3& p) { return polar_angle(p) - 1.0; }));

  auto cut = test::run_bodyfit("discretize " + (dir / "sphere.mesh").string() + " --phi " + (dir / "phi.sol").string() +
                               " --no-remesh -o " + (dir / "cut.mesh").string());
  INFO(cut.output);
  REQUIRE(cut.exit_code == 0);
  SurfaceMesh mesh = read_mesh(dir / "cut.mesh");
  require_valid(mesh, strict(2, 0));
  CHECK(mesh.n_faces() > sphere.n_faces());
  CHECK(interface_curves(mesh).closed == 1);

  auto remeshed = test::run_bodyfit("discretize " + (dir / "sphere.mesh").string() + " --phi " +
                                    (dir / "phi.sol").string() + " -o " + (dir / "out.mesh").string());
  INFO(remeshed.output);
  REQUIRE(remeshed.exit_code == 0);
  SurfaceMesh out = read_mesh(dir / "out.mesh");
  ValidateOptions options;
  options.euler_characteristic = 2;
  options.boundary_loops = 0;
  require_valid(out, options);
  CHECK(interface_curves(out).closed == 1);

  auto wrong = test::run_bodyfit("discretize " + (dir / "sphere.mesh").string() + " --phi " +
                                 (dir / "sphere.mesh").string() + " -o " + (dir / "bad.mesh").string());
  CHECK(wrong.exit_code != 0);
  CHECK(!std::filesystem::exists(dir / "bad.mesh"));
}

TEST_CASE("bad level sets are input errors, deleted elements are collected") {
  SurfaceMesh mesh = make_sphere({.faces = 320});
  CHECK_THROWS_AS(discretize(mesh, ScalarField(mesh.n_vertices() - 1, 1.0)), InputError);
  ScalarField phi = sample(mesh, [](const Vec3& p) { return p[2]; });
  phi[5] = std::nan("");
  CHECK_THROWS_AS(discretize(mesh, phi), InputError);

  // A face deleted (leaving a hole) before the cut: the result is garbage-collected and valid.
  mesh.delete_face(*mesh.faces().begin(), false);
  auto report = discretize(mesh, sample(mesh, [](const Vec3& p) { return p[2] - 0.2; }));
  CHECK(report.inserted_vertices > 0);
  require_valid(mesh, strict(1, 1));
  CHECK(mesh.n_faces() >= 319 + report.split_faces);  // each cut face becomes 2 or 3
}

TEST_CASE("the quad of a two-crossing cut gets the diagonal whose worse triangle is better") {
  for (auto values : {std::pair{1.0, 3.0}, std::pair{3.0, 1.0}, std::pair{1.0, 9.0}, std::pair{9.0, 1.0},
                      std::pair{0.5, 2.0}, std::pair{2.0, 0.5}}) {
    const double phi_b = values.first, phi_c = values.second;  // not a structured binding: CAPTURE (clang 14)
    CAPTURE(phi_b);
    CAPTURE(phi_c);
    SurfaceMesh mesh;
    Vec3 A(0, 0, 0), B(1, 0, 0), C(0, 1, 0);
    auto a = mesh.add_vertex(A);  // separate statements: argument evaluation order is unspecified
    auto b = mesh.add_vertex(B);
    auto c = mesh.add_vertex(C);
    mesh.add_face(a, b, c);
    discretize(mesh, {-1.0, phi_b, phi_c}, {.snap_ratio = 0, .speck_area = 0});
    require_valid(mesh, strict(1, 1));
    REQUIRE(mesh.n_faces() == 3);
    Vec3 P = A + (1 / (1 + phi_b)) * (B - A), Q = A + (1 / (1 + phi_c)) * (C - A);
    double with_pc = std::min(triangle_quality(P, B, C), triangle_quality(P, C, Q));
    double with_bq = std::min(triangle_quality(P, B, Q), triangle_quality(B, C, Q));
    REQUIRE(with_pc != with_bq);
    double worst = 1;
    for (auto f : mesh.faces()) worst = std::min(worst, face_quality(mesh, f));
    // The corner triangle (A, P, Q) is fixed; the quad's two triangles are the better pair.
    CHECK(worst == doctest::Approx(std::min(triangle_quality(A, P, Q), std::max(with_pc, with_bq))).epsilon(1e-12));
    int quad_triangles_at_best = 0;
    for (auto f : mesh.faces())
      if (!mesh.inside(f)) quad_triangles_at_best += face_quality(mesh, f) >= std::max(with_pc, with_bq) * (1 - 1e-12);
    CHECK(quad_triangles_at_best == 2);
    CHECK(interface_length(mesh) == doctest::Approx((P - Q).norm()).epsilon(1e-14));
  }
}

TEST_CASE("vertices the remesher cannot move snap with fixed_snap_ratio, free vertices do not") {
  const int n = 16;
  const double h = 1.0 / n;
  // A vertical line 1e-3·h right of the column x = 0.5: it passes a hair from the two boundary
  // vertices (0.5, 0) and (0.5, 1) and from the 15 interior vertices between them.
  auto phi_of = [&](const Vec3& p) { return p[0] - 0.5 - 1e-3 * h; };
  auto on_column = [&](const Vec3& p) { return std::abs(p[0] - 0.5) < 1e-12; };
  for (double fixed : {0.05, 0.0}) {
    CAPTURE(fixed);
    SurfaceMesh mesh = make_square(n);
    const std::size_t n0 = mesh.n_vertices();
    auto report = discretize(mesh, sample(mesh, phi_of), {.snap_ratio = 0, .fixed_snap_ratio = fixed});
    require_valid(mesh, strict(1, 1));
    CHECK(report.snapped_vertices == (fixed > 0 ? 2u : 0u));
    for (std::size_t i = 0; i < n0; ++i) {
      const VertexHandle v{int(i)};
      if (!on_column(mesh.point(v))) continue;
      const bool boundary = mesh.is_boundary(v);
      CHECK((mesh.phi(v) == 0) == (boundary && fixed > 0));
    }
    // The interface still runs from boundary to boundary as one curve.
    CHECK(interface_curves(mesh).open == 1);
  }
}

TEST_CASE("grown_from: a new part that does not meet the old region goes to the outside, whatever its size") {
  // The old region: a disk. The new one: the disk grown, a blob 4 h across ahead of it that does
  // not meet the old disk, and a larger blob that overlaps it. With grown_from (the old disk's
  // distance) the far blob is given to the outside; the rest stays as without.
  const int n = 48;
  const double h = 1.0 / n;
  const Vec3 centre(0.3, 0.5, 0), far(0.8, 0.5, 0), overlap(0.3, 0.72, 0);
  auto old_distance = [&](const Vec3& p) { return (p - centre).norm() - 0.15; };
  auto grown = [&](const Vec3& p) {
    return std::min({(p - centre).norm() - 0.2, (p - far).norm() - 2 * h, (p - overlap).norm() - 0.1});
  };
  SurfaceMesh kept = make_square(n);
  const DiscretizeReport kept_report = discretize(kept, sample(kept, grown));
  CHECK(kept_report.removed_detached == 0);
  CHECK(region_components(kept, kInside) == 2);

  SurfaceMesh mesh = make_square(n);
  const ScalarField from = sample(mesh, old_distance);
  DiscretizeOptions options;
  options.grown_from = from;
  const DiscretizeReport report = discretize(mesh, sample(mesh, grown), options);
  require_valid(mesh, strict(1, 1));
  CHECK(report.removed_detached == 1);
  CHECK(region_components(mesh, kInside) == 1);
  CHECK(region_components(mesh, kOutside) == 1);
  CHECK(interface_curves(mesh).closed == 1);
  // What went is the far blob: π (2h)², to the polygon's chords.
  CHECK(region_area(kept, kInside) - region_area(mesh, kInside) == doctest::Approx(pi * 4 * h * h).epsilon(0.05));
  for (auto v : mesh.vertices()) {
    bool inside_face = false, outside_face = false;
    for (auto f : mesh.vf_range(v)) (mesh.region(f) == kInside ? inside_face : outside_face) = true;
    if (!outside_face) CHECK(mesh.phi(v) <= 0);
    if (!inside_face) CHECK(mesh.phi(v) >= 0);
  }
  // grown_from must have one value per vertex of the input.
  SurfaceMesh other = make_square(n / 2);
  CHECK_THROWS_AS(discretize(other, sample(other, grown), options), InputError);
}

TEST_CASE("specks: parts of a region below speck_area·h² go to the region around them") {
  const int n = 32;
  const double h = 1.0 / n, r = 0.2;
  const Vec3 centre(0.5, 0.5, 0);
  // A disk, an inside island of a fraction of a cell far from it, and a hole of the same size in
  // the disk: without speck removal three interface curves, with it one.
  // Each is a disk of radius 0.15 h centred 0.05 h from a vertex: only that vertex changes sign,
  // and the cut around it encloses 0.06 h² (h the mean edge length).
  const Vec3 island(27 * h + 0.04 * h, 5 * h + 0.03 * h, 0), hole(16 * h + 0.04 * h, 16 * h + 0.03 * h, 0);
  const double speck = 0.15 * h;
  auto phi_of = [&](const Vec3& p) {
    double disk = (p - centre).norm() - r;
    double speck_in = (p - island).norm() - speck, speck_out = speck - (p - hole).norm();
    return std::min(std::max(disk, speck_out), speck_in);
  };
  SurfaceMesh kept = make_square(n);
  auto kept_report = discretize(kept, sample(kept, phi_of), {.speck_area = 0});
  require_valid(kept, strict(1, 1));
  CHECK(kept_report.removed_specks == 0);
  CHECK(interface_curves(kept).closed == 3);

  SurfaceMesh mesh = make_square(n);
  auto report = discretize(mesh, sample(mesh, phi_of), {.speck_area = 0.1});
  require_valid(mesh, strict(1, 1));
  CHECK(report.removed_specks == 2);
  CHECK(interface_curves(mesh).closed == 1);
  CHECK(region_components(mesh, kInside) == 1);
  CHECK(region_components(mesh, kOutside) == 1);
  // Each speck was under 0.1 h²: the inside area moves by less than that per speck.
  CHECK(std::abs(region_area(mesh, kInside) - region_area(kept, kInside)) < 2 * 0.1 * h * h);
  // φ agrees with the labels: negative only where a face is inside.
  for (auto v : mesh.vertices()) {
    bool inside_face = false, outside_face = false;
    for (auto f : mesh.vf_range(v)) (mesh.region(f) == kInside ? inside_face : outside_face) = true;
    if (!outside_face) CHECK(mesh.phi(v) <= 0);
    if (!inside_face) CHECK(mesh.phi(v) >= 0);
  }
}

TEST_CASE("specks: a speck area above the whole surface's gives G away once and stops") {
  // Every part is then a speck: G goes to the region around it, and the surface, one region with
  // nothing around it, is not given back (the two used to trade places without end).
  const int n = 16;
  SurfaceMesh mesh = make_square(n);
  const auto phi = sample(mesh, [](const Vec3& p) { return (p - Vec3(0.5, 0.5, 0)).norm() - 0.2; });
  const auto report = discretize(mesh, phi, {.speck_area = 1e300});
  require_valid(mesh, strict(1, 1));
  CHECK(report.removed_specks == 1);
  CHECK(region_components(mesh, kInside) == 0);
  CHECK(region_area(mesh, kOutside) == doctest::Approx(1.0));
}

TEST_CASE("specks: the threshold is the part's area, however far the search stops") {
  // Two single-vertex islands of φ < 0 with linear crossings: each encloses t² times the star of
  // its vertex, t = a / (a + b) the crossings' fraction. One is set just under speck_area·h², the
  // other just over; a large disk is kept. The search of each part stops once its area reaches the
  // threshold: stopping early or late moves a part to the wrong side of it.
  const int n = 24;
  SurfaceMesh mesh = make_square(n);
  const double h = edge_length_stats(mesh).mean, threshold = 0.1 * h * h;
  auto vertex_near = [&](double x, double y) {
    VertexHandle best;
    double best_d = 1e30;
    for (auto v : mesh.vertices())
      if (double d = (mesh.point(v) - Vec3(x, y, 0)).norm(); d < best_d) best_d = d, best = v;
    return best;
  };
  const VertexHandle small = vertex_near(0.25, 0.75), large = vertex_near(0.75, 0.75);
  auto star_area = [&](VertexHandle v) {
    double area = 0;
    for (auto f : mesh.vf_range(v)) area += face_area(mesh, f);
    return area;
  };
  const double b = 1.0;  // φ at every other vertex near the islands
  ScalarField phi(mesh.n_vertices(), b);
  auto island = [&](VertexHandle v, double area) {
    const double t = std::sqrt(area / star_area(v));  // a/(a+b) = t
    phi[v.idx()] = -t * b / (1 - t);
  };
  island(small, 0.97 * threshold);
  island(large, 1.03 * threshold);
  for (auto v : mesh.vertices())  // and a disk of radius 0.2 around (0.5, 0.25)
    if (double d = (mesh.point(v) - Vec3(0.5, 0.25, 0)).norm() - 0.2; d < 0.3) phi[v.idx()] = d;
  const DiscretizeOptions linear{.hermite_crossings = false, .speck_area = 0.1};
  SurfaceMesh kept = mesh;
  discretize(kept, phi, {.hermite_crossings = false, .speck_area = 0});
  REQUIRE(region_components(kept, kInside) == 3);
  const auto report = discretize(mesh, phi, linear);
  require_valid(mesh, strict(1, 1));
  CHECK(report.removed_specks == 1);
  CHECK(region_components(mesh, kInside) == 2);
  // The part given away is the smaller one: the inside lost 0.97·threshold.
  CHECK(region_area(kept, kInside) - region_area(mesh, kInside) == doctest::Approx(0.97 * threshold).epsilon(1e-6));
  for (auto f : mesh.vf_range(large)) CHECK(mesh.region(f) == kInside);
  for (auto f : mesh.vf_range(small)) CHECK(mesh.region(f) == kOutside);
}
