// Surface P1 finite elements and the StepContext helpers, against exact values and invariants.
#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/surface_fem.hpp>
#include <bodyfit/velocity_model.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

using namespace bodyfit;

namespace {

/// The unit square [0,1]² triangulated on an n×n grid, diagonals alternating so that the mesh is
/// not symmetric in an accidental way.
SurfaceMesh flat_square(int n) { return test::grid_square(n, {.alternate_diagonals = true}); }

double sum_of_entries(const Eigen::SparseMatrix<double>& m) { return Eigen::MatrixXd(m).sum(); }

ScalarField field(const SurfaceMesh& mesh, auto&& function) {
  ScalarField f(mesh.n_vertices());
  for (auto v : mesh.vertices()) f[v.idx()] = function(mesh.point(v));
  return f;
}

double dot(const ScalarField& a, const ScalarField& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

/// Re((x + iy)^8): a spherical harmonic of degree 8 (Laplace–Beltrami eigenvalue 8·9 = 72 on the
/// unit sphere).
double harmonic8(const Vec3& p) {
  std::complex<double> z(p[0], p[1]);
  return std::pow(z, 8).real();
}

}  // namespace

TEST_CASE("mass matrix: entries sum to the area, lumped mass is its row sums") {
  SurfaceMesh square = flat_square(7);
  CHECK(sum_of_entries(mass_matrix(square)) == doctest::Approx(1.0).epsilon(1e-13));

  SurfaceMesh sphere = make_sphere({.faces = 2000});
  auto m = mass_matrix(sphere);
  CHECK(sum_of_entries(m) == doctest::Approx(total_area(sphere)).epsilon(1e-12));
  CHECK(total_area(sphere) == doctest::Approx(4 * std::numbers::pi).epsilon(1e-2));  // inscribed polyhedron
  auto lumped = lumped_mass(sphere);
  Eigen::VectorXd rows = m * Eigen::VectorXd::Ones(m.rows());
  for (std::size_t i = 0; i < lumped.size(); ++i) CHECK(lumped[i] == doctest::Approx(rows[Eigen::Index(i)]));
  // Symmetric.
  CHECK((Eigen::MatrixXd(m) - Eigen::MatrixXd(m).transpose()).norm() == doctest::Approx(0.0));
}

TEST_CASE("stiffness matrix: K·1 = 0 and uᵀKu = ∫|∇u|² exactly for a linear u") {
  SurfaceMesh square = flat_square(6);
  auto k = stiffness_matrix(square);
  Eigen::VectorXd ones = Eigen::VectorXd::Ones(k.rows());
  CHECK((k * ones).norm() < 1e-12);
  CHECK((Eigen::MatrixXd(k) - Eigen::MatrixXd(k).transpose()).norm() < 1e-12);

  // u = 1 + 2x − 3y: |∇u|² = 13 on an area of 1.
  ScalarField u = field(square, [](const Vec3& p) { return 1 + 2 * p[0] - 3 * p[1]; });
  Eigen::Map<const Eigen::VectorXd> uv(u.data(), Eigen::Index(u.size()));
  CHECK(uv.dot(k * uv) == doctest::Approx(13.0).epsilon(1e-12));

  SurfaceMesh sphere = make_sphere({.faces = 1280});
  auto ks = stiffness_matrix(sphere);
  CHECK((ks * Eigen::VectorXd::Ones(ks.rows())).norm() < 1e-10);
}

TEST_CASE("Rayleigh quotient of the degree-1 harmonic on the sphere is about its eigenvalue 2") {
  SurfaceMesh sphere = make_sphere({.faces = 5120});
  ScalarField z = field(sphere, [](const Vec3& p) { return p[2]; });
  Eigen::Map<const Eigen::VectorXd> zv(z.data(), Eigen::Index(z.size()));
  double quotient = zv.dot(stiffness_matrix(sphere) * zv) / zv.dot(mass_matrix(sphere) * zv);
  CHECK(quotient == doctest::Approx(2.0).epsilon(5e-3));
}

TEST_CASE("smallest non-zero generalized eigenvalue of (K, M) on the unit sphere is about 2") {
  // Inverse iteration through the smoother with l = 1: u = (M + K)^{-1} M f multiplies an
  // eigenvector of eigenvalue λ by 1/(1 + λ). Removing the constants (λ = 0) M-orthogonally at each
  // step leaves the smallest non-zero eigenvalue (λ1 = 2, the degree-1 harmonics, continuous value).
  SurfaceMesh sphere = make_sphere({.faces = 5120});
  auto m = mass_matrix(sphere);
  H1Smoother smoother(m, stiffness_matrix(sphere), 1.0);
  Eigen::VectorXd ones = Eigen::VectorXd::Ones(m.rows());
  const double mass_of_ones = ones.dot(m * ones);
  auto remove_constants = [&](ScalarField& f) {
    Eigen::Map<Eigen::VectorXd> fv(f.data(), Eigen::Index(f.size()));
    fv -= (ones.dot(m * fv) / mass_of_ones) * ones;
    fv /= std::sqrt(fv.dot(m * fv));
  };
  ScalarField f = field(sphere, [](const Vec3& p) { return std::sin(3 * p[0]) + p[1] * p[2] + 0.3 * p[2]; });
  remove_constants(f);
  double lambda = 0;
  for (int iteration = 0; iteration < 40; ++iteration) {
    ScalarField u = smoother.smooth(f);
    Eigen::Map<const Eigen::VectorXd> fv(f.data(), Eigen::Index(f.size())), uv(u.data(), Eigen::Index(u.size()));
    double shrink = fv.dot(m * uv);  // f is M-normalised: the Rayleigh quotient of (M + K)^{-1} M
    lambda = 1.0 / shrink - 1.0;
    f = u;
    remove_constants(f);
  }
  CHECK(lambda == doctest::Approx(2.0).epsilon(3e-3));  // measured 2.0029
}

TEST_CASE("H1 smoothing: l = 0 is the identity, constants are kept, harmonics are damped by 1/(1+l²λ)") {
  SurfaceMesh sphere = make_sphere({.faces = 20480});
  ScalarField f = field(sphere, harmonic8);

  ScalarField same = smooth_h1(sphere, f, 0.0);
  CHECK(same == f);

  H1Smoother smoother(sphere, 0.2);
  ScalarField constant(sphere.n_vertices(), 3.5);
  for (double value : smoother.smooth(constant)) CHECK(value == doctest::Approx(3.5).epsilon(1e-10));

  // Continuous solution: u = f/(1 + l²·k(k+1)) for a harmonic of degree k.
  auto m = mass_matrix(sphere);
  auto mass_norm2 = [&](const ScalarField& g) {
    Eigen::Map<const Eigen::VectorXd> gv(g.data(), Eigen::Index(g.size()));
    return gv.dot(m * gv);
  };
  for (auto harmonic : {std::pair<int, double (*)(const Vec3&)>{1, [](const Vec3& p) { return p[2]; }},
                         std::pair<int, double (*)(const Vec3&)>{8, harmonic8}}) {
    const int degree = harmonic.first;  // not a structured binding: CAPTURE (clang 14)
    const auto function = harmonic.second;
    ScalarField g = field(sphere, function);
    ScalarField u = smoother.smooth(g);
    double expected = 1.0 / (1.0 + 0.04 * degree * (degree + 1));
    // u is (nearly) a multiple of g: project to get the factor, then check the residual is small.
    double factor = dot(u, g) / dot(g, g);
    CAPTURE(degree);
    CHECK(factor == doctest::Approx(expected).epsilon(0.01));
    ScalarField residual(u.size());
    for (std::size_t i = 0; i < u.size(); ++i) residual[i] = u[i] - factor * g[i];
    CHECK(mass_norm2(residual) < 1e-3 * mass_norm2(u));
  }
  // High frequency oscillation is reduced far more than a smooth one.
  ScalarField u8 = smoother.smooth(f);
  CHECK(mass_norm2(u8) < 0.1 * mass_norm2(f));
}

TEST_CASE("H1 smoothing of a vector field returns tangent vectors") {
  SurfaceMesh sphere = make_sphere({.faces = 2000});
  VectorField f(sphere.n_vertices(), Vec3(0.3, -1.0, 2.0));
  VectorField u = smooth_h1(sphere, f, 0.3);
  for (auto v : sphere.vertices())
    CHECK(std::abs(OpenMesh::dot(u[v.idx()], vertex_normal(sphere, v))) < 1e-12);
  // A tangent field with l = 0 comes back unchanged.
  VectorField tangent(sphere.n_vertices());
  for (auto v : sphere.vertices()) tangent[v.idx()] = project_tangent(Vec3(1, 2, 3), vertex_normal(sphere, v));
  VectorField back = smooth_h1(sphere, tangent, 0.0);
  for (std::size_t i = 0; i < back.size(); ++i) CHECK((back[i] - tangent[i]).norm() < 1e-14);
}

namespace {

/// Largest deviation of the StepContext conormal from e_θ (θ the polar angle, measured from +z)
/// on a unit sphere whose region G is the cap θ < θ0, with d = θ − θ0 exact. Vertices within
/// `margin` of the poles (where d is not smooth) are skipped.
double conormal_error(std::size_t faces, double* h) {
  SurfaceMesh sphere = make_sphere({.faces = faces});
  const double theta0 = 0.9;
  ScalarField d = field(sphere, [&](const Vec3& p) { return std::acos(std::clamp(p[2], -1.0, 1.0)) - theta0; });
  StepContext context = StepContext::standalone(sphere, d);
  *h = context.mesh_size();
  const VectorField& n = context.conormal();
  double worst = 0;
  for (auto v : sphere.vertices()) {
    Vec3 p = sphere.point(v);
    double theta = std::acos(std::clamp(p[2], -1.0, 1.0));
    if (theta < 3 * *h || theta > std::numbers::pi - 3 * *h) continue;
    double phi = std::atan2(p[1], p[0]);
    Vec3 e_theta(std::cos(theta) * std::cos(phi), std::cos(theta) * std::sin(phi), -std::sin(theta));
    worst = std::max(worst, (n[v.idx()] - e_theta).norm());
  }
  return worst;
}

}  // namespace

TEST_CASE("StepContext conormal on a sphere cap points along e_theta within O(h)") {
  double h_coarse = 0, h_fine = 0;
  double coarse = conormal_error(1280, &h_coarse);
  double fine = conormal_error(20480, &h_fine);
  CAPTURE(coarse);
  CAPTURE(fine);
  CHECK(coarse < 0.3 * h_coarse);
  CHECK(fine < 0.3 * h_fine);
  CHECK(fine < 0.5 * coarse);  // h is divided by 4: at least first order
}

TEST_CASE("StepContext: state, cached geometry and helpers") {
  SurfaceMesh sphere = make_sphere({.faces = 1280});
  ScalarField d = field(sphere, [](const Vec3& p) { return p[2]; });
  StepContext context = StepContext::standalone(
      sphere, d, {.time = 1.5, .dt = 0.25, .iteration = 7, .output_dir = "out", .height_field = false, .clock_start = {}});
  CHECK(&context.mesh() == &sphere);
  CHECK(&context.distance() == &d);
  CHECK(context.time() == 1.5);
  CHECK(context.dt() == 0.25);
  CHECK(context.iteration() == 7);
  CHECK(context.output_dir() == "out");
  CHECK_FALSE(context.is_height_field());
  CHECK(context.mesh_size() == doctest::Approx(edge_length_stats(sphere).mean));

  double area = 0;
  for (double a : context.face_areas()) area += a;
  CHECK(area == doctest::Approx(total_area(sphere)));
  CHECK(&context.mass_matrix() == &context.mass_matrix());  // cached
  CHECK(sum_of_entries(context.mass_matrix()) == doctest::Approx(area));
  for (auto v : sphere.vertices()) {
    CHECK((context.vertex_normals()[v.idx()] - sphere.point(v)).norm() < 0.05);  // unit sphere: n ≈ p
  }
  for (auto f : sphere.faces()) CHECK(OpenMesh::dot(context.face_normals()[f.idx()], face_points(sphere, f)[0]) > 0);

  // Gradients of z: ∇_S z = e_z − (e_z·n)n.
  VectorField g = context.vertex_gradients(d);
  for (auto v : sphere.vertices()) {
    Vec3 n = sphere.point(v);
    CHECK((g[v.idx()] - (Vec3(0, 0, 1) - n[2] * n)).norm() < 0.05);
  }
  CHECK(context.face_gradients(d).size() == sphere.n_faces());

  // Smoothing through the context equals the stand-alone smoother.
  ScalarField smoothed = context.smooth(d, 0.3);
  ScalarField expected = smooth_h1(sphere, d, 0.3);
  for (std::size_t i = 0; i < d.size(); ++i) CHECK(smoothed[i] == doctest::Approx(expected[i]).epsilon(1e-12));
  CHECK(context.smooth(d, 0.0) == d);
  CHECK_THROWS_AS(context.smooth(d, -1.0), InputError);
}

TEST_CASE("surface divergence: div_S of the tangential part of a constant vector on the unit sphere is -2 a·x") {
  // V = a − (a·x) x, div_S V = −2 a·x exactly; the weak lumped form converges at first order or better.
  const Vec3 a(0.3, -0.2, 0.9);
  std::vector<double> errors;
  for (std::size_t faces : {1280u, 5120u, 20480u}) {
    const SurfaceMesh sphere = make_sphere({.faces = faces});
    VectorField v(sphere.n_vertices());
    for (auto vh : sphere.vertices()) {
      const Vec3 x = sphere.point(vh);
      v[vh.idx()] = a - OpenMesh::dot(a, x) * x;
    }
    const ScalarField div = surface_divergence(sphere, v);
    double worst = 0;
    for (auto vh : sphere.vertices())
      worst = std::max(worst, std::abs(div[vh.idx()] + 2 * OpenMesh::dot(a, sphere.point(vh))));
    errors.push_back(worst);
    // The divergence theorem on a closed surface: Σ m_i div_i = 0.
    const std::vector<double> mass = lumped_mass(sphere);
    double flux = 0;
    for (std::size_t i = 0; i < div.size(); ++i) flux += mass[i] * div[i];
    CHECK(std::abs(flux) < 1e-12);
  }
  CHECK(errors[0] < 0.05);
  CHECK(errors[1] < 0.6 * errors[0]);  // h halves: at least first order
  CHECK(errors[2] < 0.6 * errors[1]);
}

TEST_CASE("StepContext::front_curvature: the circles of a cap on the unit sphere have geodesic curvature cot θ") {
  // d = θ − θ0 (the signed geodesic distance to the cap of polar angle θ0): n_Σ = e_θ and
  // κ = div_S e_θ = cot θ, exact at every vertex but near the poles, where it is singular. The
  // mass-weighted RMS error over |z| ≤ 0.8 converges (order ~1.6); the largest error stays ~0.02,
  // at the sphere's irregular vertices.
  std::vector<double> errors, largest;
  for (std::size_t faces : {1280u, 5120u, 20480u}) {
    const SurfaceMesh sphere = make_sphere({.faces = faces});
    ScalarField d(sphere.n_vertices());
    for (auto vh : sphere.vertices()) d[vh.idx()] = std::acos(std::clamp(sphere.point(vh)[2], -1.0, 1.0)) - 0.8;
    const StepContext context = StepContext::standalone(sphere, d);
    const ScalarField& kappa = context.front_curvature();
    CHECK(&kappa == &context.front_curvature());  // computed once
    const std::vector<double>& mass = context.lumped_mass();
    double worst = 0, squares = 0, weight = 0;
    for (auto vh : sphere.vertices()) {
      const double z = sphere.point(vh)[2];
      if (std::abs(z) > 0.8) continue;
      const double theta = std::acos(z);
      const double error = std::abs(kappa[vh.idx()] - std::cos(theta) / std::sin(theta));
      worst = std::max(worst, error);
      squares += mass[vh.idx()] * error * error, weight += mass[vh.idx()];
    }
    errors.push_back(std::sqrt(squares / weight));
    largest.push_back(worst);
    // Near a pole the curvature grows like 1/θ: the singularity the documentation warns of.
    double at_pole = 0;
    for (auto vh : sphere.vertices())
      if (sphere.point(vh)[2] > 0.999) at_pole = std::max(at_pole, std::abs(kappa[vh.idx()]));
    CHECK(at_pole > 5);
  }
  CHECK(errors[0] < 0.01);
  CHECK(errors[1] < 0.5 * errors[0]);
  CHECK(errors[2] < 0.5 * errors[1]);
  for (double worst : largest) CHECK(worst < 0.04);
}
