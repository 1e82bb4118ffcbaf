// The sharp problem (4.12) on the body-fitted volume mesh: u = 0 on G exactly. Against the exact
// solution on the ball held at 0 on its whole sphere, and the smoothed problem's T_ε → T as ε → 0.
#include "sharp_problem.hpp"
#include "thermal_fixtures.hpp"
#include "smoothing.hpp"
#include "thermal_fem.hpp"
#include "volume_mesh.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>

#include <doctest/doctest.h>
#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <vector>

using namespace bodyfit;
using namespace bodyfit::thermal;
using bodyfit::test::unit_sphere;

namespace {

double order(double e0, double e1, double h0, double h1) { return std::log(e0 / e1) / std::log(h0 / h1); }

}  // namespace

TEST_CASE("sharp problem on the unit ball held at 0 on its sphere: u = (1 - r^2)/6, second order") {
  std::vector<double> hs, nodal, mean_error;
  for (std::size_t faces : {320, 1280, 5120}) {
    const SurfaceMesh s = unit_sphere(faces);
    const double h = edge_length_stats(s).mean;
    const VolumeMesh v = tetrahedralize(s, {.max_volume = regular_tet_volume(h)});
    const SharpSolution sol = solve_sharp(v, {}, FaceMask(s.n_faces(), 1));
    double max_error = 0;
    for (std::size_t i = 0; i < v.points.size(); ++i)
      max_error = std::max(max_error, std::abs(sol.u[Eigen::Index(i)] - (1 - v.points[i].sqrnorm()) / 6));
    // T = (1/|B|)∫ (1 − r²)/6 = 1/15 on the ball.
    MESSAGE(fmt::format("h = {:.3f}: {} tets, nodal max error {:.2e}, T = {:.6f} (exact 1/15 = {:.6f})", h,
                        v.tets.size(), max_error, sol.mean_temperature, 1.0 / 15));
    hs.push_back(h);
    nodal.push_back(max_error);
    mean_error.push_back(std::abs(sol.mean_temperature - 1.0 / 15));
    CHECK(sol.u.head(v.n_surface_vertices).cwiseAbs().maxCoeff() == 0);  // held at 0 on G
  }
  for (std::size_t k = 1; k < hs.size(); ++k) {
    CHECK(order(nodal[k - 1], nodal[k], hs[k - 1], hs[k]) > 1.7);
    CHECK(order(mean_error[k - 1], mean_error[k], hs[k - 1], hs[k]) > 1.7);
  }
}

TEST_CASE("T_eps -> T: on the ball held at 0 everywhere, T_eps - T = eps/3 (Robin coefficient 1/eps)") {
  // With d_G ≤ −ε on all of S, h_ε(d_G) = 1/ε: the smoothed problem is the Robin problem whose
  // solution is (1 − r²)/6 + ε/3, so T_ε − T = ε/3 exactly; the discrete ones agree to O(h²).
  const SurfaceMesh s = unit_sphere(1280);
  const VolumeMesh v = tetrahedralize(s, {.max_volume = regular_tet_volume(edge_length_stats(s).mean)});
  const double T = solve_sharp(v, {}, FaceMask(s.n_faces(), 1)).mean_temperature;
  for (double epsilon : {0.2, 0.1, 0.05}) {
    ThermalProblem problem;
    problem.robin_field.assign(s.n_vertices(), -1.0);
    problem.robin_coefficient = [epsilon](double d) { return h_epsilon(d, epsilon); };
    const double T_epsilon = solve_thermal(v, problem).mean_temperature;
    MESSAGE(fmt::format("eps = {}: T_eps = {:.6f}, T = {:.6f}, (T_eps - T)/eps = {:.4f} (exact 1/3)", epsilon,
                        T_epsilon, T, (T_epsilon - T) / epsilon));
    CHECK((T_epsilon - T) / epsilon == doctest::Approx(1.0 / 3).epsilon(0.02));
  }
}

TEST_CASE("T_eps -> T on the ball held at 0 on a hemisphere, and the sharp problem's bad inputs") {
  // G: the faces below the equator; d_G = asin(z) is the signed geodesic distance to the equator on
  // the unit sphere. |T_ε − T| falls as ε does.
  const SurfaceMesh s = unit_sphere(5120);
  const VolumeMesh v = tetrahedralize(s, {.max_volume = regular_tet_volume(edge_length_stats(s).mean)});
  FaceMask lower(s.n_faces(), 0);
  for (auto f : s.faces()) lower[std::size_t(f.idx())] = s.calc_face_centroid(f)[2] < 0;
  const double T = solve_sharp(v, {}, lower).mean_temperature;
  std::vector<double> distance(s.n_vertices());
  for (auto vh : s.vertices()) distance[std::size_t(vh.idx())] = std::asin(std::clamp(s.point(vh)[2], -1.0, 1.0));
  std::vector<double> gaps;
  for (double epsilon : {0.4, 0.2, 0.1}) {
    ThermalProblem problem;
    problem.robin_field = distance;
    problem.robin_coefficient = [epsilon](double d) { return h_epsilon(d, epsilon); };
    const double T_epsilon = solve_thermal(v, problem).mean_temperature;
    gaps.push_back(std::abs(T_epsilon - T));
    MESSAGE(fmt::format("hemisphere, eps = {}: T_eps = {:.6f}, T = {:.6f}", epsilon, T_epsilon, T));
  }
  // At least order 1/2 in ε: u ~ √r at Σ, where the boundary condition changes (measured: 0.8).
  CHECK(gaps[1] < std::sqrt(0.5) * gaps[0]);
  CHECK(gaps[2] < std::sqrt(0.5) * gaps[1]);
  MESSAGE(fmt::format("order in eps: {:.2f}, {:.2f}", order(gaps[0], gaps[1], 0.4, 0.2), order(gaps[1], gaps[2], 0.2, 0.1)));
  // No G: no solution; a G face in the Neumann boxes: refused.
  CHECK_THROWS_WITH_AS(solve_sharp(v, {}, FaceMask(s.n_faces(), 0)), doctest::Contains("G is empty"), InputError);
  ThermalProblem neumann;
  neumann.neumann = lower;
  CHECK_THROWS_WITH_AS(solve_sharp(v, neumann, lower), doctest::Contains("both in G and in the Neumann boxes"),
                       InputError);
}
