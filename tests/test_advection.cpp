// Advection by characteristics: exact solutions (translation on a plane, expansion along e_β on the
// sphere, rigid rotation), inflow through an open boundary, paths through vertices and along edges,
// determinism across thread counts, and the `bodyfit advect` command.
#include <bodyfit/advection.hpp>
#include <bodyfit/band_advector.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>
#include <test_support.hpp>

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <functional>

using namespace bodyfit;

namespace {

/// The unit square [0, 1]² in the plane z = 0, n × n cells, each cut along its (1, 1) diagonal.
SurfaceMesh make_square(int n) { return test::grid_square(n); }

ScalarField sample(const SurfaceMesh& mesh, const std::function<double(const Vec3&)>& f) {
  ScalarField values(mesh.n_vertices());
  for (auto v : mesh.vertices()) values[v.idx()] = f(mesh.point(v));
  return values;
}

VectorField sample_vector(const SurfaceMesh& mesh, const std::function<Vec3(const Vec3&)>& f) {
  VectorField values(mesh.n_vertices());
  for (auto v : mesh.vertices()) values[v.idx()] = f(mesh.point(v));
  return values;
}

double polar_angle(const Vec3& p) { return std::acos(std::clamp(p[2] / p.norm(), -1.0, 1.0)); }

Vec3 e_beta(const Vec3& p) {
  const double b = polar_angle(p), a = std::atan2(p[1], p[0]);
  return Vec3(std::cos(a) * std::cos(b), std::sin(a) * std::cos(b), -std::sin(b));
}

/// Area of {φ < 0} for the P1 interpolant of φ (each face clipped exactly).
double negative_area(const SurfaceMesh& mesh, const ScalarField& phi) {
  double area = 0;
  for (auto f : mesh.faces()) {
    const auto v = face_vertices(mesh, f);
    const double full = face_area(mesh, f);
    int negative = 0;
    for (auto vh : v) negative += phi[vh.idx()] < 0;
    if (negative == 0) continue;
    if (negative == 3) {
      area += full;
      continue;
    }
    // The lone vertex on one side cuts off a similar corner triangle.
    const bool lone_negative = negative == 1;
    int lone = 0;
    for (int i = 0; i < 3; ++i)
      if ((phi[v[i].idx()] < 0) == lone_negative) lone = i;
    const double a = phi[v[lone].idx()], b = phi[v[(lone + 1) % 3].idx()], c = phi[v[(lone + 2) % 3].idx()];
    const double corner = full * (a / (a - b)) * (a / (a - c));
    area += lone_negative ? corner : full - corner;
  }
  return area;
}

/// Band error of the e_β expansion on a geodesic sphere of frequency k: φ0 = β − π/4, T = π/4.
struct BandError {
  double l2 = 0, h = 0;
  std::size_t lost = 0;
};
BandError expansion_error(int k, bool through_normal_speed, int rk = 2) {
  const SurfaceMesh mesh = make_sphere({.faces = std::size_t(20 * k * k)});
  const double a = M_PI / 4, T = M_PI / 4;
  const ScalarField phi = sample(mesh, [&](const Vec3& p) { return polar_angle(p) - a; });
  AdvectionOptions options;
  options.rk_order = rk;
  AdvectionReport report;
  const ScalarField result =
      through_normal_speed
          ? advect_normal(mesh, phi, ScalarField(mesh.n_vertices(), 1.0), T, options, &report)
          : advect(mesh, phi, sample_vector(mesh, e_beta), T, options, &report);
  BandError e;
  for (auto f : mesh.faces()) {
    const double third = face_area(mesh, f) / 3;
    for (auto v : mesh.fv_range(f)) {
      const double beta = polar_angle(mesh.point(v));
      if (std::abs(beta - M_PI / 2) >= 0.25) continue;
      const double error = result[v.idx()] - (beta - a - T);
      e.l2 += third * error * error;
    }
  }
  e.l2 = std::sqrt(e.l2);
  e.h = edge_length_stats(mesh).mean;
  e.lost = report.lost;
  return e;
}

/// A cap of angular radius 0.5 centred at polar angle π/3 carried once around the z-axis.
struct RotationResult {
  double interface_error = 0;  ///< max |φ(T) − φ0| over the vertices near the interface
  double area_before = 0, area_after = 0, h = 0;
  std::size_t lost = 0;
};
RotationResult rotate_cap(int k, int rk, double cells = 1.0) {
  const SurfaceMesh mesh = make_sphere({.faces = std::size_t(20 * k * k)});
  const Vec3 centre(std::sin(M_PI / 3), 0, std::cos(M_PI / 3));
  const ScalarField phi = sample(mesh, [&](const Vec3& p) {
    return std::acos(std::clamp(OpenMesh::dot(p.normalized(), centre), -1.0, 1.0)) - 0.5;
  });
  const VectorField velocity = sample_vector(mesh, [](const Vec3& p) { return OpenMesh::cross(Vec3(0, 0, 1), p); });
  AdvectionOptions options;
  options.rk_order = rk;
  options.max_cells_per_substep = cells;
  AdvectionReport report;
  const ScalarField result = advect(mesh, phi, velocity, 2 * M_PI, options, &report);
  RotationResult r;
  for (std::size_t i = 0; i < phi.size(); ++i)
    if (std::abs(phi[i]) < 0.1) r.interface_error = std::max(r.interface_error, std::abs(result[i] - phi[i]));
  r.area_before = negative_area(mesh, phi);
  r.area_after = negative_area(mesh, result);
  r.h = edge_length_stats(mesh).mean;
  r.lost = report.lost;
  return r;
}

}  // namespace

TEST_CASE("translation on a plane reproduces an affine level set exactly, whatever the direction") {
  // Directions along the horizontal edges, along the diagonals, straight through vertices, and
  // generic ones; backwards the paths leave through the boundary, where the (affine) boundary values
  // are also exact.
  const SurfaceMesh mesh = make_square(20);
  auto phi0 = [](double x, double y) { return 0.3 + 2 * x - y; };
  const ScalarField phi = sample(mesh, [&](const Vec3& p) { return phi0(p[0], p[1]); });
  const std::vector<Vec3> directions = {{1, 0, 0},  {0, 1, 0},   {1, 1, 0},      {-1, -1, 0},
                                        {2, 1, 0},  {1, 2, 0},   {-2, 1, 0},     {0.37, 0.11, 0},
                                        {-1, 0, 0}, {0.5, -1, 0}, {-0.23, 0.41, 0}};
  for (const Vec3& direction : directions) {
    CAPTURE(direction);
    const Vec3 V = 0.35 * direction;
    const double T = 0.8;
    AdvectionReport report;
    const ScalarField result = advect(mesh, phi, VectorField(mesh.n_vertices(), V), T, {}, &report);
    CHECK(report.lost == 0);
    CHECK(report.traced == mesh.n_vertices());
    double worst = 0;
    std::size_t leaving = 0;
    for (auto v : mesh.vertices()) {
      const Vec3 x = mesh.point(v);
      // Exact foot: x − sV for the largest s ≤ T that stays in the square.
      double s = T;
      for (int c = 0; c < 2; ++c) {
        if (V[c] > 0) s = std::min(s, x[c] / V[c]);
        if (V[c] < 0) s = std::min(s, (x[c] - 1) / V[c]);
      }
      const Vec3 foot = x - s * V;
      leaving += s < T;
      worst = std::max(worst, std::abs(result[v.idx()] - phi0(foot[0], foot[1])));
    }
    CHECK(worst < 1e-12);
    CHECK(report.hit_boundary == leaving);
  }
}

TEST_CASE("a speed that grows along the path: the midpoint's velocity is read in the face it lies in") {
  // V = u(s)·e with s = e·x and u = exp((s − s0)/L), L = 4 h, in four directions e along the grid:
  // the speed grows by 28 % per cell, as the rate of spread does up a steepening slope, and its P1
  // interpolant bends at every grid line across e. φ0 = s is affine (exact in P1 and in its
  // gradient correction), so φ(T) at a vertex is the s of its foot, compared with the P1 field's
  // own characteristic integrated here (1-D, 20,000 RK4 steps). T takes the traces across 1.5–3
  // cells, as a sub-step of the fire's max_cfl = 4 does. A midpoint rule that extends the start
  // face's affine V to a midpoint beyond its edges under-estimates a convex speed there, and a
  // trace starts at a vertex in whichever face of its fan the mesh names: the feet fell short by
  // 0.033–0.090 of a cell depending on e, and a fire's front lagged 3 % of its burnt area behind a
  // reference with 16× the sub-steps (docs/reference/fire_model.md). Read where it lies: 0.016–0.022.
  const int n = 40;
  const double h = 1.0 / n, L = 4 * h, T = 1.5 * h;
  const SurfaceMesh mesh = make_square(n);
  for (const Vec3 e : {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0)}) {
    CAPTURE(e);
    const double s0 = e[0] + e[1] < 0 ? -0.7 : 0.3;  // where the speed is 1; it grows along e
    auto speed = [&](double s) { return std::exp((s - s0) / L); };
    auto u = [&](double s) {  // the P1 interpolant along s (grid lines at multiples of h)
      const double cell = std::floor(s / h + 1e-12);
      const double t = s / h - cell;
      return (1 - t) * speed(cell * h) + t * speed((cell + 1) * h);
    };
    const ScalarField phi = sample(mesh, [&](const Vec3& p) { return OpenMesh::dot(e, p); });
    const VectorField velocity = sample_vector(mesh, [&](const Vec3& p) { return Vec3(speed(OpenMesh::dot(e, p)) * e); });
    AdvectionReport report;
    const ScalarField result = advect(mesh, phi, velocity, T, {}, &report);
    CHECK(report.lost == 0);
    double worst = 0;
    int checked = 0;
    for (auto v : mesh.vertices()) {
      const double s = OpenMesh::dot(e, mesh.point(v));
      if (s < s0 || s > s0 + 0.15) continue;  // speeds 1 to 4.5, traces inside the square
      double X = s;
      const int steps = 20000;
      const double dt = T / steps;
      for (int i = 0; i < steps; ++i) {  // backwards: dX/dt = −u(X)
        const double k1 = -u(X), k2 = -u(X + 0.5 * dt * k1), k3 = -u(X + 0.5 * dt * k2), k4 = -u(X + dt * k3);
        X += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      }
      worst = std::max(worst, std::abs(result[v.idx()] - X));
      ++checked;
    }
    CHECK(checked > 100);
    MESSAGE("worst foot error " << worst / h << " cells");
    CHECK(worst <= 0.03 * h);
  }
}

TEST_CASE("translation on a plane: a quadratic level set within the P1 interpolation bound") {
  // For u = |x − c|², I_h u − u = R² − |p − m|² ≤ R² on a triangle of circumradius R (m its
  // circumcentre): R² = h²/2 on these right triangles.
  for (int n : {10, 20, 40}) {
    const SurfaceMesh mesh = make_square(n);
    const double h = 1.0 / n;
    auto phi0 = [](double x, double y) { return (x - 0.4) * (x - 0.4) + (y - 0.6) * (y - 0.6) - 0.04; };
    const ScalarField phi = sample(mesh, [&](const Vec3& p) { return phi0(p[0], p[1]); });
    const Vec3 V(0.3, -0.2, 0);
    const double T = 1.0;
    AdvectionReport report;
    const ScalarField result = advect(mesh, phi, VectorField(mesh.n_vertices(), V), T, {}, &report);
    CHECK(report.lost == 0);
    double worst = 0;
    for (auto v : mesh.vertices()) {
      const Vec3 foot = mesh.point(v) - T * V;
      if (foot[0] < 0 || foot[0] > 1 || foot[1] < 0 || foot[1] > 1) continue;
      worst = std::max(worst, std::abs(result[v.idx()] - phi0(foot[0], foot[1])));
    }
    CAPTURE(n);
    CHECK(worst <= h * h / 2 + 1e-14);
    CHECK(worst > 0);  // the interpolation error is real: the test can tell
  }
}

TEST_CASE("open plane: inflow vertices take the boundary values at the exit point") {
  const int n = 20;
  const SurfaceMesh mesh = make_square(n);
  auto phi0 = [](double x, double y) { return std::sin(3 * y) + x * x; };
  const ScalarField phi = sample(mesh, [&](const Vec3& p) { return phi0(p[0], p[1]); });
  // Values on the inflow side x = 0, as P1 along its edges.
  auto boundary_value = [&](double y) {
    const double s = y * n;
    const int j = std::clamp(int(std::floor(s)), 0, n - 1);
    const double t = s - j;
    return (1 - t) * phi0(0, double(j) / n) + t * phi0(0, double(j + 1) / n);
  };
  for (const Vec3& V : {Vec3(1, 0, 0), Vec3(1, 0.5, 0)}) {
    CAPTURE(V);
    const double T = 0.31;  // not a multiple of h: exit points fall inside boundary edges
    AdvectionReport report;
    AdvectionOptions p1;  // the boundary value is exactly the P1 trace without the correction
    p1.gradient_correction = false;
    const ScalarField result = advect(mesh, phi, VectorField(mesh.n_vertices(), V), T, p1, &report);
    // With the correction, exit values stay within the P1 interpolation bound of the exact trace.
    const ScalarField corrected = advect(mesh, phi, VectorField(mesh.n_vertices(), V), T, {});
    double worst_corrected = 0;
    CHECK(report.lost == 0);
    std::size_t inflow = 0;
    double worst = 0;
    for (auto v : mesh.vertices()) {
      const Vec3 x = mesh.point(v);
      double s = T;
      for (int c = 0; c < 2; ++c)
        if (V[c] > 0) s = std::min(s, x[c] / V[c]);
      if (s >= T) continue;
      const Vec3 foot = x - s * V;
      if (foot[0] > 1e-12) continue;  // leaves through y = 0, not the side checked here
      ++inflow;
      worst = std::max(worst, std::abs(result[v.idx()] - boundary_value(foot[1])));
      worst_corrected = std::max(worst_corrected, std::abs(corrected[v.idx()] - phi0(foot[0], foot[1])));
    }
    CHECK(inflow > 0);
    CHECK(worst < 1e-12);
    // |∂²φ0/∂y²| ≤ 9: P1 interpolation on an edge of length h is within 9h²/8 of the exact value.
    CHECK(worst_corrected <= 9.0 / (8.0 * n * n));
  }
  // Horizontal flow: the bottom and top rows run along boundary edges and must not stop there.
  AdvectionReport report;
  advect(mesh, phi, VectorField(mesh.n_vertices(), Vec3(1, 0, 0)), 0.31, {}, &report);
  std::size_t left_of_T = 0;
  for (auto v : mesh.vertices()) left_of_T += mesh.point(v)[0] < 0.31;
  CHECK(report.hit_boundary == left_of_T);
}

TEST_CASE("sphere: expansion along e_beta converges at order 2 to beta - a - T, nothing lost") {
  const BandError e11 = expansion_error(11, false), e22 = expansion_error(22, false), e44 = expansion_error(44, false);
  CHECK(e11.lost + e22.lost + e44.lost == 0);
  const double order1 = std::log(e11.l2 / e22.l2) / std::log(e11.h / e22.h);
  const double order2 = std::log(e22.l2 / e44.l2) / std::log(e22.h / e44.h);
  CAPTURE(e11.l2);
  CAPTURE(e22.l2);
  CAPTURE(e44.l2);
  CHECK(order1 > 1.8);
  CHECK(order2 > 1.8);
  // Below the interpolation error scale h²/8 · |band|^(1/2) with |band| ≈ 3.1.
  CHECK(e44.l2 < e44.h * e44.h / 8 * std::sqrt(3.2));
}

TEST_CASE("advect_normal with v = 1 on beta - a is the e_beta expansion (grad phi = e_beta)") {
  for (int k : {11, 22}) {
    const BandError direct = expansion_error(k, false), normal = expansion_error(k, true);
    CAPTURE(k);
    CHECK(normal.lost == 0);
    // The averaged, normalised vertex gradient is e_β up to O(h²): same accuracy.
    CHECK(normal.l2 < 1.5 * direct.l2);
  }
}

TEST_CASE("rigid rotation about z: one revolution returns the cap") {
  const RotationResult r11 = rotate_cap(11, 2), r22 = rotate_cap(22, 2), r44 = rotate_cap(44, 2);
  CHECK(r11.lost + r22.lost + r44.lost == 0);
  for (const auto& r : {r11, r22, r44}) {
    CAPTURE(r.h);
    CAPTURE(r.interface_error);
    // φ0 is a distance: |φ(T) − φ0| bounds how far the interface moved. O(h²): the P1
    // interpolation at the foot (≈ h²/8·|∇²φ0|, with |∇²φ0| ≈ cot 0.5 ≈ 1.8 at the interface) plus
    // the flat faces' O(h²) relative metric error over a path of length up to 2π.
    MESSAGE("h ", r.h, " interface error ", r.interface_error, " = ", r.interface_error / (r.h * r.h), " h², area ",
            r.area_before, " -> ", r.area_after);
    CHECK(r.interface_error < 2 * r.h * r.h);
    CHECK(std::abs(r.area_after - r.area_before) < 2 * M_PI * r.h * r.h);
  }
  CHECK(r22.interface_error < r11.interface_error / 2.5);
  CHECK(r44.interface_error < r22.interface_error / 2.5);
}

TEST_CASE("RK4 is at least as accurate as RK2") {
  // Long sub-steps (4 cells) on curved paths, where the time error shows.
  const RotationResult rk2 = rotate_cap(22, 2, 4.0), rk4 = rotate_cap(22, 4, 4.0);
  CHECK(rk2.lost + rk4.lost == 0);
  CAPTURE(rk2.interface_error);
  CAPTURE(rk4.interface_error);
  CHECK(rk4.interface_error <= rk2.interface_error);
}

TEST_CASE("results do not depend on the thread count") {
  const SurfaceMesh mesh = make_sphere({.faces = 20 * 22 * 22});
  const ScalarField phi = sample(mesh, [](const Vec3& p) { return polar_angle(p) - M_PI / 4; });
  const VectorField velocity = sample_vector(mesh, [](const Vec3& p) { return e_beta(p) + OpenMesh::cross(Vec3(0, 0, 1), p); });
  ScalarField one, two;
  AdvectionReport r1, r2;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = advect(mesh, phi, velocity, 0.7, {}, &r1);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = advect(mesh, phi, velocity, 0.7, {}, &r2);
  }
  CHECK(one == two);
  CHECK(r1.substeps == r2.substeps);
  CHECK(r1.lost == 0);
}

TEST_CASE("bad input is rejected") {
  const SurfaceMesh mesh = make_square(2);
  const ScalarField phi(mesh.n_vertices(), 0.0);
  const VectorField velocity(mesh.n_vertices(), Vec3(1, 0, 0));
  CHECK_THROWS_AS(advect(mesh, ScalarField(3, 0.0), velocity, 1.0), InputError);
  CHECK_THROWS_AS(advect(mesh, phi, VectorField(2), 1.0), InputError);
  CHECK_THROWS_AS(advect(mesh, phi, velocity, -1.0), InputError);
  AdvectionOptions rk3;
  rk3.rk_order = 3;
  CHECK_THROWS_AS(advect(mesh, phi, velocity, 1.0, rk3), InputError);
}

TEST_CASE("bodyfit advect: round trip through files on a small sphere") {
  test::TempDir dir("advect_cli");
  const SurfaceMesh mesh = make_sphere({.faces = 500});
  const ScalarField phi = sample(mesh, [](const Vec3& p) { return polar_angle(p) - M_PI / 4; });
  const VectorField velocity = sample_vector(mesh, e_beta);
  write_mesh(mesh, dir / "s.mesh");
  write_scalar_sol(dir / "phi.sol", phi);
  write_vector_sol(dir / "v.sol", velocity);
  const auto run = test::run_bodyfit("advect " + (dir / "s.mesh").string() + " --phi " + (dir / "phi.sol").string() +
                                     " --velocity " + (dir / "v.sol").string() + " --time 0.5 --rk 4 -o " +
                                     (dir / "out.sol").string());
  CAPTURE(run.output);
  REQUIRE(run.exit_code == 0);
  CHECK(run.output.find("0 lost") != std::string::npos);
  const ScalarField from_file = read_scalar_sol(dir / "out.sol", mesh.n_vertices());
  AdvectionOptions options;
  options.rk_order = 4;
  const ScalarField direct = advect(read_mesh(dir / "s.mesh"), phi, velocity, 0.5, options);
  double worst = 0;
  for (std::size_t i = 0; i < direct.size(); ++i) worst = std::max(worst, std::abs(from_file[i] - direct[i]));
  CHECK(worst < 1e-12);
  // And the answer is the expansion's: β − a − T where β > T.
  double band = 0;
  for (auto v : mesh.vertices()) {
    const double beta = polar_angle(mesh.point(v));
    if (std::abs(beta - M_PI / 2) < 0.25) band = std::max(band, std::abs(from_file[v.idx()] - (beta - M_PI / 4 - 0.5)));
  }
  CHECK(band < 0.01);

  const auto missing = test::run_bodyfit("advect " + (dir / "s.mesh").string() + " --phi " +
                                         (dir / "phi.sol").string() + " --time 1 -o x.sol");
  CHECK(missing.exit_code != 0);
}

TEST_CASE("a characteristic that crosses a cluster of tiny faces gets its long sub-steps back") {
  // The square [−1, 1]² with its points pulled towards the centre (r → r⁴, radial lines stay
  // straight): cells shrink to ~1e-5 there with aspect ≤ 4. The rows through the centre cross the
  // tiny cells, then big ones again. Sub-steps follow the local cell size both ways, so a trace
  // costs about the number of cells it crosses (it used to keep the tiny steps to the end).
  SurfaceMesh mesh = test::grid_square(40, {.x0 = -1, .y0 = -1, .x1 = 1, .y1 = 1});
  for (auto w : mesh.vertices()) {
    const Vec3 p = mesh.point(w);
    const double r = std::hypot(p[0], p[1]);
    if (r > 0) mesh.set_point(w, p * (r * r * r));  // |p| → r⁴, direction kept
  }
  const ScalarField phi = sample(mesh, [](const Vec3& p) { return p[0] - 0.3 * p[1] + 0.1; });
  const VectorField velocity(mesh.n_vertices(), Vec3(1, 0, 0));
  AdvectionReport report;
  const ScalarField out = advect(mesh, phi, velocity, 1.2, {}, &report);
  CHECK(report.lost == 0);
  // Affine φ and uniform V: exact wherever the path stays in the domain, e.g. in the unit disk,
  // which the mapped square contains (within the rounding of walks through 1e-5 cells).
  std::size_t checked = 0;
  for (auto w : mesh.vertices()) {
    const Vec3 p = mesh.point(w);
    if (std::hypot(p[0], p[1]) >= 0.999 || std::hypot(p[0] - 1.2, p[1]) >= 0.999) continue;
    CHECK(std::abs(out[w.idx()] - (p[0] - 1.2 - 0.3 * p[1] + 0.1)) < 1e-9);
    ++checked;
  }
  CHECK(checked > 100);
  // A trace crosses at most ~40 cells of the row: well under 100 sub-steps per vertex (keeping
  // the tiny steps cost about 20,000 on the central row).
  MESSAGE("sub-steps per vertex " << double(report.substeps) / double(report.traced));
  CHECK(report.substeps < 100 * report.traced);
}

TEST_CASE("Advector::advect_band: the whole-mesh advection at the traced vertices, nothing elsewhere") {
  const SurfaceMesh mesh = make_sphere({.faces = 20 * 22 * 22});
  const double h = edge_length_stats(mesh).mean;
  ScalarField phi(mesh.n_vertices());
  for (auto v : mesh.vertices()) phi[v.idx()] = std::acos(std::clamp(mesh.point(v)[2], -1.0, 1.0)) - M_PI / 3;
  const VectorField velocity =
      sample_vector(mesh, [](const Vec3& p) { return e_beta(p) + 0.5 * OpenMesh::cross(Vec3(0, 0, 1), p); });
  const double T = 3 * h;  // |V| ≤ ~1.2: the feet lie within ~4h of the traced vertices
  Advector advector(mesh);
  const ScalarField whole = advector.advect(phi, velocity, T);
  std::vector<int> traced, known;
  for (auto v : mesh.vertices()) {
    if (std::abs(phi[v.idx()]) <= 2 * h) traced.push_back(v.idx());
    if (std::abs(phi[v.idx()]) <= 8 * h) known.push_back(v.idx());
  }
  // V is garbage outside `known`: the band call must not read it there.
  VectorField partial = velocity;
  for (auto v : mesh.vertices())
    if (std::abs(phi[v.idx()]) > 8 * h) partial[v.idx()] = Vec3(1e3, -1e3, 1e3);
  ScalarField out(mesh.n_vertices(), 7.0);
  AdvectionReport report;
  advector.advect_band(phi, partial, T, traced, known, out, {}, &report);
  CHECK(report.traced == traced.size());
  CHECK(report.outside_band == 0);
  CHECK(report.lost == 0);
  double worst = 0;
  std::size_t untouched = 0;
  for (auto v : mesh.vertices()) {
    const int i = v.idx();
    if (std::binary_search(traced.begin(), traced.end(), i)) worst = std::max(worst, std::abs(out[i] - whole[i]));
    else untouched += out[i] == 7.0;
  }
  CHECK(worst <= 1e-12);
  CHECK(untouched == mesh.n_vertices() - traced.size());
  // A band too narrow for the reach: the traces that leave it stop at its edge and are counted.
  std::vector<int> thin;
  for (auto v : mesh.vertices())
    if (std::abs(phi[v.idx()]) <= 2.5 * h) thin.push_back(v.idx());
  advector.advect_band(phi, partial, 10 * T, traced, thin, out, {}, &report);
  CHECK(report.outside_band > 0);
}

TEST_CASE("an Advector built on the band's faces only: the whole mesh's band call, and traces leaving it are counted") {
  // Its faces are stored in the whole mesh's order and each trace starts in the same face of its
  // vertex: the same values, bit for bit.
  const SurfaceMesh mesh = make_sphere({.faces = 20 * 22 * 22});
  const double h = edge_length_stats(mesh).mean;
  ScalarField phi(mesh.n_vertices());
  for (auto v : mesh.vertices()) phi[v.idx()] = std::acos(std::clamp(mesh.point(v)[2], -1.0, 1.0)) - M_PI / 3;
  const VectorField velocity =
      sample_vector(mesh, [](const Vec3& p) { return e_beta(p) + 0.5 * OpenMesh::cross(Vec3(0, 0, 1), p); });
  const double T = 3 * h;
  std::vector<int> traced, known;
  for (auto v : mesh.vertices()) {
    if (std::abs(phi[v.idx()]) <= 2 * h) traced.push_back(v.idx());
    if (std::abs(phi[v.idx()]) <= 8 * h) known.push_back(v.idx());
  }
  std::vector<int> faces;  // the faces with a corner in `known`
  for (auto f : mesh.faces())
    for (auto v : mesh.fv_range(f))
      if (std::binary_search(known.begin(), known.end(), v.idx())) {
        faces.push_back(f.idx());
        break;
      }
  REQUIRE(faces.size() < mesh.n_faces() / 2);
  Advector whole(mesh), band(mesh, faces);
  ScalarField expected(mesh.n_vertices(), 7.0), out(mesh.n_vertices(), 7.0);
  AdvectionReport report;
  whole.advect_band(phi, velocity, T, traced, known, expected);
  band.advect_band(phi, velocity, T, traced, known, out, {}, &report);
  CHECK(report.outside_band == 0);
  CHECK(report.hit_boundary == 0);
  CHECK(report.lost == 0);
  std::size_t differ = 0;
  for (std::size_t v = 0; v < out.size(); ++v) differ += out[v] != expected[v];
  CHECK(differ == 0);
  // Too long a time for the faces built: the traces reach their edge and are counted as having
  // left the band, never as having met a boundary of S (a closed sphere has none).
  band.advect_band(phi, velocity, 10 * T, traced, known, out, {}, &report);
  CHECK(report.outside_band > 0);
  CHECK(report.hit_boundary == 0);
  CHECK_THROWS_AS(band.advect(phi, velocity, T), std::logic_error);
}

TEST_CASE("BandAdvector: built around the band, built again when the band moves beyond it, the whole mesh's values") {
  const SurfaceMesh mesh = make_sphere({.faces = 20 * 22 * 22});
  const double h = edge_length_stats(mesh).mean;
  const VectorField velocity = sample_vector(mesh, [](const Vec3& p) { return e_beta(p); });
  Advector whole(mesh);
  BandAdvector band_advector(mesh);
  // A front at polar angle theta, its band and the vertices traced, advected by both Advectors.
  auto same_as_whole = [&](double theta, int rings) {
    ScalarField phi(mesh.n_vertices());
    for (auto v : mesh.vertices()) phi[v.idx()] = std::acos(std::clamp(mesh.point(v)[2], -1.0, 1.0)) - theta;
    std::vector<int> traced, known;
    for (auto v : mesh.vertices()) {
      if (std::abs(phi[v.idx()]) <= 2 * h) traced.push_back(v.idx());
      if (std::abs(phi[v.idx()]) <= 6 * h) known.push_back(v.idx());
    }
    ScalarField expected(mesh.n_vertices(), 7.0), out(mesh.n_vertices(), 7.0);
    AdvectionReport report;
    whole.advect_band(phi, velocity, 2 * h, traced, known, expected);
    band_advector.covering(known, rings).advect_band(phi, velocity, 2 * h, traced, known, out, {}, &report);
    CHECK(report.outside_band == 0);
    std::size_t differ = 0;
    for (std::size_t v = 0; v < out.size(); ++v) differ += out[v] != expected[v];
    return differ == 0;
  };
  CHECK(same_as_whole(M_PI / 3, 4));
  CHECK(band_advector.builds() == 1);
  CHECK(same_as_whole(M_PI / 3 + h, 4));  // still within the 4 rings built beyond the band
  CHECK(band_advector.builds() == 1);
  CHECK(same_as_whole(M_PI / 3 + 10 * h, 4));  // beyond them: built again, further on
  CHECK(band_advector.builds() == 2);
}

TEST_CASE("Advector::advect_band_composed: sub-steps of a translation give the one-step result, not K interpolations") {
  // A uniform V on a plane: the composed foot map is affine, so its interpolation is exact and K
  // composed calls of T/K interpolate phi once, at the same foot as one call of T. Interpolating phi
  // at every call (advect_band) adds K interpolation errors of a curved phi instead.
  const int n = 40;
  const SurfaceMesh mesh = make_square(n);
  const double h = 1.0 / n;
  const ScalarField phi = sample(mesh, [](const Vec3& p) {
    return (p[0] - 0.4) * (p[0] - 0.4) + (p[1] - 0.6) * (p[1] - 0.6) - 0.04;
  });
  const Vec3 V(0.3, -0.2, 0);
  const VectorField velocity(mesh.n_vertices(), V);
  const double T = 0.5;
  const int K = 4;
  std::vector<int> all(mesh.n_vertices());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = int(i);
  Advector advector(mesh);
  const ScalarField once = advector.advect(phi, velocity, T);
  ScalarField composed = phi, interpolated = phi;
  advector.start_composition(phi);
  for (int k = 0; k < K; ++k) {
    ScalarField next = composed;
    AdvectionReport report;
    advector.advect_band_composed(composed, velocity, T / K, all, all, next, {}, &report);
    CHECK(report.lost == 0);
    composed = std::move(next);
    next = interpolated;
    advector.advect_band(interpolated, velocity, T / K, all, all, next);
    interpolated = std::move(next);
  }
  // Feet stopped on the inflow boundary are not a translation, and each call interpolates the feet
  // of vertices up to an edge further out: compared, the vertices whose characteristic stays K + 1
  // edges inside the square.
  double worst_composed = 0, worst_interpolated = 0;
  std::size_t compared = 0;
  for (auto v : mesh.vertices()) {
    const Vec3 foot = mesh.point(v) - T * V;
    const Vec3 start = mesh.point(v);
    const double margin = (K + 1) * h;
    if (std::min({foot[0], foot[1], start[0], start[1]}) < margin ||
        std::max({foot[0], foot[1], start[0], start[1]}) > 1 - margin)
      continue;
    ++compared;
    worst_composed = std::max(worst_composed, std::abs(composed[v.idx()] - once[v.idx()]));
    worst_interpolated = std::max(worst_interpolated, std::abs(interpolated[v.idx()] - once[v.idx()]));
  }
  MESSAGE("largest difference to one step of T: " << worst_composed << " composed, " << worst_interpolated
                                                   << " interpolated at every call (" << compared << " vertices)");
  CHECK(compared > 100);
  // Rounding: a walk snaps to an edge within 1e-11 of its length (walk() in advection.cpp).
  CHECK(worst_composed <= 1e-10);
  CHECK(worst_interpolated > 1e-5);  // 2.4e-4
}
