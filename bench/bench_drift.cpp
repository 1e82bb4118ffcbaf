// Drift of an oscillating cap: a cap of polar angle a0 around +z on the unit
// sphere moves along its conormal with the normal speed s·cos(2πt/P), so its exact polar angle is
//     a(t) = a0 + s·P/(2π)·sin(2πt/P),
// periodic: after every period the cap is the initial one. Algorithm 1 is run stage by stage here
// (the same calls and options as evolve, one advection per step, the conormal model with the speed
// factor averaged over each step), and each stage's share of the drift is measured per step as
// the move it gives the front, in radians of polar angle:
//   distance  r_d − r_n       r_n the mean polar angle of the interface vertices of T^n, r_d the
//                             front position d^n implies: the mean of β − d over the vertices within
//                             1.5 h of the front (β the polar angle; d is β − a for a true cap)
//   advect    r_adv − r_d − (a(t^{n+1}) − a(t^n))   r_adv the same mean for φ^{n+1} on T^n
//   cut       r_cut − r_adv   r_cut the mean polar angle of the interface vertices after discretize
//   remesh    r_rem − r_cut   r_rem the same after remesh: that is r_{n+1}
// and |G| against the exact cap area 2π(1 − cos a(t)) at the end of every period.
//
//   bench_drift [--h 0.06,0.04,0.03] [--periods 10] [--period 6] [--speed 0.5] [--angle 45] [--c 0.5]
//               [-o drift.csv] [--p1] [--linear-cut] [--straight]
#include "bench_args.hpp"

#include <bodyfit/advection.hpp>
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/checkpoint.hpp>
#include <bodyfit/distance.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/levelset_mesher.hpp>
#include <bodyfit/remesh.hpp>
#include <bodyfit/velocity_model.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <array>
#include <fstream>
#include <set>
#include <numbers>
#include <string>
#include <vector>

using namespace bodyfit;

namespace {

constexpr double kPi = std::numbers::pi;

double polar(const Vec3& p) { return std::atan2(std::hypot(p[0], p[1]), p[2]); }

/// Mean polar angle of the interface vertices.
double interface_angle(const SurfaceMesh& mesh) {
  double sum = 0;
  std::size_t n = 0;
  for (auto v : mesh.vertices()) {
    bool on = false;
    for (auto e : mesh.ve_range(v)) on = on || mesh.interface(e);
    if (on) sum += polar(mesh.point(v)), ++n;
  }
  return n ? sum / double(n) : 0.0;
}

/// The front position a field implies: the mean of β − φ over the vertices with |φ| < width.
double implied_angle(const SurfaceMesh& mesh, const ScalarField& phi, double width) {
  double sum = 0;
  std::size_t n = 0;
  for (auto v : mesh.vertices())
    if (std::abs(phi[v.idx()]) < width) sum += polar(mesh.point(v)) - phi[v.idx()], ++n;
  return n ? sum / double(n) : 0.0;
}

/// The polar angle of the cap with the area of G, the polygon's chord deficit added back (each
/// interface edge of length L cuts a segment of area ≈ L³κ/12 off a circle of geodesic curvature
/// κ = cot r): a measure of the front that does not depend on how densely it is sampled.
double area_angle(const SurfaceMesh& mesh) {
  const double area = region_area(mesh, kInside);
  const double r = std::acos(1 - area / (2 * kPi));
  double deficit = 0;
  for (auto e : mesh.edges())
    if (mesh.interface(e)) deficit += std::pow(edge_length(mesh, e), 3) / (12 * std::tan(r));
  return std::acos(1 - (area + deficit) / (2 * kPi));
}

struct Options {
  double period = 6, speed = 0.5, angle = 45, c = 0.5;
  int periods = 10;
  double hausd = 0;  ///< 0: the remesher's default
  double noise = 0;  ///< --static: amplitude of a perturbation of φ
  double march = 0;  ///< --static: the circle moves by this many h per cut, one way (0: ±0.3 h)
  bool p1 = false, linear_cut = false, straight = false, verbose = false, static_cut = false, face_slopes = false;
};

struct StageDrift {
  double distance = 0, advect = 0, cut = 0, remesh = 0;
  double level_set = 0, cut_area = 0, remesh_area = 0;  ///< by area_angle: d + advect + cut, and remesh
};

void run(double h, const Options& o, std::ofstream& csv) {
  const std::string text = fmt::format(R"(
[surface]
generator = "sphere"
h = {h}
[region]
shape = "cap"
axis = [0, 0, 1]
angle = {angle}
[model]
name = "conormal"
[time]
cfl = {c}
final_time = 1
[remesh]
hmax = {h}
)",
                                       fmt::arg("h", h), fmt::arg("angle", o.angle), fmt::arg("c", o.c));
  CaseConfig config = parse_case(toml::parse(text));
  CaseSetup setup = setup_case(config);
  SurfaceMesh& mesh = setup.mesh;
  EvolutionOptions options = setup.options;
  if (o.p1) options.advection.gradient_correction = false;
  if (o.linear_cut) options.discretize.hermite_crossings = false;
  if (o.face_slopes) options.discretize.fitted_slopes = false;
  if (o.straight) options.distance.curved_interface = false;
  if (o.hausd > 0) options.remesh.hausd = o.hausd;
  const double a0 = o.angle * kPi / 180, omega = 2 * kPi / o.period, amplitude = o.speed / omega;
  auto exact = [&](double t) { return a0 + amplitude * std::sin(omega * t); };
  auto cap_area = [](double a) { return 2 * kPi * (1 - std::cos(a)); };
  if (o.static_cut) {
    // The remesher alone: cut the exact distance to a circle that moves by ±0.3 h, remesh, and see
    // where the interface vertices are.
    double sum = 0, sum_area = 0;
    for (int k = 1; k <= (o.march != 0 ? 30 : 100); ++k) {
      const double a = o.march != 0 ? a0 + k * o.march * h : a0 + (k % 2 ? 0.3 : -0.3) * h;
      ScalarField phi(mesh.n_vertices());
      for (auto v : mesh.vertices()) {
        // A deterministic pseudo-random perturbation of φ (--noise), as an interpolated φ has.
        const Vec3& p = mesh.point(v);
        const double hash = std::sin(12.9898 * p[0] + 78.233 * p[1] + 37.719 * p[2]) * 43758.5453;
        phi[v.idx()] = polar(p) - a + o.noise * 2 * (hash - std::floor(hash) - 0.5);
      }
      discretize(mesh, phi, options.discretize);
      const double cut = interface_angle(mesh) - a, cut_area = area_angle(mesh) - a;
      std::vector<Vec3> cut_points;
      for (auto v : mesh.vertices())
        for (auto e : mesh.ve_range(v))
          if (mesh.interface(e)) {
            cut_points.push_back(mesh.point(v).normalized());
            break;
          }
      remesh(mesh, options.remesh);
      canonicalize(mesh);
      const double rem = interface_angle(mesh) - a, rem_area = area_angle(mesh) - a;
      sum += rem - cut, sum_area += rem_area - cut_area;
      if (o.verbose) {
        double kept = 0, moved = 0, worst = 0;
        int n_kept = 0, n_moved = 0;
        for (auto v : mesh.vertices()) {
          bool on = false;
          for (auto e : mesh.ve_range(v)) on = on || mesh.interface(e);
          if (!on) continue;
          const Vec3 q = mesh.point(v).normalized();
          double nearest = 1e9;
          for (const Vec3& c : cut_points) nearest = std::min(nearest, (c - q).norm());
          const double dev = polar(q) - a;
          if (nearest < 1e-12) kept += dev, ++n_kept;
          else moved += dev, ++n_moved, worst = std::min(worst, dev);
        }
        fmt::print("  cut {}: {} kept at {:.2e}, {} moved at {:.2e} (lowest {:.2e})\n", k, n_kept,
                   n_kept ? kept / n_kept : 0.0, n_moved, n_moved ? moved / n_moved : 0.0, worst);
      }
      if (k <= 4 || k % 25 == 0)
        fmt::print("static cut {}: cut vertices {:.3e} area {:.3e}; remeshed vertices {:.3e} area {:.3e}\n", k, cut,
                   cut_area, rem, rem_area);
    }
    fmt::print("static: mean remesh move per cut {:.3e} rad (vertices), {:.3e} (area)\n", sum / (o.march != 0 ? 30 : 100), sum_area / (o.march != 0 ? 30 : 100));
    return;
  }
  const int steps = int(std::lround(o.period / options.dt));
  const double dt = o.period / steps;  // a whole number of steps per period
  mesh.garbage_collection();
  canonicalize(mesh);
  const double area0 = region_area(mesh, kInside);
  fmt::print("h = {}: {} faces, {} steps per period, dt = {:.5g}, a(t) = {:.4f} + {:.4f} sin(2πt/{}); "
             "|G(0)| = {:.6f} (exact cap {:.6f})\n",
             h, mesh.n_faces(), steps, dt, a0, amplitude, o.period, area0, cap_area(a0));
  fmt::print("{:>6} {:>10} {:>10} {:>10} | per step, mean 1e-6 rad: {:>8} {:>8} {:>8} {:>8} | {:>6} {:>6}\n", "period",
             "|G|", "|G|/|G0|-1", "r - a", "dist", "advect", "cut", "remesh", "qmin", "s");
  const auto start = std::chrono::steady_clock::now();
  double t = 0;
  for (int p = 1; p <= o.periods; ++p) {
    StageDrift drift;
    for (int k = 0; k < steps; ++k) {
      t = double((p - 1) * steps + k) * dt;
      DistanceSolver solver(mesh);
      const ScalarField d = solver.signed_distance_to_region(options.distance);
      const double r_n = interface_angle(mesh), r_n_area = area_angle(mesh);
      const double band = 1.5 * h;
      const double r_d = implied_angle(mesh, d, band);
      // The conormal model's V with the speed factor averaged over the step (exact in time).
      const double factor = amplitude * (std::sin(omega * (t + dt)) - std::sin(omega * t)) / dt;
      StandaloneStep where;
      where.time = t, where.dt = dt;
      const StepContext context = StepContext::standalone(mesh, d, where);
      VectorField velocity = context.conormal();
      for (auto& v : velocity) v *= factor;
      const ScalarField phi = advect(mesh, d, velocity, dt, options.advection);
      const double r_adv = implied_angle(mesh, phi, band);
      discretize(mesh, phi, options.discretize);
      const double r_cut = interface_angle(mesh), r_cut_area = area_angle(mesh);
      std::vector<Vec3> cut_points;  // directions of the interface vertices after the cut
      if (o.verbose)
        for (auto v : mesh.vertices()) {
          bool on = false;
          for (auto e : mesh.ve_range(v)) on = on || mesh.interface(e);
          if (on) cut_points.push_back(mesh.point(v).normalized());
        }
      const RemeshReport rr = remesh(mesh, options.remesh);
      canonicalize(mesh);
      const double r_rem = interface_angle(mesh), r_rem_area = area_angle(mesh);
      drift.level_set += r_cut_area - r_n_area - (exact(t + dt) - exact(t));
      drift.remesh_area += r_rem_area - r_cut_area;
      if (o.verbose) {
        // Interface vertices after the remesh: kept where the cut put them, or new/moved.
        double kept = 0, moved = 0;
        int n_kept = 0, n_moved = 0;
        for (auto v : mesh.vertices()) {
          bool on = false;
          for (auto e : mesh.ve_range(v)) on = on || mesh.interface(e);
          if (!on) continue;
          const Vec3 q = mesh.point(v).normalized();
          // Kept: still in the direction of a cut point; else moved along the curve or added.
          double nearest = 1e9, second = 1e9, beta_nearest = 0, beta_second = 0;
          for (const Vec3& c : cut_points) {
            const double dist = (c - q).norm();
            if (dist < nearest) second = nearest, beta_second = beta_nearest, nearest = dist, beta_nearest = polar(c);
            else if (dist < second) second = dist, beta_second = polar(c);
          }
          if (nearest < 1e-12) {
            kept += polar(q) - r_cut, ++n_kept;
          } else {  // against the cut points on either side, interpolated by distance
            const double local = (beta_nearest * second + beta_second * nearest) / (nearest + second);
            moved += polar(q) - local, ++n_moved;
          }
        }
        fmt::print("  step {}: cut {} interface vertices, after remesh {} kept (mean beta - r_cut {:.2e}), {} new or moved "
                   "(mean beta - the cut points around it {:.2e}); splits {} collapses {} relocations {}\n",
                   k, cut_points.size(), n_kept, n_kept ? kept / n_kept : 0.0, n_moved, n_moved ? moved / n_moved : 0.0,
                   rr.splits, rr.collapses, rr.relocations);
      }
      drift.distance += r_d - r_n;
      drift.advect += r_adv - r_d - (exact(t + dt) - exact(t));
      drift.cut += r_cut - r_adv;
      drift.remesh += r_rem - r_cut;
    }
    const double area = region_area(mesh, kInside);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double r = interface_angle(mesh);
    const double per = 1e6 / steps;
    fmt::print("{:>6} {:>10.6f} {:>10.3e} {:>10.3e} | {:>33} {:>8.3f} {:>8.3f} {:>8.3f} {:>8.3f} | {:>6.3f} {:>6.1f}"
               " | by area: d+advect+cut {:.3f} remesh {:.3f}\n",
               p, area, area / area0 - 1, r - a0, "", drift.distance * per, drift.advect * per, drift.cut * per,
               drift.remesh * per, quality_stats(mesh).min, seconds, drift.level_set * per, drift.remesh_area * per);
    csv << fmt::format("{},{},{},{:.8f},{:.8f},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.4f},{}\n", h,
                       steps, p, area, area0, area / area0 - 1, r - a0, drift.distance / steps, drift.advect / steps,
                       drift.cut / steps, drift.remesh / steps, drift.level_set / steps, drift.remesh_area / steps,
                       quality_stats(mesh).min, mesh.n_faces());
    csv.flush();
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<double> hs{0.06, 0.04, 0.03};
  Options o;
  std::string csv_path = "drift.csv";
  bench::Arguments args(
      "bench_drift",
      "usage: bench_drift [--h 0.06,0.04,0.03] [--periods N] [--period P] [--speed s] [--angle a0] [--c c]\n"
      "                   [-o drift.csv] [--p1] [--linear-cut] [--straight]\n"
      "  A cap of polar angle a0 (degrees, default 45) moves with the normal speed s cos(2 pi t / P)\n"
      "  (default s = 0.5, P = 6) for N periods (default 10) at each mesh size h (hmax = h, dt = c h,\n"
      "  default c = 0.5, rounded to a whole number of steps per period). Prints and writes per period:\n"
      "  |G| against |G(0)|, the interface's mean polar angle against a0, and each stage's mean drift\n"
      "  of the front per step (distance, advect, cut, remesh; radians).\n"
      "  --p1          plain P1 values at the feet of the characteristics (no gradient correction)\n"
      "  --linear-cut  cut at the linear zero of phi on each edge (no Hermite crossings)\n"
      "  --straight    distance to the polygon of interface edges (no curved interface)\n"
      "  --face-slopes Hermite slopes from the averaged face gradients (the cut's earlier slopes)\n"
      "  --hausd       the remesher's hausd (default: its own, diagonal / 1000)\n"
      "  --verbose     per step: the interface vertices the remesh keeps, moves or adds\n"
      "  --static      the remesher alone: 100 cuts of the exact distance to a circle moving by +-0.3 h\n"
      "  --noise       with --static: a uniform perturbation of phi of this amplitude at the vertices\n"
      "  --march       with --static: the circle moves one way by this many h per cut (default: +-0.3 h)\n");
  args.option("--h", hs);
  args.option("--periods", o.periods);
  args.option("--period", o.period);
  args.option("--speed", o.speed);
  args.option("--angle", o.angle);
  args.option("--c", o.c);
  args.option("-o", csv_path);
  args.option("--hausd", o.hausd);
  args.flag("--p1", o.p1);
  args.flag("--face-slopes", o.face_slopes);
  args.flag("--verbose", o.verbose);
  args.flag("--static", o.static_cut);
  args.option("--noise", o.noise);
  args.option("--march", o.march);
  args.flag("--linear-cut", o.linear_cut);
  args.flag("--straight", o.straight);
  args.parse(argc, argv);
  if (!(o.period > 0) || o.periods < 1 || !(o.c > 0)) args.fail("--period, --periods and --c must be positive");
  spdlog::set_level(spdlog::level::warn);
  std::ofstream csv(csv_path);
  csv << "h,steps_per_period,period,area,area0,area_change,angle_error,drift_distance,drift_advect,drift_cut,"
         "drift_remesh,drift_levelset_by_area,drift_remesh_by_area,min_quality,faces\n";
  for (double h : hs) run(h, o, csv);
  return 0;
}
