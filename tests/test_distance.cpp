// Signed geodesic distance: convergence against exact distances on a sphere and in a plane,
// invariants (sign, unit gradient, scale invariance), region labels vs level set, edge cases, CLI.
#include <bodyfit/distance.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/levelset_mesher.hpp>

#include <doctest/doctest.h>
#include <test_support.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

using namespace bodyfit;

namespace {

/// Not a distance: 3·(z − 0.2 + 0.1 sin 5θ), whose zero set is a wobbly curve round the sphere.
ScalarField wavy_level_set(const SurfaceMesh& mesh) {
  ScalarField phi(mesh.n_vertices());
  for (auto v : mesh.vertices()) {
    const Vec3& p = mesh.point(v);
    phi[v.idx()] = 3 * (p[2] - 0.2 + 0.1 * std::sin(5 * std::atan2(p[1], p[0])));
  }
  return phi;
}

constexpr double kCap = std::numbers::pi / 4;

double polar_angle(const Vec3& p) { return std::acos(std::clamp(p[2] / p.norm(), -1.0, 1.0)); }

/// The non-distance level set of the polar cap of angle a: cos a − z.
ScalarField cap_level_set(const SurfaceMesh& mesh) {
  ScalarField phi(mesh.n_vertices());
  for (auto v : mesh.vertices()) phi[v.idx()] = std::cos(kCap) - mesh.point(v)[2];
  return phi;
}

struct Errors {
  double h = 0, l2 = 0, linf_near = 0;
};

/// L2 error (dual cells of 1/3 of the adjacent face areas) and L∞ error where |exact| < 2h.
template <class Exact>
Errors errors(const SurfaceMesh& mesh, const ScalarField& d, Exact exact) {
  Errors e;
  e.h = edge_length_stats(mesh).mean;
  std::vector<double> dual(mesh.n_vertices(), 0.0);
  for (auto f : mesh.faces())
    for (auto v : mesh.fv_range(f)) dual[v.idx()] += face_area(mesh, f) / 3;
  double sum = 0;
  for (auto v : mesh.vertices()) {
    const double ex = exact(mesh.point(v));
    const double err = std::abs(d[v.idx()] - ex);
    sum += err * err * dual[v.idx()];
    if (std::abs(ex) < 2 * e.h) e.linf_near = std::max(e.linf_near, err);
  }
  e.l2 = std::sqrt(sum);
  return e;
}

double cap_exact(const Vec3& p) { return polar_angle(p) - kCap; }

/// The square [x0, x1] × [y0, y1] in the plane z = 0, n × n cells, each split into two right
/// triangles along alternating diagonals.
SurfaceMesh make_square(int n, double x0 = -1, double y0 = -1, double x1 = 1, double y1 = 1) {
  return test::grid_square(n, {x0, y0, x1, y1, true});
}

/// A strip of flat obtuse triangles: rows of spacing 0.35·h shifted by h/2 on odd rows, so every
/// triangle has a 110° angle.
SurfaceMesh make_obtuse_strip(int n) {
  SurfaceMesh mesh;
  const double h = 1.0 / n, dy = 0.35 * h;
  const int rows = int(1.0 / dy);
  std::vector<std::vector<VertexHandle>> v(std::size_t(rows + 1));
  for (int j = 0; j <= rows; ++j)
    for (int i = 0; i <= n; ++i) v[std::size_t(j)].push_back(mesh.add_vertex(Vec3(i * h + (j % 2) * h / 2, j * dy, 0)));
  for (int j = 0; j < rows; ++j) {
    const auto& lo = v[std::size_t(j)];
    const auto& hi = v[std::size_t(j + 1)];
    for (int i = 0; i < n; ++i) {
      if (j % 2 == 0) {  // upper row shifted right
        mesh.add_face(lo[std::size_t(i)], lo[std::size_t(i + 1)], hi[std::size_t(i)]);
        if (i + 1 < n) mesh.add_face(lo[std::size_t(i + 1)], hi[std::size_t(i + 1)], hi[std::size_t(i)]);
      } else {  // lower row shifted right
        mesh.add_face(lo[std::size_t(i)], hi[std::size_t(i + 1)], hi[std::size_t(i)]);
        if (i + 1 < n) mesh.add_face(lo[std::size_t(i)], lo[std::size_t(i + 1)], hi[std::size_t(i + 1)]);
      }
    }
  }
  return mesh;
}

ScalarField evaluate(const SurfaceMesh& mesh, auto function) {
  ScalarField values(mesh.n_vertices());
  for (auto v : mesh.vertices()) values[v.idx()] = function(mesh.point(v));
  return values;
}

double planar(const Vec3& p, double cx, double cy) { return std::hypot(p[0] - cx, p[1] - cy); }

}  // namespace

TEST_CASE("sphere cap from a non-distance level set: first order in L2, second order near the interface") {
  std::vector<Errors> all;
  // 9.7k, 39k, 155k faces. The L2 errors stay below Mshdist's (8.4e-3, 4.2e-3, 2.1e-3).
  const double mshdist_l2[] = {8.4e-3, 4.2e-3, 2.1e-3};
  for (std::size_t k : {22u, 44u, 88u}) {
    const SurfaceMesh mesh = make_sphere({.faces = 20 * k * k});
    DistanceReport report;
    const ScalarField d = signed_distance(mesh, cap_level_set(mesh), {}, &report);
    CHECK(report.has_interface);
    CHECK(report.initialised + report.marched == mesh.n_vertices());
    const Errors e = errors(mesh, d, cap_exact);
    CHECK(e.l2 < 0.16 * e.h);
    CHECK(e.linf_near < 0.4 * e.h * e.h);
    CHECK(e.l2 < mshdist_l2[all.size()]);
    all.push_back(e);
  }
  for (std::size_t i = 1; i < all.size(); ++i) {
    const double ratio = std::log(all[i - 1].h / all[i].h);
    const double l2_order = std::log(all[i - 1].l2 / all[i].l2) / ratio;
    const double near_order = std::log(all[i - 1].linf_near / all[i].linf_near) / ratio;
    INFO("sizes ", i - 1, " -> ", i, ": L2 order ", l2_order, ", near-interface order ", near_order);
    CHECK(l2_order >= 0.9);
    CHECK(near_order >= 1.8);
    CHECK(near_order <= 2.3);
  }
}

TEST_CASE("sphere cap: sign everywhere, zero only on the zero set, unit gradient away from the medial axis") {
  const SurfaceMesh mesh = make_sphere({.faces = 9680});
  const ScalarField phi = cap_level_set(mesh);
  const ScalarField d = signed_distance(mesh, phi);
  const double h = edge_length_stats(mesh).mean;
  for (auto v : mesh.vertices()) {
    const int i = v.idx();
    REQUIRE(std::isfinite(d[i]));
    CHECK((phi[i] > 0) == (d[i] > 0));
    CHECK((phi[i] < 0) == (d[i] < 0));
  }
  // The medial axis of the cap's boundary circle is the two poles.
  double worst = 0;
  for (auto f : mesh.faces()) {
    bool near_pole = false;
    for (auto v : mesh.fv_range(f)) {
      const double beta = polar_angle(mesh.point(v));
      near_pole = near_pole || beta < 4 * h || beta > std::numbers::pi - 4 * h;
    }
    if (near_pole) continue;
    worst = std::max(worst, std::abs(face_gradient(mesh, f, d).norm() - 1));
  }
  CHECK(worst < 2 * h);
}

TEST_CASE("distance from region labels equals distance from a level set that is zero on the interface edges") {
  SurfaceMesh mesh = make_sphere({.faces = 9680});
  for (auto f : mesh.faces()) {
    Vec3 centroid(0, 0, 0);
    for (auto v : mesh.fv_range(f)) centroid += mesh.point(v) / 3;
    mesh.region(f) = polar_angle(centroid) < kCap ? kInside : kOutside;
  }
  // φ = 0 on the interface vertices, −1 inside, +1 outside.
  ScalarField phi;
  auto make_phi = [&] {
    update_interface_from_regions(mesh);
    phi.assign(mesh.n_vertices(), 1.0);
    for (auto f : mesh.faces())
      if (mesh.inside(f))
        for (auto v : mesh.fv_range(f)) phi[v.idx()] = -1;
    for (auto e : mesh.edges())
      if (mesh.interface(e)) {
        phi[mesh.to_vertex_handle(mesh.halfedge_handle(e, 0)).idx()] = 0;
        phi[mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)).idx()] = 0;
      }
  };
  // The zero set of the P1 φ is exactly the interface edges only if no other edge joins two
  // interface vertices: split such edges, the new vertex (and its faces) on the side of the edge.
  make_phi();
  std::vector<EdgeHandle> notches;
  for (auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    if (!mesh.interface(e) && phi[mesh.to_vertex_handle(h).idx()] == 0 && phi[mesh.from_vertex_handle(h).idx()] == 0)
      notches.push_back(e);
  }
  for (auto e : notches) {
    const auto h = mesh.halfedge_handle(e, 0);
    const int label = mesh.region(mesh.face_handle(h));
    const Vec3 middle = (mesh.point(mesh.to_vertex_handle(h)) + mesh.point(mesh.from_vertex_handle(h))) / 2;
    const auto v = mesh.split(e, middle.normalized());
    for (auto f : mesh.vf_range(v)) mesh.region(f) = label;
  }
  make_phi();
  for (auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    if (!mesh.interface(e))
      REQUIRE_FALSE((phi[mesh.to_vertex_handle(h).idx()] == 0 && phi[mesh.from_vertex_handle(h).idx()] == 0));
  }
  DistanceReport from_labels_report;
  // The polygon of interface edges (its staircase turns are mostly sharp anyway) is the zero set
  // of the P1 φ.
  const ScalarField from_labels = signed_distance_to_region(mesh, {.curved_interface = false}, &from_labels_report);
  const ScalarField from_phi = signed_distance(mesh, phi);
  CHECK(from_labels_report.has_interface);
  double worst = 0;
  for (std::size_t i = 0; i < from_phi.size(); ++i) worst = std::max(worst, std::abs(from_labels[i] - from_phi[i]));
  CHECK(worst < 1e-12);
  // And it is the distance to the staircase interface: within a couple of edge lengths of the cap's.
  const double h = edge_length_stats(mesh).mean;
  for (auto v : mesh.vertices()) CHECK(std::abs(from_labels[v.idx()] - cap_exact(mesh.point(v))) < h);
}

/// A band β ∈ [a − 0.4, a + 0.4] of the unit sphere (β the polar angle) with rows of n vertices
/// at β = a + kΔβ, odd rows shifted by half a column so that the vertices next to the circle
/// β = a sit in front of the middle of its chords; the faces above that circle are inside.
SurfaceMesh make_cap_band(int n, double a) {
  const double dlambda = 2 * std::numbers::pi / n;
  const double dbeta = std::sqrt(3.0) / 2 * dlambda * std::sin(a);
  const int half = int(std::ceil(0.4 / dbeta));
  SurfaceMesh mesh;
  std::vector<VertexHandle> v;
  for (int j = 0; j <= 2 * half; ++j)
    for (int i = 0; i < n; ++i) {
      const double beta = a + (j - half) * dbeta, lambda = (i + 0.5 * (j % 2)) * dlambda;
      v.push_back(mesh.add_vertex(
          Vec3(std::sin(beta) * std::cos(lambda), std::sin(beta) * std::sin(lambda), std::cos(beta))));
    }
  // (row, unwrapped column) corners; ordered counter-clockwise in (β, λ), i.e. outward.
  auto add = [&](std::array<std::pair<int, int>, 3> c) {
    auto x = [](std::pair<int, int> p) { return p.second + 0.5 * (p.first % 2); };
    const double cross = (c[1].first - c[0].first) * (x(c[2]) - x(c[0])) - (x(c[1]) - x(c[0])) * (c[2].first - c[0].first);
    if (cross < 0) std::swap(c[1], c[2]);
    std::array<VertexHandle, 3> h;
    for (int k = 0; k < 3; ++k) h[k] = v[std::size_t(c[k].first * n + (c[k].second % n))];
    const auto f = mesh.add_face(h[0], h[1], h[2]);
    mesh.region(f) = std::max({c[0].first, c[1].first, c[2].first}) <= half ? kInside : kOutside;
  };
  for (int j = 0; j < 2 * half; ++j)
    for (int i = 0; i < n; ++i) {
      if (j % 2 == 0) {
        add({{{j, i}, {j, i + 1}, {j + 1, i}}});
        add({{{j, i + 1}, {j + 1, i + 1}, {j + 1, i}}});
      } else {
        add({{{j, i}, {j + 1, i + 1}, {j + 1, i}}});
        add({{{j, i}, {j, i + 1}, {j + 1, i + 1}}});
      }
    }
  update_interface_from_regions(mesh);
  return mesh;
}

TEST_CASE("region labels of a cap whose interface vertices lie on its circle: the curved interface removes the sagitta") {
  // The chords of the circle β = a lie inside it by up to the sagitta κL²/8 (geodesic curvature
  // κ = cot a): the polygon's distance carries that error, the arcs leave O(L³).
  std::vector<double> off_errors, on_errors, lengths;
  for (int n : {48, 96}) {
    const SurfaceMesh mesh = make_cap_band(n, kCap);
    const double chord = 2 * std::sin(kCap) * std::sin(std::numbers::pi / n);
    const double sagitta = chord * chord / std::tan(kCap) / 8;
    auto near_error = [&](const ScalarField& d) {
      double worst = 0;
      for (auto v : mesh.vertices()) {
        const double exact = cap_exact(mesh.point(v));
        REQUIRE((d[v.idx()] < 0) == (exact < -1e-12));
        if (std::abs(exact) < 2 * chord) worst = std::max(worst, std::abs(d[v.idx()] - exact));
      }
      return worst;
    };
    const double off = near_error(signed_distance_to_region(mesh, {.curved_interface = false}));
    const double on = near_error(signed_distance_to_region(mesh));
    INFO("n ", n, ": sagitta ", sagitta, ", polygon error ", off, ", curved error ", on);
    CHECK(off > 0.7 * sagitta);
    CHECK(on < 0.2 * off);
    off_errors.push_back(off);
    on_errors.push_back(on);
    lengths.push_back(chord);
  }
  const double ratio = std::log(lengths[0] / lengths[1]);
  const double off_order = std::log(off_errors[0] / off_errors[1]) / ratio;
  const double on_order = std::log(on_errors[0] / on_errors[1]) / ratio;
  INFO("polygon order ", off_order, ", curved order ", on_order);
  CHECK(off_order < 2.3);
  CHECK(on_order > 2.7);
}

TEST_CASE("flat square, disk region: the Euclidean distance |x − c| − r") {
  std::vector<double> l2, near;
  std::vector<double> hs;
  for (int n : {40, 80, 160}) {
    const SurfaceMesh mesh = make_square(n);
    auto exact = [](const Vec3& p) { return planar(p, 0.1, -0.05) - 0.5; };
    // A non-distance level set with the same zero set.
    const ScalarField phi = evaluate(mesh, [](const Vec3& p) {
      return (std::pow(p[0] - 0.1, 2) + std::pow(p[1] + 0.05, 2) - 0.25) * 3.7;
    });
    const ScalarField d = signed_distance(mesh, phi);
    const Errors e = errors(mesh, d, exact);
    l2.push_back(e.l2);
    near.push_back(e.linf_near);
    hs.push_back(e.h);
    for (auto v : mesh.vertices()) REQUIRE(std::abs(d[v.idx()] - exact(mesh.point(v))) < 2 * e.h);
  }
  for (std::size_t i = 1; i < l2.size(); ++i) {
    const double ratio = std::log(hs[i - 1] / hs[i]);
    INFO("L2 ", l2[i], " near ", near[i]);
    CHECK(l2[i] < 0.1 * hs[i]);
    CHECK(std::log(near[i - 1] / near[i]) / ratio >= 1.8);
  }
}

TEST_CASE("region labels: carrying the front's curvature makes the far field second order (plane disk, sphere cap)") {
  // The planar update errs by O(h²κ) per step where the front is curved, which accumulates to a
  // first-order error far from the interface; circular fronts whose curvature follows the Riccati
  // equation (κ' = −κ² − K) remove it. Regions come from cutting the exact level set (no snapping).
  auto study = [](auto make_mesh, auto level_set, auto exact, const std::vector<int>& sizes, double min_order) {
    std::vector<double> hs, on, off;
    for (int n : sizes) {
      SurfaceMesh mesh = make_mesh(n);
      discretize(mesh, evaluate(mesh, level_set), {.snap_ratio = 0});
      hs.push_back(edge_length_stats(mesh).mean);
      on.push_back(errors(mesh, signed_distance_to_region(mesh), exact).l2);
      off.push_back(errors(mesh, signed_distance_to_region(mesh, {.front_curvature = false}), exact).l2);
    }
    for (std::size_t i = 1; i < sizes.size(); ++i) {
      const double ratio = std::log(hs[i - 1] / hs[i]);
      const double order_on = std::log(on[i - 1] / on[i]) / ratio, order_off = std::log(off[i - 1] / off[i]) / ratio;
      MESSAGE("h " << hs[i] << ": L2 " << on[i] << " (order " << order_on << ") against planar " << off[i]
                   << " (order " << order_off << ")");
      CHECK(order_on > min_order);
      CHECK(order_on > order_off + 0.3);
      CHECK(on[i] < 0.35 * off[i]);
    }
  };
  SUBCASE("plane, disk of radius 0.5") {
    // Measured order 1.4 then 1.15 (planar 0.7, 0.8), 4.6× smaller at h = 0.014: the far field
    // outside the disk converges at about first order on this right-triangle grid, not understood yet.
    study([](int n) { return make_square(n); },
          [](const Vec3& p) { return planar(p, 0.1, -0.05) - 0.5; },
          [](const Vec3& p) { return planar(p, 0.1, -0.05) - 0.5; }, {40, 80, 160}, 1.1);
  }
  SUBCASE("unit sphere, cap of polar angle π/4") {
    // Measured order 1.74 then 2.14 (planar 1.3, 1.0), 6.9× smaller at 39k faces.
    study([](int n) { return make_sphere({.faces = std::size_t(n)}); }, cap_exact, cap_exact, {2420, 9680, 38720},
          1.6);
  }
}

TEST_CASE("flat square, two disjoint disks: the minimum of the two distances") {
  const SurfaceMesh mesh = make_square(120);
  auto exact = [](const Vec3& p) { return std::min(planar(p, -0.5, -0.4) - 0.3, planar(p, 0.45, 0.4) - 0.4); };
  const ScalarField phi = evaluate(mesh, [](const Vec3& p) {
    return std::min(std::pow(p[0] + 0.5, 2) + std::pow(p[1] + 0.4, 2) - 0.09,
                    std::pow(p[0] - 0.45, 2) + std::pow(p[1] - 0.4, 2) - 0.16);
  });
  const ScalarField d = signed_distance(mesh, phi);
  const Errors e = errors(mesh, d, exact);
  // The zero set of the P1 interpolant is within O(h²/r) of the circle: the near-field bound scales
  // with the curvature of the smaller disk.
  CHECK(e.l2 < 0.2 * e.h);
  CHECK(e.linf_near < 0.25 * e.h * e.h / 0.3);
  for (auto v : mesh.vertices()) {
    CHECK(std::abs(d[v.idx()] - exact(mesh.point(v))) < 1.5 * e.h);
    CHECK((d[v.idx()] < 0) == (exact(mesh.point(v)) < 0));
  }
}

TEST_CASE("open surface: a disk cut by the boundary, the boundary is not an interface") {
  // The square [0, 1]² with a disk centred on its left side: G meets the boundary of S.
  const SurfaceMesh mesh = make_square(100, 0, 0, 1, 1);
  auto exact = [](const Vec3& p) { return planar(p, 0.0, 0.5) - 0.3; };
  const ScalarField d = signed_distance(mesh, evaluate(mesh, exact));
  const Errors e = errors(mesh, d, exact);
  CHECK(e.linf_near < 0.25 * e.h * e.h / 0.3);
  for (auto v : mesh.vertices()) {
    const double ex = exact(mesh.point(v));
    CHECK(std::abs(d[v.idx()] - ex) < 1.5 * e.h);
    if (mesh.is_boundary(v) && std::abs(ex) > e.h) CHECK(std::abs(d[v.idx()]) > 0.5 * std::abs(ex));
  }
}

TEST_CASE("level set exactly zero at vertices and along whole edges: a straight line, exact") {
  const SurfaceMesh mesh = make_square(50);
  // x = 0.2 is a grid column: φ is zero on a chain of edges; on the right-triangle mesh the planar
  // update is exact for a straight front.
  const ScalarField phi = evaluate(mesh, [](const Vec3& p) { return 5 * (p[0] - 0.2); });
  DistanceReport report;
  const ScalarField d = signed_distance(mesh, phi, {}, &report);
  CHECK(report.has_interface);
  for (auto v : mesh.vertices()) {
    const double ex = mesh.point(v)[0] - 0.2;
    CHECK(d[v.idx()] == doctest::Approx(ex).epsilon(1e-12).scale(1));
    if (phi[v.idx()] == 0) CHECK(d[v.idx()] == 0);
  }
}

TEST_CASE("obtuse triangles: the unfolding keeps a straight front exact") {
  const SurfaceMesh mesh = make_obtuse_strip(30);
  REQUIRE(quality_stats(mesh).max < 0.8);  // every triangle is obtuse
  // A slanted line: the front reaches the vertices at their 110° corners, so every update needs
  // the unfolding (without it, edge updates would be off by O(1)).
  const Vec3 normal = Vec3(1, 2, 0).normalized();
  auto exact = [&](const Vec3& p) { return (p | normal) - 0.9; };
  DistanceReport report;
  const ScalarField d = signed_distance(mesh, evaluate(mesh, exact), {}, &report);
  // Where the straight characteristic leaves the strip the geodesic bends around the end of the
  // line, and the march's stencil (the virtual triangle between the 35° edge and the unfolded
  // vertex above) carries that into the cone between the characteristic and the 35° edge. Check
  // the vertices below the line whose foot point and 35° ray both stay inside the strip.
  const Vec3 edge = Vec3(0.5, 0.35, 0).normalized();
  double worst = 0;
  std::size_t checked = 0;
  for (auto v : mesh.vertices()) {
    const Vec3 p = mesh.point(v);
    const double e = exact(p);
    if (mesh.is_isolated(v) || e >= 0 || p[0] < 0.05) continue;
    const Vec3 foot = p - normal * e, along_edge = p + edge * (-e / (edge | normal));
    if (std::max(foot[0], along_edge[0]) > 0.95 || std::max(foot[1], along_edge[1]) > 0.95) continue;
    ++checked;
    worst = std::max(worst, std::abs(d[v.idx()] - e));
  }
  CHECK(checked > 1000);
  CHECK(worst < 1e-10);
}

TEST_CASE("scale invariance: φ and 1000·φ give the same distance") {
  const SurfaceMesh mesh = make_sphere({.faces = 2420});
  const ScalarField phi = cap_level_set(mesh);
  ScalarField scaled = phi;
  for (double& value : scaled) value *= 1000;
  const ScalarField a = signed_distance(mesh, phi), b = signed_distance(mesh, scaled);
  for (std::size_t i = 0; i < a.size(); ++i) CHECK(a[i] == doctest::Approx(b[i]).epsilon(1e-12).scale(1));
}

TEST_CASE("narrow band: values within the band are unchanged, beyond it ±infinity") {
  const SurfaceMesh mesh = make_sphere({.faces = 2420});
  const ScalarField phi = cap_level_set(mesh);
  const ScalarField full = signed_distance(mesh, phi);
  const ScalarField band = signed_distance(mesh, phi, {.narrow_band = 0.3});
  for (std::size_t i = 0; i < full.size(); ++i) {
    if (std::abs(full[i]) <= 0.3) CHECK(band[i] == full[i]);
    else CHECK(band[i] == (full[i] > 0 ? 1 : -1) * std::numeric_limits<double>::infinity());
  }
}

TEST_CASE("no crossing: ±infinity everywhere and has_interface false") {
  SurfaceMesh mesh = make_sphere({.faces = 320});
  const double inf = std::numeric_limits<double>::infinity();
  DistanceReport report;
  for (double d : signed_distance(mesh, ScalarField(mesh.n_vertices(), 2.5), {}, &report)) CHECK(d == inf);
  CHECK_FALSE(report.has_interface);
  report = {};
  for (double d : signed_distance(mesh, ScalarField(mesh.n_vertices(), -1e-3), {}, &report)) CHECK(d == -inf);
  CHECK_FALSE(report.has_interface);
  for (auto f : mesh.faces()) mesh.region(f) = kOutside;
  update_interface_from_regions(mesh);
  report = {};
  for (double d : signed_distance_to_region(mesh, {}, &report)) CHECK(d == inf);
  CHECK_FALSE(report.has_interface);
  for (auto f : mesh.faces()) mesh.region(f) = kInside;
  for (double d : signed_distance_to_region(mesh)) CHECK(d == -inf);
  CHECK_THROWS(signed_distance(mesh, ScalarField(3, 1.0)));
}

TEST_CASE("CLI: bodyfit distance writes the library's values") {
  test::TempDir dir("distance_cli");
  SurfaceMesh mesh = make_sphere({.faces = 2420});
  const ScalarField phi = cap_level_set(mesh);
  for (auto f : mesh.faces()) {
    bool in = true;
    for (auto v : mesh.fv_range(f)) in = in && phi[v.idx()] < 0.05;
    mesh.region(f) = in ? kInside : kOutside;
  }
  update_interface_from_regions(mesh);
  write_mesh(mesh, dir / "s.mesh");
  write_scalar_sol(dir / "phi.sol", phi);
  const SurfaceMesh reread = read_mesh(dir / "s.mesh");
  REQUIRE(reread.n_vertices() == mesh.n_vertices());

  auto result = test::run_bodyfit("distance " + (dir / "s.mesh").string() + " --phi " + (dir / "phi.sol").string() +
                                  " -o " + (dir / "d.sol").string());
  INFO(result.output);
  REQUIRE(result.exit_code == 0);
  const ScalarField expected = signed_distance(reread, read_scalar_sol(dir / "phi.sol", reread.n_vertices()));
  const ScalarField written = read_scalar_sol(dir / "d.sol", mesh.n_vertices());
  for (std::size_t i = 0; i < written.size(); ++i) CHECK(written[i] == doctest::Approx(expected[i]).epsilon(1e-9));

  result = test::run_bodyfit("distance " + (dir / "s.mesh").string() + " --region 3 -o " + (dir / "r.sol").string());
  INFO(result.output);
  REQUIRE(result.exit_code == 0);
  const ScalarField from_region = signed_distance_to_region(reread);
  const ScalarField written_region = read_scalar_sol(dir / "r.sol", mesh.n_vertices());
  for (std::size_t i = 0; i < written_region.size(); ++i)
    CHECK(written_region[i] == doctest::Approx(from_region[i]).epsilon(1e-9));

  result = test::run_bodyfit("distance " + (dir / "s.mesh").string() + " -o " + (dir / "x.sol").string());
  CHECK(result.exit_code == 1);
}

TEST_CASE("DistanceSolver::redistance: the whole-mesh signed distance within the band, nothing beyond") {
  const SurfaceMesh mesh = make_sphere({.faces = 9680});
  const double h = edge_length_stats(mesh).mean;
  // Not a distance: a wavy, scaled level set whose zero set is a wobbly curve round the sphere.
  const ScalarField phi = wavy_level_set(mesh);
  const ScalarField exact = signed_distance(mesh, phi);
  const double width = 6 * h;
  // `near`: a superset of the vertices of the faces where φ changes sign.
  std::vector<int> near;
  for (auto v : mesh.vertices())
    if (std::abs(exact[v.idx()]) <= 2 * h) near.push_back(v.idx());
  DistanceSolver solver(mesh);
  for (int round = 0; round < 2; ++round) {  // the second call reuses the solver's arrays
    ScalarField band_phi = phi;
    const std::vector<int> band = solver.redistance(band_phi, width, near);
    std::vector<int> expected;
    for (auto v : mesh.vertices())
      if (std::abs(exact[v.idx()]) <= width) expected.push_back(v.idx());
    CHECK(band == expected);
    double worst = 0;
    std::size_t untouched = 0;
    for (auto v : mesh.vertices()) {
      const int i = v.idx();
      if (std::binary_search(band.begin(), band.end(), i)) worst = std::max(worst, std::abs(band_phi[i] - exact[i]));
      else untouched += band_phi[i] == phi[i];
    }
    CHECK(worst <= 1e-12);
    CHECK(untouched == mesh.n_vertices() - band.size());
    CHECK(band.size() < mesh.n_vertices() / 2);  // a band, not the mesh
  }
}

namespace {
/// Where φ's P1 zero set crosses each edge whose ends have opposite signs (edge index → fraction
/// from its first vertex): the zero set, as the cut will see it.
std::vector<std::pair<int, double>> crossings(const SurfaceMesh& mesh, const ScalarField& phi) {
  std::vector<std::pair<int, double>> out;
  for (auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    const double a = phi[mesh.from_vertex_handle(h).idx()], b = phi[mesh.to_vertex_handle(h).idx()];
    if (a * b < 0) out.emplace_back(e.idx(), a / (a - b));
  }
  return out;
}

double largest_shift(const std::vector<std::pair<int, double>>& x, const std::vector<std::pair<int, double>>& y) {
  if (x.size() != y.size()) return std::numeric_limits<double>::infinity();  // edges gained or lost
  double worst = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (x[i].first != y[i].first) return std::numeric_limits<double>::infinity();
    worst = std::max(worst, std::abs(x[i].second - y[i].second));
  }
  return worst;
}
}  // namespace

TEST_CASE("keep_crossings: redistancing leaves the zero set where it was, the far field as without it") {
  const SurfaceMesh mesh = make_sphere({.faces = 9680});
  const double h = edge_length_stats(mesh).mean;
  // A curved zero set and a φ that is not a distance: the exact initialisation re-places the
  // crossings by O(h²κ) (what CFL sub-steps used to add up), keep_crossings must not move them.
  const ScalarField phi = wavy_level_set(mesh);
  const auto before = crossings(mesh, phi);
  REQUIRE(before.size() > 50);
  DistanceOptions keep;
  keep.keep_crossings = true;
  const ScalarField moved = signed_distance(mesh, phi), kept = signed_distance(mesh, phi, keep);
  // Without it the zero set moves (so this test can tell), with it not at all.
  CHECK(largest_shift(before, crossings(mesh, moved)) > 1e-3);
  CHECK(largest_shift(before, crossings(mesh, kept)) == 0.0);
  // Only the vertices of crossed faces keep φ; every other vertex has the distance.
  std::vector<char> on_crossed_face(mesh.n_vertices(), 0);
  for (auto f : mesh.faces()) {
    double lo = 1e300, hi = -1e300;
    for (auto v : mesh.fv_range(f)) lo = std::min(lo, phi[v.idx()]), hi = std::max(hi, phi[v.idx()]);
    if (lo < 0 && hi > 0)
      for (auto v : mesh.fv_range(f)) on_crossed_face[v.idx()] = 1;
  }
  std::size_t kept_count = 0, differ = 0;
  for (auto v : mesh.vertices()) {
    const int i = v.idx();
    if (on_crossed_face[i]) kept_count += kept[i] == phi[i];
    else differ += kept[i] != moved[i];
  }
  CHECK(kept_count == std::size_t(std::count(on_crossed_face.begin(), on_crossed_face.end(), 1)));
  CHECK(differ == 0);

  // The band version, called again and again as the sub-steps do: the crossings never move, while
  // re-placing them drifts further with every call.
  std::vector<int> near;
  for (auto v : mesh.vertices())
    if (std::abs(moved[v.idx()]) <= 2 * h) near.push_back(v.idx());
  DistanceSolver solver(mesh);
  ScalarField band_kept = phi, band_moved = phi;
  for (int call = 0; call < 5; ++call) {
    solver.redistance(band_kept, 6 * h, near, nullptr, keep);
    solver.redistance(band_moved, 6 * h, near);
  }
  CHECK(largest_shift(before, crossings(mesh, band_kept)) == 0.0);
  CHECK(largest_shift(before, crossings(mesh, band_moved)) > 1e-3);
}
