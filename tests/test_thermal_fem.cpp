// The numerical core of the thermal model (plugins/thermal): TetGen volume meshes that keep S, P1
// finite elements against exact solutions, the adjoint, the shape derivative against finite
// differences of J_ε, and the inputs that must fail with a clear message.
#include "linear_solver.hpp"
#include "thermal_fixtures.hpp"
#include "quadrature.hpp"
#include "shape_derivative.hpp"
#include "smoothing.hpp"
#include "surface_check.hpp"
#include "thermal_fem.hpp"
#include "volume_mesh.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/surface_fem.hpp>

#include <Eigen/SparseCholesky>
#include <doctest/doctest.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <vector>

using namespace bodyfit;
using namespace bodyfit::thermal;
using bodyfit::test::DiskOnCube;
using bodyfit::test::make_box;
using bodyfit::test::unit_sphere;

namespace {

double mean_edge(const SurfaceMesh& mesh) { return edge_length_stats(mesh).mean; }

/// ‖u_h − u‖ in L²(Ω) with the 4-point rule of degree 2 on each tetrahedron.
double l2_error(const VolumeMesh& mesh, const Eigen::VectorXd& uh, const std::function<double(const Vec3&)>& u) {
  double sum = 0;
  for (const auto& t : mesh.tets) {
    std::array<Vec3, 4> p;
    for (int k = 0; k < 4; ++k) p[std::size_t(k)] = mesh.points[std::size_t(t[std::size_t(k)])];
    double vol = tet_volume(p[0], p[1], p[2], p[3]);
    for (const auto& q : tet_points_degree2()) {
      const auto& l = q.barycentric;
      Vec3 x = p[0] * l[0] + p[1] * l[1] + p[2] * l[2] + p[3] * l[3];
      double e = l[0] * uh[t[0]] + l[1] * uh[t[1]] + l[2] * uh[t[2]] + l[3] * uh[t[3]] - u(x);
      sum += vol * q.weight * e * e;
    }
  }
  return std::sqrt(sum);
}

double order(double e_coarse, double e_fine, double h_coarse, double h_fine) {
  return std::log(e_coarse / e_fine) / std::log(h_coarse / h_fine);
}

template <class F>
std::string error_message(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

// ---- h and quadrature ------------------------------------------------------------------------------

TEST_CASE("h: bounds, h(0) = 1/2, symmetry, integral of h' = -1, h' against finite differences, no overflow") {
  CHECK(h(0) == doctest::Approx(0.5).epsilon(1e-15));
  CHECK(h(-1) == 1);
  CHECK(h(1) == 0);
  CHECK(h(-3) == 1);
  CHECK(h(2) == 0);
  double previous = 1;
  for (int i = -1000; i <= 1000; ++i) {
    double r = i / 1000.0;
    double v = h(r);
    CHECK(v >= 0);
    CHECK(v <= 1);
    CHECK(v <= previous);  // non-increasing
    previous = v;
    CHECK(h(-r) == doctest::Approx(1 - v).epsilon(1e-12));
    CHECK(h_prime(r) <= 0);
  }
  // Near ±1 the exponent 4r/(r² − 1) is huge: no NaN, no overflow.
  for (double r : {std::nextafter(1.0, 0.0), 1 - 1e-12, 1 - 1e-6, -1 + 1e-12, std::nextafter(-1.0, 0.0)}) {
    CHECK(std::isfinite(h(r)));
    CHECK(std::isfinite(h_prime(r)));
    CHECK(std::abs(h_prime(r)) < 1e-100);
  }
  // h' is C^∞ and flat at ±1: the trapezoidal rule converges spectrally.
  const int n = 4000;
  double integral = 0;
  for (int i = 1; i < n; ++i) integral += h_prime(-1 + 2.0 * i / n);
  integral *= 2.0 / n;
  CHECK(integral == doctest::Approx(-1).epsilon(1e-12));
  for (double r : {-0.9, -0.6, -0.3, -0.05, 0.0, 0.2, 0.5, 0.8, 0.95}) {
    double d = 1e-6;
    double fd = (h(r + d) - h(r - d)) / (2 * d);
    CHECK(h_prime(r) == doctest::Approx(fd).epsilon(1e-7));
  }
  // h_ε and its derivative in d.
  double eps = 0.03;
  CHECK(h_epsilon(-1, eps) == doctest::Approx(1 / eps));
  CHECK(h_epsilon(0, eps) == doctest::Approx(0.5 / eps));
  CHECK(h_epsilon(0.04, eps) == 0);
  for (double d : {-0.02, -0.01, 0.0, 0.015, 0.025}) {
    double step = 1e-7;
    double fd = (h_epsilon(d + step, eps) - h_epsilon(d - step, eps)) / (2 * step);
    CHECK(h_epsilon_prime(d, eps) == doctest::Approx(fd).epsilon(1e-6));
  }
}

TEST_CASE("triangle quadrature: degree 5 exact on every subdivision, weights sum to 1") {
  auto factorial = [](int k) {
    double f = 1;
    for (int i = 2; i <= k; ++i) f *= i;
    return f;
  };
  for (int k : {1, 2, 3}) {
    auto points = triangle_points({.subdivisions = k});
    CHECK(points.size() == std::size_t(7 * k * k));
    for (int a = 0; a <= 5; ++a)
      for (int b = 0; a + b <= 5; ++b)
        for (int c = 0; a + b + c <= 5; ++c) {
          // ∫_T λ0^a λ1^b λ2^c / |T| = 2 a! b! c! / (a + b + c + 2)!
          double exact = 2 * factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 2);
          double sum = 0;
          for (const auto& q : points)
            sum += q.weight * std::pow(q.barycentric[0], a) * std::pow(q.barycentric[1], b) *
                   std::pow(q.barycentric[2], c);
          CHECK(sum == doctest::Approx(exact).epsilon(1e-13));
        }
  }
  CHECK_THROWS_AS(triangle_points({.subdivisions = 0}), InputError);
}

// ---- the volume mesh -------------------------------------------------------------------------------

TEST_CASE("tetrahedralize: S kept exactly, vertices first and in order, tets positive, faces outward") {
  for (bool sphere : {true, false}) {
    SurfaceMesh s = sphere ? unit_sphere(1280) : make_box(6, {0, 0, 0}, {1, 2, 1});
    double h = mean_edge(s);
    VolumeMesh v = tetrahedralize(s, {.max_volume = regular_tet_volume(h)});
    REQUIRE(v.n_surface_vertices == int(s.n_vertices()));
    REQUIRE(v.points.size() > s.n_vertices());  // interior points
    for (auto vh : s.vertices()) CHECK(v.points[std::size_t(vh.idx())] == s.point(vh));
    REQUIRE(v.boundary_faces.size() == s.n_faces());
    for (auto f : s.faces()) {
      CHECK(v.boundary_source_face[std::size_t(f.idx())] == f.idx());
      int k = 0;
      for (auto vh : s.fv_range(f)) CHECK(v.boundary_faces[std::size_t(f.idx())][std::size_t(k++)] == vh.idx());
    }
    // Every tet positive; the tets fill exactly the polyhedron bounded by S.
    double total = 0;
    for (const auto& t : v.tets) {
      double vol = tet_volume(v.points[std::size_t(t[0])], v.points[std::size_t(t[1])], v.points[std::size_t(t[2])],
                              v.points[std::size_t(t[3])]);
      CHECK(vol > 0);
      total += vol;
    }
    CHECK(total == doctest::Approx(enclosed_volume(s)).epsilon(1e-12));
    // Each boundary face is a face of exactly one tet, whose fourth vertex lies behind it (outward
    // normal); every other tet face is shared by two tets.
    std::map<std::array<int, 3>, std::vector<std::pair<int, int>>> faces;  // sorted face → (tet, opposite vertex)
    for (int t = 0; t < int(v.tets.size()); ++t)
      for (int k = 0; k < 4; ++k) {
        std::array<int, 3> f;
        int m = 0;
        for (int j = 0; j < 4; ++j)
          if (j != k) f[std::size_t(m++)] = v.tets[std::size_t(t)][std::size_t(j)];
        std::sort(f.begin(), f.end());
        faces[f].emplace_back(t, v.tets[std::size_t(t)][std::size_t(k)]);
      }
    std::size_t single = 0;
    for (const auto& [f, owners] : faces) {
      CHECK(owners.size() <= 2);
      if (owners.size() == 1) ++single;
    }
    CHECK(single == s.n_faces());
    for (const auto& bf : v.boundary_faces) {
      auto key = bf;
      std::sort(key.begin(), key.end());
      auto it = faces.find(key);
      REQUIRE(it != faces.end());
      REQUIRE(it->second.size() == 1);
      const Vec3& opposite = v.points[std::size_t(it->second[0].second)];
      CHECK(tet_volume(v.points[std::size_t(bf[0])], v.points[std::size_t(bf[1])], v.points[std::size_t(bf[2])],
                       opposite) < 0);
    }
    auto stats = volume_stats(v);
    MESSAGE(fmt::format("{}: {} surface faces, h = {:.3f}: {} tets, {} vertices, dihedral angles {:.1f}-{:.1f}°, mean "
                        "tet edge {:.3f}",
                        sphere ? "sphere" : "box", s.n_faces(), h, stats.tets, stats.vertices, stats.min_dihedral_deg,
                        stats.max_dihedral_deg, stats.mean_edge));
    CHECK(stats.min_dihedral_deg > 3);
  }
}

// ---- finite elements against exact solutions -----------------------------------------------------

TEST_CASE("Robin-Poisson on the unit ball: u = (1 - r^2)/6 + 1/(3 kappa), second order") {
  // −Δu = 1 in the ball, ∂u/∂n + κu = 0 on the sphere. The discrete Ω is the inscribed polyhedron
  // (its vertices on the sphere): the errors below are against u at the nodes and in L²(Ω_h), both
  // O(h²), and so is ∫u_h − ∫_ball u (mostly the volume the polyhedron misses). Measured (h = 0.30,
  // 0.15, 0.076; 2k, 18k, 146k tets): nodal max 7.8e-3, 2.1e-3, 5.5e-4 (orders 1.9, 1.9); L² 2.0e-2,
  // 5.0e-3, 1.3e-3 (orders 2.0, 2.0); ∫u 1.5887, 1.6534, 1.6699 against 1.6755161 (orders 2.0, 2.0).
  const double kappa = 1;
  auto exact = [&](const Vec3& x) { return (1 - x.sqrnorm()) / 6 + 1 / (3 * kappa); };
  std::vector<double> hs, nodal, l2, integral_error;
  for (std::size_t faces : {320, 1280, 5120}) {
    auto s = unit_sphere(faces);
    double h = mean_edge(s);
    VolumeMesh v = tetrahedralize(s, {.max_volume = regular_tet_volume(h)});
    ThermalProblem problem;
    problem.robin_field.assign(s.n_vertices(), kappa);
    auto sol = solve_thermal(v, problem);
    double max_error = 0;
    for (std::size_t i = 0; i < v.points.size(); ++i)
      max_error = std::max(max_error, std::abs(sol.u[Eigen::Index(i)] - exact(v.points[i])));
    hs.push_back(h);
    nodal.push_back(max_error);
    l2.push_back(l2_error(v, sol.u, exact));
    double integral = sol.mean_temperature * sol.volume;
    double exact_integral = 4 * std::numbers::pi / 45 + 4 * std::numbers::pi / (9 * kappa);
    MESSAGE(fmt::format("ball h = {:.3f}: {} tets, nodal max error {:.2e}, L2 error {:.2e}, ∫u = {:.6f} (exact on the "
                        "ball {:.7f}), |Ω_h| = {:.5f}; assembly {:.1f} ms, factorisation {:.1f} ms, solves {:.1f} ms",
                        h, v.tets.size(), max_error, l2.back(), integral, exact_integral, sol.volume,
                        sol.timings.setup_ms + sol.timings.assembly_ms, sol.timings.factorization_ms,
                        sol.timings.solve_ms));
    integral_error.push_back(std::abs(integral - exact_integral));
    CHECK(integral_error.back() < 0.06 * exact_integral);
  }
  for (std::size_t k = 1; k < hs.size(); ++k) {
    double on = order(nodal[k - 1], nodal[k], hs[k - 1], hs[k]);
    double ol = order(l2[k - 1], l2[k], hs[k - 1], hs[k]);
    double oi = order(integral_error[k - 1], integral_error[k], hs[k - 1], hs[k]);
    MESSAGE(fmt::format("orders: nodal {:.2f}, L2 {:.2f}, integral {:.2f}", on, ol, oi));
    CHECK(on > 1.7);
    CHECK(ol > 1.7);
    CHECK(oi > 1.7);
  }
}

TEST_CASE("manufactured solution on a cube: variable conductivity, Robin data, Neumann face, second order in L2") {
  // u = e^{z/2} cos(x + 2y) on [0,1]³, γ = 1 + x, κ = 1 + x (a P1 field, exact), Γ_N = {z = 1} with
  // g = γ∂u/∂n, g_R = γ∂u/∂n + κu on the other faces, f = −div(γ∇u) = 4.75(1 + x)u + e^{z/2} sin(x + 2y).
  // Measured (n = 4, 8, 16; 0.7k, 6.7k, 59k tets): L² errors 1.4e-2, 3.4e-3, 8.2e-4 (orders 2.0, 2.1).
  auto u = [](const Vec3& x) { return std::exp(x[2] / 2) * std::cos(x[0] + 2 * x[1]); };
  auto grad = [](const Vec3& x) {
    double e = std::exp(x[2] / 2), s = std::sin(x[0] + 2 * x[1]), c = std::cos(x[0] + 2 * x[1]);
    return Vec3(-e * s, -2 * e * s, 0.5 * e * c);
  };
  auto gamma = [](const Vec3& x) { return 1 + x[0]; };
  auto outward = [](const Vec3& x) {
    // The face of the unit cube x lies on (the boundary load is evaluated inside faces, never on edges).
    const double t = 1e-12;
    if (x[0] < t) return Vec3(-1, 0, 0);
    if (x[0] > 1 - t) return Vec3(1, 0, 0);
    if (x[1] < t) return Vec3(0, -1, 0);
    if (x[1] > 1 - t) return Vec3(0, 1, 0);
    if (x[2] < t) return Vec3(0, 0, -1);
    return Vec3(0, 0, 1);
  };
  auto flux = [&](const Vec3& x) { return gamma(x) * OpenMesh::dot(grad(x), outward(x)); };
  std::vector<double> hs, errors;
  for (int n : {4, 8, 16}) {
    auto s = make_box(n, {0, 0, 0}, {1, 1, 1});
    double hh = 1.0 / n;
    VolumeMesh v = tetrahedralize(s, {.max_volume = regular_tet_volume(hh)});
    ThermalProblem problem;
    problem.conductivity = gamma;
    problem.source = [&](const Vec3& x) {
      return 4.75 * (1 + x[0]) * u(x) + std::exp(x[2] / 2) * std::sin(x[0] + 2 * x[1]);
    };
    problem.robin_field.resize(s.n_vertices());
    for (auto vh : s.vertices()) problem.robin_field[std::size_t(vh.idx())] = 1 + s.point(vh)[0];
    problem.robin_source = [&](const Vec3& x) { return flux(x) + (1 + x[0]) * u(x); };
    problem.neumann.assign(s.n_faces(), 0);
    for (auto f : s.faces()) {
      auto [a, b, c] = face_points(s, f);
      if (a[2] == 1 && b[2] == 1 && c[2] == 1) problem.neumann[std::size_t(f.idx())] = 1;
    }
    problem.neumann_flux = flux;
    auto sol = solve_thermal(v, problem);
    hs.push_back(hh);
    errors.push_back(l2_error(v, sol.u, u));
    MESSAGE(fmt::format("cube n = {}: {} tets, L2 error {:.2e}", n, v.tets.size(), errors.back()));
  }
  for (std::size_t k = 1; k < hs.size(); ++k) {
    double o = order(errors[k - 1], errors[k], hs[k - 1], hs[k]);
    MESSAGE(fmt::format("L2 order {:.2f}", o));
    CHECK(o > 1.7);
  }
}

// ---- the adjoint and the solvers ---------------------------------------------------------------------

TEST_CASE("adjoint: p = -u/|Omega| when f = 1, gamma = 1, no Neumann part, every linear solver agrees") {
  auto s = unit_sphere(1280);
  VolumeMesh v = tetrahedralize(s, {.max_volume = regular_tet_volume(mean_edge(s))});
  // κ = h_ε(d) with G the polar cap z > 0.5 (d ≈ its signed distance along the sphere).
  const double eps = 0.2;
  ThermalProblem problem;
  problem.robin_field.resize(s.n_vertices());
  for (auto vh : s.vertices())
    problem.robin_field[std::size_t(vh.idx())] = std::acos(std::clamp(s.point(vh)[2], -1.0, 1.0)) - std::acos(0.5);
  problem.robin_coefficient = [eps](double d) { return h_epsilon(d, eps); };

  ThermalSolution reference;
  for (LinearSolver solver : {LinearSolver::cholmod_supernodal, LinearSolver::cholmod_simplicial,
                              LinearSolver::eigen_simplicial, LinearSolver::conjugate_gradient}) {
    ThermalOptions options;
    options.linear.solver = solver;
    auto sol = solve_thermal(v, problem, options);
    double scale = sol.u.cwiseAbs().maxCoeff() / sol.volume;
    double mismatch = (sol.p + sol.u / sol.volume).cwiseAbs().maxCoeff();
    MESSAGE(fmt::format("{}: max|p + u/|Ω|| = {:.2e} (|p| ≤ {:.3f}), T = {:.8f}, cg iterations {}", to_string(solver),
                        mismatch, scale, sol.mean_temperature, sol.timings.cg_iterations));
    CHECK(mismatch <= (solver == LinearSolver::conjugate_gradient ? 1e-8 : 1e-12) * scale);
    CHECK(sol.mean_temperature > 0);
    CHECK(sol.p.maxCoeff() < 0);
    if (solver == LinearSolver::cholmod_supernodal) {
      reference = sol;
    } else {
      CHECK((sol.u - reference.u).cwiseAbs().maxCoeff() <= 1e-8 * reference.u.cwiseAbs().maxCoeff());
    }
  }
  // A conjugate gradient that cannot converge (2 iterations) hands over to CHOLMOD, or fails clearly.
  ThermalOptions starved;
  starved.linear.cg_max_iterations = 2;
  ThermalSolver rescue(v, problem, starved);
  auto rescued = rescue.solve();
  CHECK(rescue.linear_stats().fell_back);
  CHECK((rescued.u - reference.u).cwiseAbs().maxCoeff() <= 1e-12 * reference.u.cwiseAbs().maxCoeff());
  starved.linear.fallback_to_cholmod = false;
  CHECK(contains(error_message([&] { solve_thermal(v, problem, starved); }), "did not reach"));
  // The shortcut gives the same p without the second solve.
  ThermalOptions shortcut;
  shortcut.linear.solver = LinearSolver::cholmod_supernodal;  // as the reference
  shortcut.adjoint_shortcut = true;
  auto fast = solve_thermal(v, problem, shortcut);
  CHECK((fast.p - reference.p).cwiseAbs().maxCoeff() <= 1e-12 * reference.p.cwiseAbs().maxCoeff());
  // With a source that is not 1 the adjoint is no longer proportional to the state.
  problem.source = [](const Vec3& x) { return 1 + x[0]; };
  auto other = solve_thermal(v, problem);
  CHECK((other.p + other.u / other.volume).cwiseAbs().maxCoeff() > 1e-3 * other.p.cwiseAbs().maxCoeff());
}

// ---- the shape derivative ------------------------------------------------------------------------------

TEST_CASE("shape derivative: band formula against central finite differences of J_eps, J decreases as G grows") {
  // The disk on the cube (DiskOnCube). Moving R by δ moves d by −δ (s ≡ −1); G's labels, hence ℓ|G|,
  // stay fixed on the mesh.
  // Measured: relative difference FD/band 1e-9 (δ = 1e-4·ε) and 1.1e-5 (δ = 1e-2·ε: the O(δ²) term).
  const DiskOnCube disk(0.45);
  const SurfaceMesh& s = disk.surface;
  const double R = disk.R, eps = 0.15, ell = 0.01;
  auto distance = [&](double radius) { return disk.distance(radius); };
  VolumeMesh v = tetrahedralize(s, {.max_volume = regular_tet_volume(0.125)});
  ThermalProblem problem;
  problem.robin_field = distance(R);
  problem.robin_coefficient = [eps](double d) { return h_epsilon(d, eps); };
  ThermalSolver solver(v, problem);
  ObjectiveOptions options{.epsilon = eps, .ell = ell};

  auto sol = solver.solve();
  auto objective = thermal_objective(s, problem.robin_field, sol, options);
  std::vector<double> minus_one(s.n_vertices(), -1.0);
  double band = band_derivative(s, problem.robin_field, minus_one, sol, options);
  CHECK(objective.J == doctest::Approx(objective.T + ell * objective.area));
  CHECK(objective.area > 0.8 * std::numbers::pi * R * R);
  CHECK(band < 0);  // a larger G cools Ω
  // w ≤ 0 everywhere, and its lumped integral (the nodal form the plugin will use) approximates the
  // band derivative for s ≡ −1: nodal products instead of the quadrature, 9 % apart on this coarse
  // mesh (h = 0.125 against a band 2ε = 0.3 wide).
  auto lumped = lumped_mass(s);
  double nodal = 0;
  for (std::size_t i = 0; i < objective.density.size(); ++i) {
    CHECK(objective.density[i] <= 0);
    nodal += objective.density[i] * lumped[i];
  }
  MESSAGE(fmt::format("J = {:.10f}, T = {:.10f}, |G| = {:.5f}, dJ/dR: band {:.8e}, lumped nodal w {:.8e}", objective.J,
                      objective.T, objective.area, band, nodal));
  CHECK(nodal == doctest::Approx(band).epsilon(0.2));

  for (double delta : {1e-4 * eps, 1e-2 * eps}) {
    auto plus = solver.solve(distance(R + delta));
    auto minus = solver.solve(distance(R - delta));
    CHECK(plus.timings.analysis_ms == 0);  // the symbolic factorisation is reused
    double Jp = thermal_objective(s, distance(R + delta), plus, options).J;
    double Jm = thermal_objective(s, distance(R - delta), minus, options).J;
    double fd = (Jp - Jm) / (2 * delta);
    double relative = std::abs(fd - band) / std::abs(band);
    MESSAGE(fmt::format("δ = {:.1e}: finite difference {:.10e}, band derivative {:.10e}, relative difference {:.1e}",
                        delta, fd, band, relative));
    CHECK(relative < 1e-3);
    CHECK(Jp < Jm);
  }
}

TEST_CASE("Taylor test along the computed descent velocity: J(t) - J(0) - t J' = O(t^2), J' < 0") {
  // The same cube and disk; v is the descent speed the plugin computes, (M + α²K) v = −M w,
  // normalised to max |v| = 1. Moving Σ with normal speed v for a time t moves d by −t·v (labels
  // fixed: only h_ε changes), so J(t) = J(0) + t·J′ + O(t²) with J′ = band_derivative(s = −v).
  // Measured: J′ = −15.8, remainder / t² = 52.4, 52.7, 52.7, 52.8 for t = 0.02 … 0.0025.
  const DiskOnCube disk(0.45);
  const SurfaceMesh& s = disk.surface;
  const double eps = 0.15, alpha = 0.25;
  const std::vector<double> d = disk.distance(disk.R);
  VolumeMesh volume = tetrahedralize(s, {.max_volume = regular_tet_volume(0.125)});
  ThermalProblem problem;
  problem.robin_field = d;
  problem.robin_coefficient = [eps](double x) { return h_epsilon(x, eps); };
  ThermalSolver solver(volume, problem);
  ObjectiveOptions options{.epsilon = eps, .ell = 0};
  const auto sol = solver.solve();
  const auto objective = thermal_objective(s, d, sol, options);

  const Eigen::SparseMatrix<double> M = mass_matrix(s), K = stiffness_matrix(s);
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(Eigen::SparseMatrix<double>(M + alpha * alpha * K));
  const Eigen::Map<const Eigen::VectorXd> w(objective.density.data(), Eigen::Index(objective.density.size()));
  Eigen::VectorXd v = -ldlt.solve(M * w);
  v /= v.cwiseAbs().maxCoeff();
  std::vector<double> minus_v(std::size_t(v.size()));
  for (Eigen::Index i = 0; i < v.size(); ++i) minus_v[std::size_t(i)] = -v[i];
  const double slope = band_derivative(s, d, minus_v, sol, options);
  CHECK(slope < 0);  // a descent direction

  auto J_at = [&](double t) {
    std::vector<double> moved(d.size());
    for (std::size_t i = 0; i < d.size(); ++i) moved[i] = d[i] - t * v[Eigen::Index(i)];
    return thermal_objective(s, moved, solver.solve(moved), options).J;
  };
  std::vector<double> remainders;
  for (double t : {0.02, 0.01, 0.005, 0.0025}) {
    const double remainder = std::abs(J_at(t) - objective.J - t * slope);
    MESSAGE(fmt::format("t = {}: J' = {:.6e}, |J(t) - J(0) - t J'| = {:.3e}, / t² = {:.4e}", t, slope, remainder, remainder / (t * t)));
    remainders.push_back(remainder);
  }
  for (std::size_t k = 1; k < remainders.size(); ++k) {
    const double ratio = remainders[k] / remainders[k - 1];  // 1/4 for a second-order remainder
    CAPTURE(k);
    CHECK(ratio > 0.2);
    CHECK(ratio < 0.3);
  }
}

// ---- inputs that must fail --------------------------------------------------------------------------

TEST_CASE("bad inputs: open, inward, self-intersecting surfaces, epsilon <= 0, Gamma_N = S, kappa = 0") {
  {
    auto s = unit_sphere(320);
    s.delete_face(*s.faces().begin(), false);
    s.garbage_collection();
    auto message = error_message([&] { tetrahedralize(s); });
    MESSAGE(message);
    CHECK(contains(message, "not closed (3 boundary edges)"));
  }
  {
    // The same sphere with every face turned around.
    auto s = unit_sphere(320);
    SurfaceMesh flipped;
    for (auto vh : s.vertices()) flipped.add_vertex(s.point(vh));
    for (auto f : s.faces()) {
      auto vs = face_vertices(s, f);
      flipped.add_face(vs[0], vs[2], vs[1]);
    }
    auto message = error_message([&] { tetrahedralize(flipped); });
    MESSAGE(message);
    CHECK(contains(message, "oriented inward"));
  }
  {
    // Two overlapping closed boxes in one mesh (no coplanar faces).
    auto s = make_box(3, {0.5, 0.3, 0.4}, {1.5, 1.3, 1.4}, make_box(3, {0, 0, 0}, {1, 1, 1}));
    auto message = error_message([&] { tetrahedralize(s); });
    MESSAGE(message);
    CHECK(contains(message, "self-intersecting"));
    // Without our check, TetGen meets the intersection itself and dies in its own error path (a
    // double free): the child process it runs in crashes, the caller gets an InputError.
    message = error_message([&] { tetrahedralize(s, {.check_self_intersections = false}); });
    MESSAGE(message);
    CHECK(contains(message, "TetGen crashed"));
  }
  {
    // A vertex pushed through the opposite side of the sphere.
    auto s = unit_sphere(320);
    VertexHandle top = *s.vertices().begin();
    for (auto vh : s.vertices())
      if (s.point(vh)[2] > s.point(top)[2]) top = vh;
    s.set_point(top, Vec3(0, 0, -1.5));
    auto message = error_message([&] { tetrahedralize(s); });
    MESSAGE(message);
    CHECK(contains(message, "self-intersecting"));
  }
  {
    // Clean surfaces have no self-intersection, including coplanar neighbours (the box's faces).
    CHECK(self_intersections(unit_sphere(5120)).empty());
    CHECK(self_intersections(make_box(10, {0, 0, 0}, {1, 1, 1})).empty());
  }
  auto s = unit_sphere(320);
  VolumeMesh v = tetrahedralize(s);
  ThermalProblem problem;
  problem.robin_field.assign(s.n_vertices(), 1.0);
  auto sol = solve_thermal(v, problem);
  {
    std::vector<double> d(s.n_vertices(), 0.0);
    for (double eps : {0.0, -0.1}) {
      auto message = error_message([&] { thermal_objective(s, d, sol, {.epsilon = eps}); });
      MESSAGE(message);
      CHECK(contains(message, "ε"));
      CHECK_THROWS_AS(h_epsilon(0.1, eps), InputError);
      CHECK_THROWS_AS(band_derivative(s, d, d, sol, {.epsilon = eps}), InputError);
    }
  }
  {
    ThermalProblem all_neumann = problem;
    all_neumann.neumann.assign(s.n_faces(), 1);
    all_neumann.neumann_flux = [](const Vec3&) { return 1.0; };
    auto message = error_message([&] { ThermalSolver(v, all_neumann); });
    MESSAGE(message);
    CHECK(contains(message, "Γ_N covers all"));
  }
  {
    ThermalProblem insulated = problem;
    insulated.robin_field.assign(s.n_vertices(), 0.0);
    auto message = error_message([&] { solve_thermal(v, insulated); });
    MESSAGE(message);
    CHECK(contains(message, "vanishes on all of S"));
    // d ≥ ε everywhere: h_ε(d) = 0, the same singular system.
    ThermalProblem far = problem;
    far.robin_field.assign(s.n_vertices(), 1.0);
    far.robin_coefficient = [](double d) { return h_epsilon(d, 0.1); };
    CHECK(contains(error_message([&] { solve_thermal(v, far); }), "vanishes on all of S"));
  }
  {
    ThermalProblem negative = problem;
    negative.robin_field.assign(s.n_vertices(), -1.0);
    CHECK(contains(error_message([&] { solve_thermal(v, negative); }), "Robin coefficient is -1"));
    ThermalProblem wrong_size = problem;
    wrong_size.robin_field.assign(3, 1.0);
    CHECK(contains(error_message([&] { solve_thermal(v, wrong_size); }), "3 values"));
  }
  CHECK_THROWS_AS(tetrahedralize(s, {.radius_edge_ratio = 0.5}), InputError);
  CHECK_THROWS_AS(linear_solver_from_string("lu"), InputError);
  CHECK(linear_solver_from_string("conjugate_gradient") == LinearSolver::conjugate_gradient);
}
