// The thermal model's objectives and the derivative it follows: each functional's adjoint against
// finite differences of J when the region G moves (its radius and its centre: the distance is
// recomputed for the moved G), the band's derivative carried onto Σ against finite differences of
// moving a disk cut into the mesh, the speed extended along Σ's normals, and the descent's rules
// (merit, sufficient decrease, noise, trust region, stops, continuation stages) on numbers.
#include "descent.hpp"
#include "objective.hpp"
#include "shape_derivative.hpp"
#include "smoothing.hpp"
#include "surface_transfer.hpp"
#include "thermal_fem.hpp"
#include "thermal_fixtures.hpp"
#include "volume_mesh.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/levelset_mesher.hpp>
#include <bodyfit/projection.hpp>
#include <bodyfit/surface_fem.hpp>

#include <doctest/doctest.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace bodyfit;
using namespace bodyfit::thermal;
using bodyfit::test::DiskOnCube;

namespace {

constexpr double kEpsilon = 0.15;

ObjectiveSpec spec_of(ObjectiveKind kind) {
  ObjectiveSpec spec;
  spec.kind = kind;
  spec.exponent = 8;
  spec.boxes = {{-1, -1, 0, 1, 1, 1}};  // the upper half of the cube, next to the disk
  return spec;
}

/// ∂d/∂δ for the disk's radius R + δ (s ≡ −1 on the top face) or its centre moved to (δ, 0, 1)
/// (s = −x/r): d of the moved disk is exact, so these are the geometry's own perturbations.
std::vector<double> perturbation(const SurfaceMesh& s, bool centre) {
  std::vector<double> out(s.n_vertices(), 0.0);
  for (auto v : s.vertices()) {
    const Vec3& p = s.point(v);
    if (p[2] != 1) continue;
    const double r = std::hypot(p[0], p[1]);
    out[std::size_t(v.idx())] = centre ? (r > 0 ? -p[0] / r : 0.0) : -1.0;
  }
  return out;
}

}  // namespace

TEST_CASE("every objective's adjoint against central finite differences of J as the disk G grows and moves") {
  // Mean and L^8 temperature, the mean over the upper half, the dissipation ∫γ|∇u|²: j′(u) drives
  // the adjoint, and the band formula pᵀ(dR)u must be the derivative of J = j(u(G)) for each.
  const DiskOnCube disk(0.45);
  const SurfaceMesh& s = disk.surface;
  const VolumeMesh v = tetrahedralize(s, {.max_volume = regular_tet_volume(0.125)});
  for (ObjectiveKind kind : {ObjectiveKind::mean_temperature, ObjectiveKind::max_temperature,
                             ObjectiveKind::region_mean, ObjectiveKind::dissipation}) {
    CAPTURE(to_string(kind));
    ThermalProblem problem;
    problem.robin_field = disk.distance(disk.R);
    problem.robin_coefficient = [](double d) { return h_epsilon(d, kEpsilon); };
    problem.objective = spec_of(kind);
    ThermalSolver solver(v, problem);
    const ObjectiveOptions options{.epsilon = kEpsilon, .ell = 0};
    const auto solution = solver.solve();
    CHECK(solution.objective == doctest::Approx(solver.functional().value(solution.u)).epsilon(1e-14));
    for (bool centre : {false, true}) {
      CAPTURE(centre);
      const double band = band_derivative(s, problem.robin_field, perturbation(s, centre), solution, options);
      const double delta = 1e-4 * kEpsilon;
      auto J = [&](double shift) {
        const auto d = centre ? disk.distance(disk.R, shift) : disk.distance(disk.R + shift);
        return thermal_objective(s, d, solver.solve(d), options).J;
      };
      const double fd = (J(delta) - J(-delta)) / (2 * delta);
      const double scale = centre ? std::abs(J(0)) : std::abs(band);  // the centre's derivative is 0 by symmetry
      MESSAGE(fmt::format("{}, {}: dJ finite difference {:.10e}, band {:.10e}", to_string(kind),
                          centre ? "centre" : "radius", fd, band));
      CHECK(std::abs(fd - band) <= 1e-6 * scale + 1e-6 * std::abs(band));
    }
  }
}

TEST_CASE("objectives: the L^q mean tends to max u, the dissipation is |Omega| T - u'Ru, bad regions are refused") {
  const DiskOnCube disk(0.45);
  const VolumeMesh v = tetrahedralize(disk.surface, {.max_volume = regular_tet_volume(0.125)});
  ThermalProblem problem;
  problem.robin_field = disk.distance(disk.R);
  problem.robin_coefficient = [](double d) { return h_epsilon(d, kEpsilon); };
  const auto solution = solve_thermal(v, problem);
  const SparseMatrix K = assemble_stiffness(v);
  const Eigen::VectorXd weights = assemble_volume_weights(v);
  const double top = solution.u.maxCoeff();
  double previous = 0;
  for (double q : {1.0, 8.0, 64.0, 512.0}) {
    ObjectiveSpec spec;
    spec.kind = ObjectiveKind::max_temperature;
    spec.exponent = q;
    const double j = TemperatureFunctional(v, spec, K, weights).value(solution.u);
    MESSAGE(fmt::format("q = {}: j = {:.6f}, max u = {:.6f}", q, j, top));
    CHECK(j > previous);  // the L^q means increase with q ...
    CHECK(j <= top * (1 + 1e-12));  // ... towards the maximum
    previous = j;
  }
  CHECK(previous > 0.98 * top);
  // q = 1 is the mean temperature (u > 0).
  ObjectiveSpec mean;
  CHECK(TemperatureFunctional(v, mean, K, weights).value(solution.u) == doctest::Approx(solution.mean_temperature));
  // With f = 1 and no boundary source, uᵀ(K + R)u = 1ᵀ(weights ∘ u) = |Ω|T: the dissipation is |Ω|T − uᵀRu.
  const SparseMatrix R = assemble_robin(v, problem.robin_field, problem.robin_coefficient);
  ObjectiveSpec dissipation;
  dissipation.kind = ObjectiveKind::dissipation;
  const double j = TemperatureFunctional(v, dissipation, K, weights).value(solution.u);
  CHECK(j == doctest::Approx(solution.volume * solution.mean_temperature - solution.u.dot(R * solution.u)).epsilon(1e-10));

  ObjectiveSpec outside;
  outside.kind = ObjectiveKind::region_mean;
  outside.boxes = {{2, 2, 2, 3, 3, 3}};
  try {
    TemperatureFunctional(v, outside, K, weights);
    FAIL("a region outside the part was accepted");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()).find("contain no tetrahedron") != std::string::npos);
  }
  ObjectiveSpec low;
  low.kind = ObjectiveKind::max_temperature;
  low.exponent = 0.5;
  CHECK_THROWS_AS(TemperatureFunctional(v, low, K, weights), InputError);
  CHECK_THROWS_AS(objective_kind_from_string("hottest"), InputError);
}

TEST_CASE("the band's derivative carried onto Sigma against finite differences of moving a disk cut into the mesh") {
  // The disk's circle is cut into the cube's mesh (Σ a polygon on the circle). Moving the centre
  // by δ along x moves Σ with the normal speed θ·n = x/R: d moves by −(θ·n)∘π_Σ exactly, so
  // dJ/dδ = bᵀv with v = θ·n at Σ's vertices and b the band's derivative carried onto Σ.
  DiskOnCube disk(0.45);
  SurfaceMesh& s = disk.surface;
  discretize(s, disk.distance(disk.R));
  const std::vector<double> d = disk.distance(disk.R);
  const VolumeMesh v = tetrahedralize(s, {.max_volume = regular_tet_volume(0.125)});
  ThermalProblem problem;
  problem.robin_field = d;
  problem.robin_coefficient = [](double x) { return h_epsilon(x, kEpsilon); };
  ThermalSolver solver(v, problem);
  const ObjectiveOptions options{.epsilon = kEpsilon, .ell = 0};
  const auto solution = solver.solve();

  const InterfaceProjection projection = project_onto_interface(s, kEpsilon + 0.25);
  const Eigen::VectorXd b = projected_band_load(projection, band_weights(s, d, solution, options), s.n_vertices());
  std::vector<double> speed(s.n_vertices(), 0.0);
  std::size_t on_sigma = 0;
  for (auto vh : s.vertices()) {
    const Vec3& p = s.point(vh);
    speed[std::size_t(vh.idx())] = p[2] == 1 ? p[0] / std::max(std::hypot(p[0], p[1]), 1e-12) : 0.0;
    on_sigma += b[vh.idx()] != 0;
  }
  double predicted = 0;
  for (std::size_t i = 0; i < speed.size(); ++i) predicted += b[Eigen::Index(i)] * speed[i];
  // The rigid motion of the disk changes J only through the mesh (the cube is symmetric about x = 0
  // but its gridding is not): compare the derivative along the radius instead, whose v ≡ 1.
  double radial = 0;
  for (Eigen::Index i = 0; i < b.size(); ++i) radial += b[i];
  const double delta = 1e-4 * kEpsilon;
  auto J = [&](double radius) { return thermal_objective(s, disk.distance(radius), solver.solve(disk.distance(radius)), options).J; };
  const double fd = (J(disk.R + delta) - J(disk.R - delta)) / (2 * delta);
  MESSAGE(fmt::format("dJ/dR: finite difference {:.8e}, carried onto Σ {:.8e} ({} vertices of Σ loaded); along x: {:.3e}",
                      fd, radial, on_sigma, predicted));
  CHECK(on_sigma > 20);
  CHECK(radial == doctest::Approx(fd).epsilon(1e-6));  // Σ_k W_k: the same sum, any projection
  CHECK(std::abs(predicted) < 0.02 * std::abs(radial));  // ∫ w cos φ on a circle: small against ∫ w

  // v∘π_Σ: equal to v on Σ and, off Σ, to v at the closest point of Σ.
  std::vector<double> x(s.n_vertices());
  for (auto vh : s.vertices()) x[std::size_t(vh.idx())] = s.point(vh)[0];
  const std::vector<double> extended = extend_from_interface(projection, x);
  double worst = 0;
  std::size_t off = 0;
  for (auto vh : s.vertices()) {
    const auto k = std::size_t(vh.idx());
    if (projection.from[k] < 0) continue;
    const Vec3& p = s.point(vh);
    const double r = std::hypot(p[0], p[1]);
    if (d[k] == 0) CHECK(extended[k] == doctest::Approx(x[k]).epsilon(1e-12));
    if (p[2] == 1 && std::abs(d[k]) < kEpsilon) {  // the band, where the load comes from
      worst = std::max(worst, std::abs(extended[k] - disk.R * p[0] / r));  // x at the circle's closest point
      ++off;
    }
  }
  MESSAGE(fmt::format("v∘π_Σ against v at the circle's closest point: worst {:.3e} over {} vertices", worst, off));
  CHECK(off > 50);
  CHECK(worst < 0.01);  // the polygon's chords against the circle: O(h²/R)
}

// ---- the descent's rules -----------------------------------------------------------------------------

TEST_CASE("descent: merit and slope weight with an area target, sufficient decrease, noise learnt from retries") {
  DescentOptions o;
  o.ell = 0.01;
  o.target = 2.0;
  o.penalty = 4.0;
  o.armijo = 0.5;
  o.noise = 0.001;
  Descent d(o);
  d.set_lambda(0.3);
  // M = j + ℓA + λ(A − A*) + μ/2 (A − A*)²; ℓ_eff = ℓ + λ + μ(A − A*).
  CHECK(d.merit(1.0, 2.5) == doctest::Approx(1.0 + 0.025 + 0.3 * 0.5 + 2.0 * 0.25));
  CHECK(d.area_weight(2.5) == doctest::Approx(0.01 + 0.3 + 4.0 * 0.5));
  // Accepted: M drops by at least half the predicted decrease (up to the noise); rejected otherwise.
  const double M = d.merit(1.0, 2.0);
  CHECK(d.judge(1.0, 2.0, -1.0, 0.1, 1.0, 1.0 - 0.06, 2.0, 0).accept);
  CHECK_FALSE(d.judge(1.0, 2.0, -1.0, 0.1, 1.0, 1.0 - 0.04, 2.0, 0).accept);
  CHECK(d.judge(1.0, 2.0, -1.0, 0.1, 1.0, 1.0 - 0.04, 2.0, 0).bound == doctest::Approx(M - 0.05 + 0.001 * M));
  // A retry whose deviation from the first-order model does not shrink is noise: the noise grows to
  // twice its rise; a deviation that shrinks like Δt² is curvature and leaves it alone.
  CHECK_FALSE(d.judge(1.0, 2.0, -1.0, 0.02, 1.0, 1.0 + 0.004, 2.0, 0).accept);
  CHECK_FALSE(d.judge(1.0, 2.0, -1.0, 0.01, 1.0, 1.0 + 0.0035, 2.0, 1).accept);
  CHECK(d.options().noise == doctest::Approx(2 * 0.0035 / M));
  Descent curved(o);
  CHECK_FALSE(curved.judge(1.0, 2.0, -1.0, 0.4, 1.0, 1.0 + 0.4, 2.0, 0).accept);     // deviation 0.8
  CHECK_FALSE(curved.judge(1.0, 2.0, -1.0, 0.2, 1.0, 1.0 + 0.0, 2.0, 1).accept);     // deviation 0.2: a quarter
  CHECK(curved.options().noise == 0.001);
  // The noise never exceeds max_noise.
  Descent capped(o);
  capped.judge(1.0, 2.0, -1.0, 0.02, 1.0, 1.5, 2.0, 0);
  capped.judge(1.0, 2.0, -1.0, 0.01, 1.0, 1.5, 2.0, 1);
  CHECK(capped.options().noise == doctest::Approx(o.max_noise));
  // The shortest step is taken even when it raises M (a jump of the discretisation).
  o.min_step = 0.01;
  Descent shortest(o);
  const auto forced = shortest.judge(1.0, 2.0, -1.0, 0.01, 1.0, 1.5, 2.0, 3);
  CHECK(forced.accept);
  CHECK(forced.forced);
}

TEST_CASE("descent: the trust region grows after a clean step, holds after a rejection, halves after a rise") {
  DescentOptions o;
  o.grow = 1.5;
  o.max_motion = 0.1;
  o.max_step = 10;
  o.min_step = 0.001;
  Descent d(o);
  // A clean first-attempt step: Δt grows, within max_motion / speed.
  CHECK(d.next_step(0.02, 1.0, 0, false, 1.0) == doctest::Approx(0.03));
  CHECK(d.next_step(0.08, 1.0, 0, false, 1.0) == doctest::Approx(0.1));  // the motion's cap
  CHECK(d.next_step(0.08, 1.0, 0, false, 0.25) == doctest::Approx(0.12));  // slower speed: longer Δt
  // Accepted after a rejection: no growth, and the region shrinks to the motion taken.
  CHECK(d.next_step(0.05, 0.5, 2, false, 0.5) == doctest::Approx(0.05));
  CHECK(d.motion() == doctest::Approx(0.025));
  // A step that raised M: the region halves the motion taken, Δt does not grow.
  CHECK(d.next_step(0.05, 0.5, 0, true, 0.5) == doctest::Approx(0.025));
  CHECK(d.motion() == doctest::Approx(0.0125));
  // Never below min_step.
  d.set_motion(1e-6);
  CHECK(d.next_step(0.05, 1.0, 0, true, 1.0) == doctest::Approx(0.001));
  // A new stage starts with the whole region.
  d.accept(1.0, 1.0);
  d.new_stage(0.9, 1.0);
  CHECK(d.stage_step(0.5) == doctest::Approx(0.2));
}

TEST_CASE("descent: stationary and stalled stops, per stage, and the area target's multiplier") {
  DescentOptions o;
  o.stationarity = 0.01;
  o.patience = 3;
  o.tolerance = 1e-3;
  Descent d(o);
  d.accept(1.0, 1.0);
  d.set_slope(-2.0);
  CHECK(d.stop_reason().empty());
  d.accept(0.9, 1.0);
  d.set_slope(-0.1);
  CHECK(d.stop_reason().empty());
  d.accept(0.85, 1.0);
  d.set_slope(-0.019);
  CHECK(d.stop_reason().find("stationary") == 0);
  // A new stage measures stationarity against its own first slope.
  d.new_stage(0.7, 1.0);
  d.set_slope(-0.5);
  CHECK(d.stop_reason().empty());
  CHECK(d.stage() == 1);
  // Stalled: the best merit of the last `patience` records is not below the best before them.
  for (double j : {0.69, 0.6901, 0.6902, 0.6899}) {
    d.accept(j, 1.0);
    d.set_slope(-0.4);
  }
  CHECK(d.stop_reason().find("stalled") == 0);

  // λ ← λ + μ(|G| − A) every update_every records; no stationary stop off the target.
  DescentOptions a;
  a.target = 1.0;
  a.penalty = 2.0;
  a.update_every = 2;
  a.stationarity = 0.5;
  Descent al(a);
  al.accept(1.0, 1.5);
  al.set_slope(-1.0);
  CHECK(al.lambda() == 0);
  al.accept(0.9, 1.25);
  CHECK(al.lambda() == doctest::Approx(0.5));
  al.set_slope(-0.1);
  CHECK(al.stop_reason().empty());  // stationary but 25 % off the target
  al.accept(0.9, 1.001);
  al.set_slope(-0.1);
  CHECK(al.stop_reason().find("stationary") == 0);  // 0.1 % off: within area_tolerance (0.5 %)
}

TEST_CASE("surface transfer: a linear field carried between two meshes of the unit sphere, to the chords' sagitta") {
  // f = x + 2y − z sampled on a coarse and a fine sphere: at each fine vertex, the coarse mesh's
  // field at the closest point differs from f there by at most |∇f| = √6 times the distance between
  // the meshes: a coarse triangle's sagitta, r_c²/2 ≤ h²/6 for a circumradius r_c ≤ h/√3.
  const SurfaceMesh coarse = bodyfit::test::unit_sphere(1280), fine = bodyfit::test::unit_sphere(5120);
  std::vector<double> f(coarse.n_vertices());
  for (auto v : coarse.vertices()) {
    const Vec3& p = coarse.point(v);
    f[std::size_t(v.idx())] = p[0] + 2 * p[1] - p[2];
  }
  const ReferenceSurface reference(coarse);
  const std::vector<double> carried = interpolate(locate(coarse, reference, vertex_points(fine)), f);
  double worst = 0;
  for (auto v : fine.vertices()) {
    const Vec3& p = fine.point(v);
    worst = std::max(worst, std::abs(carried[std::size_t(v.idx())] - (p[0] + 2 * p[1] - p[2])));
  }
  double h = 0;
  for (auto e : coarse.edges()) h = std::max(h, coarse.calc_edge_length(e));
  MESSAGE(fmt::format("worst difference {:.3e}, bound sqrt(6) h^2/6 = {:.3e} (h = {:.3f})", worst, std::sqrt(6.0) * h * h / 6, h));
  CHECK(worst <= std::sqrt(6.0) * h * h / 6);
  CHECK(worst > 0);
  // A mesh with deleted elements must be garbage-collected first.
  SurfaceMesh holed = coarse;
  holed.delete_face(*holed.faces().begin(), false);
  const ReferenceSurface holed_reference(holed);
  CHECK_THROWS_AS(locate(holed, holed_reference, vertex_points(fine)), InputError);
}
