// Benchmark of the thermal model's numerical core (plugins/thermal, docs/validation/thermal_solvers.md): TetGen,
// assembly, and the linear solvers on the state + adjoint of a unit ball whose skin is cooled on a
// polar cap G (κ = h_ε(d), ε = 2h by default, d the distance along the sphere to the cap's circle).
//
//   bench_thermal_solvers [--faces 1280,3500,8000] [--solvers all|name,...] [--repeat 3] [--eps 2] [-o file.csv]
//
// Each size: make_sphere(faces), tetrahedralize with max_volume = regular_tet_volume(h) (h the mean
// surface edge), then per solver: the first solve (symbolic analysis + factorisation + the two solves in
// one call) and `repeat` more solves with a moved cap (the pattern reused: factorisation + solves, the
// conjugate gradient started from the previous solution), the time per iteration of the optimisation
// loop. Differences of u and p are against the first solver.
#include "linear_solver.hpp"
#include "smoothing.hpp"
#include "thermal_fem.hpp"
#include "volume_mesh.hpp"

#include "bench_args.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace bodyfit;
using namespace bodyfit::thermal;

namespace {

constexpr const char* kUsage =
    "usage: bench_thermal_solvers [--faces 1280,3500,8000] [--solvers all|name,...] [--repeat 3] [--eps 2] [-o file.csv]\n"
    "  --faces    surface triangles of the unit spheres (one row per size and solver)\n"
    "  --solvers  cholmod_supernodal, cholmod_simplicial, eigen_simplicial, conjugate_gradient, or all\n"
    "             (default: all but eigen_simplicial, which takes minutes at 8000 faces)\n"
    "  --repeat   solves after the first one, each with a moved cap (default 3)\n"
    "  --eps      ε of the Robin coefficient h_ε in units of the mean surface edge h (default 2)\n"
    "  -o         CSV output (default bench_thermal_solvers.csv)\n";

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// CPU time of the process (all threads, BLAS's included), ms: the figure that a machine shared with
/// other jobs disturbs least.
double cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return 1e3 * double(t.tv_sec) + 1e-6 * double(t.tv_nsec);
}

std::vector<std::string> split(const std::string& list) {
  std::vector<std::string> items;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) items.push_back(item);
  return items;
}

/// Signed distance along the unit sphere to the circle of polar angle `angle` (negative inside the cap).
std::vector<double> cap_distance(const SurfaceMesh& s, double angle) {
  std::vector<double> d(s.n_vertices());
  for (auto v : s.vertices()) {
    const Vec3& p = s.point(v);
    d[std::size_t(v.idx())] = std::acos(std::clamp(p[2] / p.norm(), -1.0, 1.0)) - angle;
  }
  return d;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::size_t> sizes{1280, 3500, 8000};  // about 17k, 83k, 290k tetrahedra
  const std::vector<LinearSolver> all{LinearSolver::cholmod_supernodal, LinearSolver::cholmod_simplicial,
                                      LinearSolver::eigen_simplicial, LinearSolver::conjugate_gradient};
  // Eigen's LDLᵀ takes minutes at 290k tetrahedra: only on request.
  std::vector<LinearSolver> solvers{LinearSolver::cholmod_supernodal, LinearSolver::cholmod_simplicial,
                                    LinearSolver::conjugate_gradient};
  int repeat = 3;
  double eps_ratio = 2;
  std::string csv_path = "bench_thermal_solvers.csv";
  bench::Arguments args("bench_thermal_solvers", kUsage);
  args.option("--faces", sizes);
  args.option("--solvers", [&](const std::string& list) {
    solvers.clear();
    if (list == "all") solvers = all;
    else
      for (const auto& item : split(list)) solvers.push_back(linear_solver_from_string(item));
  });
  args.option("--repeat", repeat);
  args.option("--eps", eps_ratio);
  args.option("-o", csv_path);
  args.parse(argc, argv);
  if (sizes.empty() || solvers.empty() || repeat < 0 || !(eps_ratio > 0)) args.fail("nothing to measure");

  std::ofstream csv(csv_path);
  csv << "surface_faces,h,tets,vertices,min_dihedral_deg,tetgen_ms,setup_ms,robin_ms,solver,analysis_ms,"
         "factorization_ms,solve_ms,first_total_ms,refactorization_ms,resolve_ms,iteration_ms,cg_iterations,"
         "cg_iterations_warm,factor_nonzeros,factor_flops,ordering,max_diff_u,max_diff_p,mean_temperature,first_cpu_ms,"
         "iteration_cpu_ms\n";
  fmt::print("{:>7} {:>8} {:>7} {:>8} {:>8} {:>8} | {:<19} {:>8} {:>8} {:>7} {:>8} {:>8} | {:>8} {:>8} {:>8} {:>9} {:>9}  {}\n",
             "faces", "tets", "verts", "tetgen", "setup", "robin", "solver", "analyse", "factor", "solve", "first",
             "first", "refactor", "iterate", "iterate", "max|du|", "max|dp|",
             "CG iterations cold/warm, or nnz(L) GFlop/s ordering");
  fmt::print("{:>7} {:>8} {:>7} {:>8} {:>8} {:>8} | {:<19} {:>8} {:>8} {:>7} {:>8} {:>8} | {:>8} {:>8} {:>8} {:>9} {:>9}\n",
             "", "", "", "ms", "ms", "ms", "", "ms", "ms", "ms", "ms", "cpu ms", "ms", "ms", "cpu ms", "(rel)", "(rel)");
  for (std::size_t faces : sizes) {
    SurfaceMesh s = make_sphere({.faces = faces});
    double h = edge_length_stats(s).mean;
    auto t0 = std::chrono::steady_clock::now();
    VolumeMesh mesh = tetrahedralize(s, {.max_volume = regular_tet_volume(h)});
    double tetgen_ms = ms_since(t0);
    auto stats = volume_stats(mesh);

    const double eps = eps_ratio * h;
    ThermalProblem problem;
    problem.robin_field = cap_distance(s, 0.6);
    problem.robin_coefficient = [eps](double d) { return h_epsilon(d, eps); };

    Eigen::VectorXd u_ref, p_ref;
    for (LinearSolver solver : solvers) {
      ThermalOptions options;
      options.linear.solver = solver;
      ThermalSolver thermal(mesh, problem, options);
      double c0 = cpu_ms();
      auto first = thermal.solve();
      double first_cpu = cpu_ms() - c0;
      LinearSolverStats linear = thermal.linear_stats();  // the first solve's (analysis included)
      double refactor = 0, resolve = 0, iteration = 0, cg_next = 0, iteration_cpu = 0;
      for (int k = 0; k < repeat; ++k) {
        // The next iterate: the cap moved a little (the pattern of K + R does not change).
        auto field = cap_distance(s, 0.6 + 0.01 * (k + 1));
        auto t1 = std::chrono::steady_clock::now();
        double c1 = cpu_ms();
        auto next = thermal.solve(field);
        iteration_cpu += cpu_ms() - c1;
        iteration += ms_since(t1);
        refactor += next.timings.factorization_ms;
        resolve += next.timings.solve_ms;
        cg_next += next.timings.cg_iterations;
      }
      if (repeat > 0) refactor /= repeat, resolve /= repeat, iteration /= repeat, cg_next /= repeat, iteration_cpu /= repeat;
      // Achieved rate of the numeric factorisation (CHOLMOD's flop count of the analysis).
      double gflops = linear.factor_flops > 0 && refactor > 0 ? linear.factor_flops / (refactor * 1e6) : 0;
      if (u_ref.size() == 0) u_ref = first.u, p_ref = first.p;
      double du = (first.u - u_ref).cwiseAbs().maxCoeff() / u_ref.cwiseAbs().maxCoeff();
      double dp = (first.p - p_ref).cwiseAbs().maxCoeff() / p_ref.cwiseAbs().maxCoeff();
      const auto& t = first.timings;
      double first_total = t.assembly_ms + t.analysis_ms + t.factorization_ms + t.solve_ms;
      std::string cg = solver == LinearSolver::conjugate_gradient
                           ? fmt::format("{}/{:.0f}", t.cg_iterations, cg_next)
                           : (linear.factor_nonzeros > 0 ? fmt::format("{:.1f}M {:.1f}GF {}", linear.factor_nonzeros * 1e-6,
                                                                      gflops, linear.ordering)
                                                         : std::string("-"));
      fmt::print(
          "{:>7} {:>8} {:>7} {:>8.0f} {:>8.1f} {:>8.1f} | {:<19} {:>8.1f} {:>8.1f} {:>7.1f} {:>8.1f} {:>8.1f} | {:>8.1f} "
          "{:>8.1f} {:>8.1f} {:>9.1e} {:>9.1e}  {}\n",
          s.n_faces(), stats.tets, stats.vertices, tetgen_ms, t.setup_ms, t.assembly_ms, to_string(solver),
          t.analysis_ms, t.factorization_ms, t.solve_ms, first_total, first_cpu, refactor, iteration, iteration_cpu, du,
          dp, cg);
      std::fflush(stdout);
      csv << fmt::format("{},{:.5f},{},{},{:.2f},{:.1f},{:.2f},{:.2f},{},{:.2f},{:.2f},{:.2f},{:.2f},{:.2f},{:.2f},{:.2f},{},"
                         "{:.1f},{:.0f},{:.4g},{},{:.3e},{:.3e},{:.12g},{:.1f},{:.1f}\n",
                         s.n_faces(), h, stats.tets, stats.vertices, stats.min_dihedral_deg, tetgen_ms, t.setup_ms,
                         t.assembly_ms, to_string(solver), t.analysis_ms, t.factorization_ms, t.solve_ms, first_total,
                         refactor, resolve, iteration, t.cg_iterations, cg_next, linear.factor_nonzeros,
                         linear.factor_flops, linear.ordering, du, dp, first.mean_temperature, first_cpu, iteration_cpu);
    }
  }
  fmt::print("wrote {}\n", csv_path);
  return 0;
}
