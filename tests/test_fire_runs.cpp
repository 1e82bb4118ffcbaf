// The fire plugin inside Algorithm 1, against exact front speeds (paper §4.3).
#include "balbi.hpp"
#include "fire_maps.hpp"

#include <bodyfit/app/model_files.hpp>
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/app/config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/app/plan_geometry.hpp>
#include <bodyfit/plugin_loader.hpp>
#include <bodyfit/projection.hpp>
#include <bodyfit/app/vector_io.hpp>
#include <bodyfit/app/render.hpp>

#include "gis_module.hpp"
#include "test_support.hpp"

#include <fmt/format.h>

#include <doctest/doctest.h>

#include <cmath>
#include <optional>
#include <fstream>
#include <sstream>

using namespace bodyfit;

namespace {

constexpr double kDeg = M_PI / 180;

// A planar terrain z = slope·x over [0, size]², meshed by the DEM path of the generators.
SurfaceMesh inclined_plane(double size, double h, double slope) {
  HeightGrid grid;
  grid.cell_size = h;
  grid.cols = grid.rows = std::size_t(size / h) + 1;
  grid.heights.resize(grid.cols * grid.rows);
  for (std::size_t r = 0; r < grid.rows; ++r)
    for (std::size_t c = 0; c < grid.cols; ++c) grid.heights[r * grid.cols + c] = slope * ((double(c) + 0.5) * h);
  return make_terrain_from_grid(grid, h);
}

struct FireRun {
  SurfaceMesh mesh;
  EvolutionResult result;
};

// Burn disks (x, y, r in plan view) for `steps` steps of `dt` with the fire model configured by `toml_text`.
FireRun burn(SurfaceMesh surface, const std::vector<std::array<double, 3>>& disks, const std::string& toml_text,
             double dt, int steps, const std::filesystem::path& output_dir = {}, double hausd = 0,
             double max_cfl = 0, bool narrow_band = true, bool keep_crossings = true,
             bool compose_substeps = false) {
  ScalarField phi(surface.n_vertices());
  for (auto v : surface.vertices()) {
    double best = std::numeric_limits<double>::infinity();
    for (auto& d : disks) best = std::min(best, std::hypot(surface.point(v)[0] - d[0], surface.point(v)[1] - d[1]) - d[2]);
    phi[v.idx()] = best;
  }
  RemeshOptions remesh;
  remesh.hmax = edge_length_stats(surface).mean;
  remesh.hausd = hausd;
  remesh.reference = std::make_shared<ReferenceSurface>(surface);
  remesh.check_distance_to_reference = false;  // as a case on a terrain (setup_case)
  mesh_initial_region(surface, phi, {}, remesh);

  LoadedModel model = load_plugin_file(std::filesystem::path(BODYFIT_PLUGIN_DIR) / "bodyfit_fire.so");
  configure_model(model, toml::parse(toml_text));
  EvolutionOptions options;
  options.dt = dt;
  options.max_iterations = steps;
  options.remesh = remesh;
  options.height_field = true;
  options.output_dir = output_dir;
  options.max_cfl = max_cfl;
  options.narrow_band = narrow_band;
  options.keep_crossings = keep_crossings;
  options.compose_substeps = compose_substeps;
  options.cfl_length = remesh.hmax;
  FireRun run;
  GridFiles grids(output_dir, "asc", model->outputs(), "fire");  // arrival_time.asc, rate_of_spread.asc
  EvolutionHooks hooks = EvolutionHooks::quiet();
  if (!output_dir.empty()) hooks.outputs = &grids;
  run.result = evolve(surface, model.model(), options, {}, hooks);
  run.mesh = std::move(surface);
  return run;
}

double distance_to_segments(const Vec3& p, const Segments& segments) {
  double nearest = std::numeric_limits<double>::infinity();
  for (const auto& [a, b] : segments) {
    const Vec3 e = b - a;
    const double t = e.sqrnorm() > 0 ? std::clamp(OpenMesh::dot(p - a, e) / e.sqrnorm(), 0.0, 1.0) : 0.0;
    nearest = std::min(nearest, (p - (a + t * e)).norm());
  }
  return nearest;
}

// 1.4 km square of hills and hollows (heights ±amplitude, wavelengths 1.1 and 1.4 km), cells of h.
HeightGrid bumpy_ground(double h, double amplitude) {
  HeightGrid grid;
  grid.cell_size = h;
  grid.cols = grid.rows = std::size_t(1400 / h) + 1;
  grid.heights.resize(grid.cols * grid.rows);
  for (std::size_t r = 0; r < grid.rows; ++r)
    for (std::size_t c = 0; c < grid.cols; ++c)
      grid.heights[r * grid.cols + c] = amplitude * std::sin(double(c) * h / 170) * std::cos(double(r) * h / 230);
  return grid;
}

// An ESRI ASCII grid read as written, NODATA values included.
HeightGrid read_raw_grid(const std::filesystem::path& file) {
  std::ifstream in(file);
  HeightGrid g;
  std::string key;
  double value;
  for (int i = 0; i < 6 && in >> key >> value; ++i) {
    if (key == "ncols") g.cols = std::size_t(value);
    if (key == "nrows") g.rows = std::size_t(value);
    if (key == "xllcorner") g.x_origin = value;
    if (key == "yllcorner") g.y_origin = value;
    if (key == "cellsize") g.cell_size = value;
    if (key == "NODATA_value") g.nodata = value;
  }
  g.heights.resize(g.cols * g.rows);
  for (double& h : g.heights) in >> h;
  return g;
}

// Extent of G along x: the interface vertices' min and max x.
std::pair<double, double> front_x_extent(const SurfaceMesh& mesh) {
  double lo = 1e300, hi = -1e300;
  for (auto e : mesh.edges())
    if (mesh.interface(e))
      for (int i = 0; i < 2; ++i) {
        double x = mesh.point(mesh.to_vertex_handle(mesh.halfedge_handle(e, i)))[0];
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
  return {lo, hi};
}

// The exact advance of the head of a plan-view disk of radius r0 on a plane of slope alpha, no
// wind, after a time t. Hopf's formula (a convex initial region, a normal speed R(n) that depends
// on n only) gives the burnt region in surface coordinates as the intersection of the half-planes
// u·n <= h0(n) + t R(n), h0 the support function of the initial ellipse (semi-axes r0/cos(alpha)
// uphill, r0 across). Symmetric about the uphill axis, its uphill extent is the least
// (h0 + t R)/cos(theta) over the normals at theta from uphill: R(alpha)·t only while
// h0 + t R stays a support function there (h0 + h0'' + t (R + R'') >= 0 at theta = 0).
double exact_head_advance(double alpha, double r0, double t, const fire::BalbiParameters& p) {
  const double a = r0 / std::cos(alpha), b = r0;
  double head = std::numeric_limits<double>::infinity();
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double theta = (double(i) / n - 0.5) * M_PI * 0.999;
    const double c = std::cos(theta), s = std::sin(theta);
    const double support = std::sqrt(a * a * c * c + b * b * s * s);
    const double rate = fire::rate_of_spread(std::atan(std::tan(alpha) * c), p);
    head = std::min(head, (support + t * rate) / c);
  }
  return head - a;
}

}  // namespace

TEST_CASE("flat ground, no wind: a disk grows at exactly R0") {
  const double R0 = fire::BalbiParameters{}.R0;
  const double r0 = 150, dt = 20;  // 8 m per step, edge 20 m
  FireRun run = burn(inclined_plane(1200, 20, 0), {{600, 600, r0}}, "preset = 'balbi2009'", dt, 50, {}, 0.05);
  double t = run.result.time;
  CHECK(t == doctest::Approx(50 * dt));
  double radius = std::sqrt(region_area(run.mesh, kInside) / M_PI);
  double exact = r0 + R0 * t;
  INFO("radius " << radius << " exact " << exact);
  CHECK(std::abs(radius - exact) / exact < 0.01);
}

TEST_CASE("inclined plane, no wind: the head runs uphill at R(alpha), the back at R0") {
  fire::BalbiParameters p;
  const double alpha = 20 * kDeg, slope = std::tan(alpha);
  const double r0 = 150, dt = 10, steps = 40;
  FireRun run = burn(inclined_plane(1600, 20, slope), {{700, 800, r0}}, "", dt, int(steps), {}, 0.05);
  double t = run.result.time;
  auto [x_back, x_head] = front_x_extent(run.mesh);
  // Distances along the surface: horizontal / cos α.
  double head = (x_head - 700) / std::cos(alpha) - r0 / std::cos(alpha);
  double back = (700 - x_back) / std::cos(alpha) - r0 / std::cos(alpha);
  double head_exact = fire::rate_of_spread(alpha, p) * t, back_exact = p.R0 * t;
  INFO("head " << head << " exact " << head_exact << "; back " << back << " exact " << back_exact);
  CHECK(head == doctest::Approx(head_exact).epsilon(0.02));
  CHECK(back == doctest::Approx(back_exact).epsilon(0.03));
}

TEST_CASE("CFL-capped sub-steps (max_cfl): the head still runs uphill at R(alpha), the back at R0") {
  fire::BalbiParameters p;
  const double alpha = 20 * kDeg, slope = std::tan(alpha);
  const double r0 = 150, dt = 100, steps = 4;  // R(α)·Δt ≈ 6 edges per step: sub-steps of ≤ 1 edge
  FireRun run = burn(inclined_plane(1600, 20, slope), {{700, 800, r0}}, "", dt, int(steps), {}, 0.05, 1.0);
  REQUIRE(run.result.records.size() == std::size_t(steps));
  for (const auto& record : run.result.records) CHECK(record.substeps >= 5);
  double t = run.result.time;
  auto [x_back, x_head] = front_x_extent(run.mesh);
  double head = (x_head - 700) / std::cos(alpha) - r0 / std::cos(alpha);
  double back = (700 - x_back) / std::cos(alpha) - r0 / std::cos(alpha);
  double head_exact = fire::rate_of_spread(alpha, p) * t, back_exact = p.R0 * t;
  MESSAGE("sub-steps " << run.result.records.front().substeps << ": head " << head << " exact " << head_exact
                       << "; back " << back << " exact " << back_exact);
  INFO("head " << head << " exact " << head_exact << "; back " << back << " exact " << back_exact);
  CHECK(head == doctest::Approx(head_exact).epsilon(0.02));
  CHECK(back == doctest::Approx(back_exact).epsilon(0.03));
}

TEST_CASE("many sub-steps: the head runs as the exact solution, the back at R0 (Huygens' velocity)") {
  // A steep plane: the head runs at 6 times R0, so max_cfl = 0.25 takes about 45 sub-steps per step.
  // Where R + R'' < 0 at the head, the exact head is a corner of the Wulff shape and runs well short
  // of R(alpha). V = R n_Σ (front_velocity = "normal") turns with n_Σ over a sub-step and put the
  // head 16 % ahead of the exact front here (5 % with composed sub-steps); V = R n_Σ + (dR/dθ) t, the
  // front's characteristic velocity, puts it within 0.2 % (docs/reference/fire_model.md, "Huygens' velocity"). The
  // back runs at R0 and moves 1/25 of an edge per sub-step: redistancing that re-placed the zero
  // set every sub-step (keep_crossings = false) moved that slow front by O(h^2 kappa) each time,
  // 2 % of its motion, against 0.03 % with the crossings kept.
  fire::BalbiParameters p;
  const double alpha = 30 * kDeg, slope = std::tan(alpha);
  const double r0 = 150, dt = 100, steps = 4;
  // Relative errors of the head's advance (against the exact front) and of the back's (against R0·t).
  auto errors = [&](const std::string& model, bool compose, bool keep) {
    FireRun run = burn(inclined_plane(1600, 20, slope), {{400, 800, r0}}, model, dt, int(steps), {}, 0.05, 0.25, true,
                       keep, compose);
    CHECK(run.result.records.front().substeps >= 40);
    const auto extent = front_x_extent(run.mesh);
    const double t = run.result.time;
    const double head = (extent.second - 400) / std::cos(alpha) - r0 / std::cos(alpha);
    const double back = (400 - extent.first) / std::cos(alpha) - r0 / std::cos(alpha);
    return std::array<double, 2>{head / exact_head_advance(alpha, r0, t, p) - 1, back / (p.R0 * t) - 1};
  };
  CHECK(exact_head_advance(alpha, r0, dt * steps, p) < 0.85 * fire::rate_of_spread(alpha, p) * dt * steps);
  const std::array<double, 2> huygens = errors("", false, true), composed = errors("", true, true),
                              replaced = errors("", false, false),
                              normal = errors("front_velocity = 'normal'", false, true);
  MESSAGE("head, back: relative errors " << huygens[0] << ", " << huygens[1] << " Huygens; " << composed[0] << ", "
                                      << composed[1] << " composed; " << replaced[0] << ", " << replaced[1]
                                      << " crossings re-placed; " << normal[0] << ", " << normal[1] << " V = R n");
  CHECK(std::abs(huygens[0]) <= 0.01);
  CHECK(std::abs(huygens[1]) <= 0.005);
  CHECK(std::abs(composed[0]) <= 0.03);
  CHECK(std::abs(composed[1]) <= 0.005);
  CHECK(std::abs(huygens[0]) < 0.1 * std::abs(normal[0]));  // what the characteristic velocity removes
  CHECK(std::abs(replaced[1]) > 2 * std::abs(huygens[1]));
}

TEST_CASE("narrow-band sub-steps: the whole-surface computation's front and arrival times") {
  // Bumpy ground and a wind: R varies along the front and the sub-steps recompute it near the front.
  const double h = 20;
  const HeightGrid grid = bumpy_ground(h, 60);
  const std::string model = "[wind]\ntype = 'uniform'\nvelocity = [4.0, 2.0]\n";
  test::TempDir dir_band("fire_band"), dir_whole("fire_whole");
  FireRun band = burn(make_terrain_from_grid(grid, h), {{600, 650, 120}}, model, 120, 3, dir_band.path(), 0.05, 1.0);
  FireRun whole =
      burn(make_terrain_from_grid(grid, h), {{600, 650, 120}}, model, 120, 3, dir_whole.path(), 0.05, 1.0, false);
  REQUIRE(band.result.records.size() == 3);
  REQUIRE(whole.result.records.size() == 3);
  for (std::size_t k = 0; k < 3; ++k) {
    CHECK(band.result.records[k].substeps == whole.result.records[k].substeps);
    CHECK(band.result.records[k].substeps >= 3);
  }
  const double area = region_area(whole.mesh, kInside);
  CHECK(std::abs(region_area(band.mesh, kInside) - area) <= 1e-9 * area);
  CHECK(interface_hausdorff(band.mesh, whole.mesh) <= 1e-6 * h);
  // The arrival raster: the band visits only the cells near the front, with the same result.
  const HeightGrid a = read_raw_grid(dir_band.path() / "arrival_time.asc");
  const HeightGrid b = read_raw_grid(dir_whole.path() / "arrival_time.asc");
  REQUIRE(a.heights.size() == b.heights.size());
  std::size_t reached = 0, differ = 0;
  for (std::size_t i = 0; i < a.heights.size(); ++i) {
    reached += a.heights[i] != a.nodata;
    differ += std::abs(a.heights[i] - b.heights[i]) > 1e-6;
  }
  CHECK(reached > 100);
  CHECK(differ == 0);
}

TEST_CASE("the fire near its front (the default) gives the front of landscape_statistics, without its landscape metrics") {
  // d in a band of the front against d on the whole surface: the same rates where the front goes.
  const double h = 20;
  const HeightGrid grid = bumpy_ground(h, 60);
  const std::string wind = "[wind]\ntype = 'uniform'\nvelocity = [4.0, 2.0]\n";
  test::TempDir dir_band("fire_near"), dir_whole("fire_landscape");
  FireRun near = burn(make_terrain_from_grid(grid, h), {{600, 650, 120}}, wind, 120, 3, dir_band.path(), 0.05, 1.0);
  FireRun landscape = burn(make_terrain_from_grid(grid, h), {{600, 650, 120}}, "landscape_statistics = true\n" + wind, 120,
                           3, dir_whole.path(), 0.05, 1.0);
  REQUIRE(near.result.records.size() == 3);
  REQUIRE(landscape.result.records.size() == 3);
  auto metric = [](const IterationRecord& r, const std::string& name) -> std::optional<double> {
    for (const auto& [key, value] : r.metrics)
      if (key == name) return value;
    return std::nullopt;
  };
  for (std::size_t k = 0; k < 3; ++k) {
    CAPTURE(k);
    const IterationRecord &a = near.result.records[k], &b = landscape.result.records[k];
    CHECK(a.substeps == b.substeps);
    CHECK(a.area == doctest::Approx(b.area).epsilon(1e-9));
    for (const char* name : {"ros_min", "ros_mean", "ros_max"}) {
      REQUIRE(metric(a, name));
      CHECK(*metric(a, name) == doctest::Approx(*metric(b, name)).epsilon(1e-9));
    }
    CHECK(!metric(a, "ros_all_mean"));
    CHECK(!metric(a, "ros_all_max"));
    REQUIRE(metric(b, "ros_all_max"));
    CHECK(*metric(b, "ros_all_max") >= *metric(b, "ros_max"));
  }
  CHECK(interface_hausdorff(near.mesh, landscape.mesh) <= 1e-6 * h);
  const HeightGrid a = read_raw_grid(dir_band.path() / "arrival_time.asc");
  const HeightGrid b = read_raw_grid(dir_whole.path() / "arrival_time.asc");
  REQUIRE(a.heights.size() == b.heights.size());
  std::size_t reached = 0, differ = 0;
  for (std::size_t i = 0; i < a.heights.size(); ++i) {
    reached += a.heights[i] != a.nodata;
    differ += std::abs(a.heights[i] - b.heights[i]) > 1e-6;
  }
  CHECK(reached > 100);
  CHECK(differ == 0);
}

TEST_CASE("CFL sub-steps converge: max_cfl 4 and max_cfl 1 give the same front") {
  // Steep bumpy ground and a cross wind: R changes along the front and with its direction, from
  // R0 on the flanks to many times it uphill. Redistancing re-placed the zero set by O(h^2 kappa)
  // every sub-step, which added up with their number (EvolutionOptions::keep_crossings): max_cfl 4
  // and 1 then burnt areas 13 % apart on the four-fire case (docs/validation/advection.md, "Sub-steps that converge").
  const double h = 20;
  const HeightGrid grid = bumpy_ground(h, 200);
  const std::string model = "[wind]\ntype = 'uniform'\nvelocity = [4.0, 2.0]\n";
  auto run = [&](double max_cfl) {
    return burn(make_terrain_from_grid(grid, h), {{600, 650, 120}}, model, 200, 2, {}, 0.05, max_cfl);
  };
  const FireRun coarse = run(4), fine = run(1);
  REQUIRE(fine.result.records.size() == 2);
  int substeps_coarse = 0, substeps_fine = 0;
  for (const auto& record : coarse.result.records) substeps_coarse += record.substeps;
  for (const auto& record : fine.result.records) substeps_fine += record.substeps;
  CHECK(substeps_fine >= 1.4 * substeps_coarse);
  // The gap between the fronts: from every end and midpoint of either's edges to the other.
  const Segments a = interface_segments(coarse.mesh), b = interface_segments(fine.mesh);
  std::vector<double> gaps;
  for (const Segments* from : {&a, &b})
    for (const Segment& s : *from)
      for (const Vec3& p : {s.first, s.second, 0.5 * (s.first + s.second)})
        gaps.push_back(distance_to_segments(p, from == &a ? b : a));
  std::sort(gaps.begin(), gaps.end());
  double mean = 0;
  for (double g : gaps) mean += g / double(gaps.size());
  const double p95 = gaps[gaps.size() * 95 / 100];
  const double area = region_area(fine.mesh, kInside), area_coarse = region_area(coarse.mesh, kInside);
  INFO("gap mean " << mean / h << " h, p95 " << p95 / h << " h, max " << gaps.back() / h << " h; areas "
                   << area_coarse << " / " << area);
  CHECK(mean <= 0.25 * h);
  CHECK(p95 <= 0.5 * h);
  CHECK(std::abs(area_coarse / area - 1) <= 0.01);
}

TEST_CASE("uniform wind on flat ground: the head moves at R(atan(|U|/u0))") {
  fire::BalbiParameters p;
  const double wind = 15;  // m/s along +x
  const double r0 = 150, dt = 10;
  FireRun run = burn(inclined_plane(1600, 20, 0), {{500, 800, r0}},
                     "[wind]\ntype = 'uniform'\nvelocity = [15.0, 0.0]\n", dt, 40, {}, 0.05);
  double t = run.result.time;
  // Not a structured binding: INFO captures it in a lambda, which clang 14 refuses.
  const auto extent = front_x_extent(run.mesh);
  const double x_back = extent.first, x_head = extent.second;
  double head_exact = fire::rate_of_spread(std::atan(wind / p.u0), p) * t;
  INFO("head advance " << x_head - 500 - r0 << " exact " << head_exact);
  CHECK(x_head - 500 - r0 == doctest::Approx(head_exact).epsilon(0.02));
  CHECK(500 - r0 - x_back == doctest::Approx(p.R0 * t).epsilon(0.03));
}

TEST_CASE("uniform wind as speed and direction: a wind from 270 degrees is velocity [U, 0], from 90 its mirror") {
  auto extent_with = [](const std::string& wind) {
    FireRun run = burn(inclined_plane(1600, 20, 0), {{800, 800, 150}}, "[wind]\ntype = 'uniform'\n" + wind, 10, 8, {}, 0.05);
    return front_x_extent(run.mesh);
  };
  const auto velocity = extent_with("velocity = [15.0, 0.0]\n");
  const auto from_west = extent_with("speed = 15.0\ndirection_deg = 270.0\n");
  const auto from_east = extent_with("speed = 15.0\ndirection_deg = 90.0\n");
  CHECK(from_west.first == doctest::Approx(velocity.first).epsilon(1e-9));
  CHECK(from_west.second == doctest::Approx(velocity.second).epsilon(1e-9));
  // From the east the head runs towards −x as far as it ran towards +x (up to the mesh's asymmetry).
  CHECK(800 - from_east.first == doctest::Approx(velocity.second - 800).epsilon(0.02));
  CHECK(from_east.second - 800 == doctest::Approx(800 - velocity.first).epsilon(0.02));
  // speed and direction_deg are a uniform wind's, and not beside velocity.
  LoadedModel model = load_plugin_file(std::filesystem::path(BODYFIT_PLUGIN_DIR) / "bodyfit_fire.so");
  CHECK_THROWS_WITH_AS(configure_model(model, toml::parse("[wind]\nspeed = 3.0\ndirection_deg = 10.0\n")),
                       doctest::Contains("applies to type = \"uniform\""), InputError);
  CHECK_THROWS_WITH_AS(configure_model(model, toml::parse("[wind]\ntype = 'uniform'\nvelocity = [1.0, 0.0]\nspeed = 3.0\n"
                                                          "direction_deg = 10.0\n")),
                       doctest::Contains("either velocity or speed"), InputError);
}

TEST_CASE("four fires merge into one burnt region") {
  const double R0 = fire::BalbiParameters{}.R0;
  // Disks of 80 m, centres 300 m apart: they touch after (150 − 80)/R0 ≈ 176 s.
  FireRun run = burn(inclined_plane(1000, 20, 0), {{350, 350, 80}, {650, 350, 80}, {350, 650, 80}, {650, 650, 80}},
                     "", 20, 15);
  REQUIRE(run.result.records.size() == 15);
  CHECK(run.result.records.front().components == 4);
  CHECK(run.result.records.back().components == 1);
  CHECK(run.result.time * R0 > 150 - 80);
}

TEST_CASE("a run on a DEM read from an ESRI ASCII grid writes arrival times") {
  test::TempDir dir("fire_dem");
  // A small hill: z = 100·exp(−r²/300²) on a 41×41 raster of 25 m.
  {
    std::ofstream out(dir / "hill.asc");
    out << "ncols 41\nnrows 41\nxllcorner 0\nyllcorner 0\ncellsize 25\nNODATA_value -9999\n";
    for (int r = 0; r < 41; ++r) {
      for (int c = 0; c < 41; ++c) {
        double x = (c + 0.5) * 25 - 512.5, y = (40 - r + 0.5) * 25 - 512.5;
        out << 100 * std::exp(-(x * x + y * y) / (300.0 * 300.0)) << (c < 40 ? " " : "\n");
      }
    }
  }
  SurfaceMesh terrain = make_terrain_from_grid(read_esri_ascii(dir / "hill.asc"), 25);
  FireRun run = burn(std::move(terrain), {{300, 300, 100}}, "[arrival]\ncell_size = 25.0\n", 30, 10, dir.path());
  REQUIRE(run.result.records.size() == 10);
  CHECK(run.result.records.back().area > run.result.records.front().area);
  HeightGrid arrival = read_raw_grid(dir / "arrival_time.asc");
  // Cells inside the initial disk arrive at 0, cells far away are never reached, and arrival
  // times grow away from the ignition point.
  CHECK(fire::raster_nearest(arrival, 300, 300) == doctest::Approx(0.0));
  double near = fire::raster_nearest(arrival, 300, 420);  // 20 m beyond the initial front
  CHECK(near > 0);
  CHECK(near < run.result.time);
  CHECK(fire::raster_nearest(arrival, 1000, 1000) == arrival.nodata);
}

TEST_CASE("a fuel map's non-burnable cells stop the front") {
  test::TempDir dir("fire_fuel");
  // Fuel codes on 100 m cells over [0, 1200]²: 1 (burnable) for x < 700, 0 (not burnable) beyond.
  {
    std::ofstream out(dir / "fuel.asc");
    out << "ncols 12\nnrows 12\nxllcorner 0\nyllcorner 0\ncellsize 100\nNODATA_value -9999\n";
    for (int r = 0; r < 12; ++r)
      for (int c = 0; c < 12; ++c) out << (c < 7 ? 1 : 0) << (c < 11 ? " " : "\n");
  }
  const double R0 = fire::BalbiParameters{}.R0, h = 20, dt = 20, r0 = 150;
  const int steps = 30;  // 600 s: unobstructed, the front would reach x = 650 + 600·R0 ≈ 889 m
  FireRun run = burn(inclined_plane(1200, h, 0), {{500, 600, r0}},
                     fmt::format("[fuel]\nmap = \"{}\"\npresets = [\"balbi2009\"]\n", (dir / "fuel.asc").string()), dt,
                     steps, {}, 0.05);
  REQUIRE(run.result.records.size() == std::size_t(steps));
  double x_min = 1e30, x_max = -1e30;
  for (auto f : run.mesh.faces())
    if (run.mesh.region(f) == kInside)
      for (auto v : run.mesh.fv_range(f)) x_min = std::min(x_min, run.mesh.point(v)[0]), x_max = std::max(x_max, run.mesh.point(v)[0]);
  const double free_run = R0 * run.result.time;  // distance a front travels on open ground
  INFO("x_min " << x_min << " x_max " << x_max << " free run " << free_run);
  CHECK(650 + free_run > 800);                     // the barrier is really in the way
  CHECK(x_max <= 700 + 2 * h);                     // stopped within one cell of P1 interpolation of the speed
  CHECK(std::abs((500 - r0 - x_min) - free_run) / free_run < 0.02);  // the other side burns at R0
}

TEST_CASE("fuel NODATA and the codes of fuel.non_burnable stop the front, an unknown code is an error") {
  test::TempDir dir("fire_fuel_nodata");
  // 100 m cells over [0, 1200]²: NODATA (255, a byte raster's usual marker) for x ≥ 800, code 9
  // (water, listed in non_burnable) for x < 400, fuel 1 between.
  auto write_map = [&](const std::string& name, int unknown_code) {
    std::ofstream out(dir / name);
    out << "ncols 12\nnrows 12\nxllcorner 0\nyllcorner 0\ncellsize 100\nNODATA_value 255\n";
    for (int r = 0; r < 12; ++r)
      for (int c = 0; c < 12; ++c) out << (r == 5 && c == 6 ? unknown_code : c >= 8 ? 255 : c < 4 ? 9 : 1) << (c < 11 ? " " : "\n");
  };
  write_map("fuel.asc", 1);
  const double R0 = fire::BalbiParameters{}.R0, h = 20, dt = 20, r0 = 150;
  const int steps = 30;  // 600 s: unobstructed, the front would reach x = 750 + 600·R0 ≈ 989 m and 450 − 239 ≈ 211 m
  const std::string model = fmt::format("[fuel]\nmap = \"{}\"\npresets = [\"balbi2009\"]\nnon_burnable = [9]\n",
                                        (dir / "fuel.asc").string());
  FireRun run = burn(inclined_plane(1200, h, 0), {{600, 600, r0}}, model, dt, steps, {}, 0.05);
  REQUIRE(run.result.records.size() == std::size_t(steps));
  const double free_run = R0 * run.result.time;
  CHECK(750 + free_run > 800 + 2 * h);  // both blocks are really in the way
  CHECK(450 - free_run < 400 - 2 * h);
  // Burnt area in each block beyond the reach of the P1 interpolation of the speed (two edges).
  double in_nodata = 0, in_water = 0, y_max = -1e30;
  for (auto f : run.mesh.faces()) {
    if (run.mesh.region(f) != kInside) continue;
    const auto p = face_points(run.mesh, f);
    const double x = (p[0][0] + p[1][0] + p[2][0]) / 3;
    if (x > 800 + 2 * h) in_nodata += face_area(run.mesh, f);
    if (x < 400 - 2 * h) in_water += face_area(run.mesh, f);
    for (const auto& q : p) y_max = std::max(y_max, q[1]);
  }
  CHECK(in_nodata == 0);
  CHECK(in_water == 0);
  // Along the burnable strip the front runs at R0.
  CHECK(std::abs((y_max - 750) - free_run) / free_run < 0.02);

  // A code that is neither a preset's number, 0, NODATA nor listed: an error naming its cell.
  write_map("unknown.asc", 7);
  LoadedModel plugin = load_plugin_file(std::filesystem::path(BODYFIT_PLUGIN_DIR) / "bodyfit_fire.so");
  const std::string unknown = fmt::format("[fuel]\nmap = \"{}\"\npresets = [\"balbi2009\"]\nnon_burnable = [9]\n",
                                          (dir / "unknown.asc").string());
  CHECK_THROWS_WITH_AS(configure_model(plugin, toml::parse(unknown)), doctest::Contains("row 6, column 7"), InputError);
  CHECK_THROWS_AS(configure_model(plugin, toml::parse("[fuel]\nnon_burnable = [1.5]\n")), InputError);
}

TEST_CASE("the fire cases of meshes/cases are valid and configure the plugin") {
  // The [model] paths (fuel map, arrival raster) are relative to the case file: read from an
  // unrelated working directory.
  test::TempDir elsewhere("fire_cases_cwd");
  const auto previous = std::filesystem::current_path();
  std::filesystem::current_path(elsewhere.path());
  for (const char* name : {"fire_one_disk", "fire_four_disks", "fire_rotating_wind", "fire_luxembourg"}) {
    CAPTURE(name);
    CaseConfig c = read_case(test::source_path(std::string("meshes/cases/") + name + ".toml"));
    CHECK(c.model == "fire");
    LoadedModel model = load_plugin_file(std::filesystem::path(BODYFIT_PLUGIN_DIR) / "bodyfit_fire.so");
    CHECK_NOTHROW(configure_model(model, c.model_parameters));
  }
  std::filesystem::current_path(previous);
}

TEST_CASE("[model] file names are relative to the case file: a run from another directory, its --resume, a missing file") {
  namespace fs = std::filesystem;
  test::TempDir dir("fire_paths");
  fs::create_directories(dir / "case" / "maps");
  fs::create_directories(dir / "elsewhere");
  auto grid = [&](const std::string& name, double value) {
    std::ofstream out(dir / "case" / "maps" / name);
    out << "ncols 25\nnrows 25\nxllcorner 0\nyllcorner 0\ncellsize 40\nNODATA_value -9999\n";
    for (int i = 0; i < 25 * 25; ++i) out << value << (i % 25 == 24 ? "\n" : " ");
  };
  grid("flat.asc", 0), grid("fuel.asc", 1), grid("u.asc", 2), grid("v.asc", 0);
  auto write_case = [&](const std::string& file, const std::string& fuel_map) {
    std::ofstream out(dir / "case" / file);
    out << "[surface]\ngenerator = \"terrain\"\ndem = \"maps/flat.asc\"\nh = 40.0\n"
        << "[region]\nshape = \"disks\"\ncenters = [[500.0, 500.0]]\nradii = [150.0]\n"
        << "[model]\nname = \"fire\"\n"
        << "wind = { type = \"grid\", u_file = \"maps/u.asc\", v_file = \"./maps/v.asc\" }\n"
        << "fuel = { map = \"" << fuel_map << "\", presets = [\"balbi2009\"] }\n"
        << "arrival = { like = \"maps/flat.asc\" }\n"
        << "[time]\ndt = 30.0\niterations = 3\n[output]\nvtu_every = 0\n";
  };
  write_case("case.toml", "maps/fuel.asc");
  write_case("missing.toml", "maps/nope.asc");
  const auto previous = fs::current_path();
  auto history_rows = [&] {
    std::ifstream in(dir / "elsewhere" / "out" / "history.csv");
    std::vector<std::string> rows;
    for (std::string line; std::getline(in, line);) rows.push_back(line);
    return rows;
  };

  fs::current_path(dir / "elsewhere");
  auto first = test::run_bodyfit("run ../case/case.toml -o out --set time.iterations=2");
  INFO(first.output);
  CHECK(first.exit_code == 0);
  CHECK(fs::exists(dir / "elsewhere" / "out" / (config::have_gdal ? "arrival_time.tif" : "arrival_time.asc")));
  if constexpr (config::have_cairo) {  // the model's map of the run, drawn at its end (docs/reference/fire_model.md, "Maps")
    const Image map = read_png(dir / "elsewhere" / "out" / "fire_map.png");
    CHECK(map.width == 1200);
    CHECK(map.height == 900);
  }
  CHECK(history_rows().size() == 4);  // header, states 0..2

  // --resume reads the case given on its command line again: from a third directory, same files.
  fs::current_path(dir.path());
  auto resumed = test::run_bodyfit("run case/case.toml -o elsewhere/out --resume");
  INFO(resumed.output);
  CHECK(resumed.exit_code == 0);
  auto rows = history_rows();
  REQUIRE(rows.size() == 5);
  CHECK(rows.back().rfind("3,", 0) == 0);

  // A missing file is named by its resolved path (next to the case file, not in the working directory).
  auto missing = test::run_bodyfit("run case/missing.toml -o elsewhere/missing");
  fs::current_path(previous);
  INFO(missing.output);
  CHECK(missing.exit_code == 1);
  CHECK(missing.output.find((fs::absolute(dir / "case") / "maps" / "nope.asc").string()) != std::string::npos);
}

TEST_CASE("GIS outputs of a run: arrival time and rate of spread as GeoTIFF, perimeters as a GeoPackage") {
  if constexpr (!config::have_gdal) return;
  namespace fs = std::filesystem;
  test::TempDir dir("fire_gis_outputs");
  // A tilted plane on a DEM in UTM zone 32N (the .prj of the Luxembourg DEM), 20 m cells.
  {
    std::ofstream out(dir / "slope.asc");
    out << "ncols 41\nnrows 41\nxllcorner 300000\nyllcorner 5500000\ncellsize 20\nNODATA_value -9999\n";
    for (int r = 0; r < 41; ++r)
      for (int c = 0; c < 41; ++c) out << 0.2 * (c + 0.5) * 20 << (c < 40 ? " " : "\n");
  }
  fs::copy_file(test::source_path("meshes/dem/luxembourg_elev_200m.prj"), dir / "slope.prj");
  std::ofstream(dir / "case.toml")
      << "[surface]\ngenerator = \"terrain\"\ndem = \"slope.asc\"\nh = 20.0\n"
      << "[region]\nshape = \"disks\"\ncenters = [[300300.0, 5500400.0]]\nradii = [100.0]\n"
      << "[model]\nname = \"fire\"\narrival = { like = \"slope.asc\" }\n"
      << "[time]\ndt = 30.0\niterations = 4\nstart = \"2026-07-14T15:00:00+02:00\"\n[output]\nvtu_every = 0\n";
  const auto result = test::run_bodyfit("run '" + (dir / "case.toml").string() + "' -o '" + (dir / "out").string() + "'");
  INFO(result.output);
  REQUIRE(result.exit_code == 0);
  const fs::path out = dir / "out";
  const HeightGrid dem = read_esri_ascii(dir / "slope.asc");
  const gis::Api& gis = gis::module_for(out);

  // The rasters: the DEM's frame and CRS, NODATA where nothing burnt, times and rates in range.
  HeightGrid arrival, rate;
  std::string error;
  REQUIRE(gis.read_raster(out / "arrival_time.tif", arrival, error));
  REQUIRE(gis.read_raster(out / "rate_of_spread.tif", rate, error));
  for (const HeightGrid* g : {&arrival, &rate}) {
    CHECK(g->cols == dem.cols);
    CHECK(g->rows == dem.rows);
    CHECK(g->x_origin == dem.x_origin);
    CHECK(g->y_origin == dem.y_origin);
    CHECK(g->nodata == -9999);
    CHECK(gis.same_crs(g->crs, dem.crs));
  }
  CHECK(fire::raster_nearest(arrival, 300300, 5500400) == 0);
  CHECK(fire::raster_nearest(rate, 300300, 5500400) == -9999);  // burning at the start: no spread
  CHECK(fire::raster_nearest(arrival, 300790, 5500010) == -9999);  // never reached
  const fire::BalbiParameters p;
  std::size_t spread = 0;
  for (std::size_t i = 0; i < arrival.heights.size(); ++i) {
    const double t = arrival.heights[i], r = rate.heights[i];
    if (t == -9999) CHECK(r == -9999);
    if (t > 0) {
      ++spread;
      CHECK(t <= 120);
      CHECK(r >= p.R0 * 0.999);  // flat across the slope, faster uphill
      CHECK(r <= fire::rate_of_spread(std::atan(0.2), p) * 1.001);
    }
  }
  CHECK(spread > 20);

  // The perimeters: one feature per state (0 to 4), valid, their planar areas the mesh's.
  const VectorLayer layer = read_vector_layer(out / "perimeters.gpkg");
  REQUIRE(layer.features.size() == 5);
  CHECK(gis.same_crs(layer.crs, dem.crs));
  double previous = 0;
  for (std::size_t k = 0; k < layer.features.size(); ++k) {
    const VectorFeature& f = layer.features[k];
    CHECK(f.valid);
    CHECK(std::get<std::int64_t>(f.attribute("iteration")) == std::int64_t(k));
    CHECK(std::get<double>(f.attribute("time")) == doctest::Approx(30.0 * double(k)));
    CHECK(std::get<std::string>(f.attribute("datetime")) == fmt::format("2026-07-14T13:0{}:{:02}Z", k / 2, 30 * (k % 2)));
    double area = 0;
    for (const auto& polygon : f.geometry.polygons) area += polygon_area(polygon);
    CHECK(std::get<double>(f.attribute("area")) == doctest::Approx(area).epsilon(1e-12));
    CHECK(area > previous);
    previous = area;
  }
  const SurfaceMesh final_mesh = read_mesh(out / "final.mesh");
  const double final_area = region_plan_area(final_mesh);
  CHECK(std::abs(previous - final_area) <= 1e-9 * final_area);
}

TEST_CASE("a raster of another place (a fuel map 200 km off the DEM) is refused, one covering part of it is said") {
  test::TempDir dir("fire_far_map");
  const std::filesystem::path dem = test::source_path("meshes/dem/luxembourg_elev_200m.asc");
  const std::string fuel = test::read_file(test::source_path("meshes/dem/luxembourg_fuel_200m.asc"));
  const std::string prj = test::read_file(test::source_path("meshes/dem/luxembourg_fuel_200m.prj"));
  auto shifted = [&](const std::string& name, double dx) {
    std::string text = fuel;
    const std::string key = "xllcorner    263811.219768329640";
    REQUIRE(text.find(key) != std::string::npos);
    text.replace(text.find(key), key.size(), fmt::format("xllcorner    {:.6f}", 263811.219768329640 + dx));
    std::ofstream(dir / (name + ".asc")) << text;
    std::ofstream(dir / (name + ".prj")) << prj;
  };
  shifted("far", 200000);
  shifted("half", 30000);
  const std::string case_text = fmt::format(R"([surface]
generator = "terrain"
dem = "{}"
h = 800.0
[region]
shape = "disks"
centers = [[288818.0, 5548359.0]]
radii = [2000.0]
[model]
name = "fire"
preset = "balbi2009"
[model.fuel]
map = "MAP"
presets = ["balbi2009"]
[time]
dt = 600.0
iterations = 1
[output]
vtu_every = 0
)", dem.string());
  for (const char* map : {"far", "half"}) {
    CAPTURE(map);
    std::string text = case_text;
    text.replace(text.find("MAP"), 3, (dir / (std::string(map) + ".asc")).string());
    std::ofstream(dir / "case.toml") << text;
    auto run = test::run_bodyfit("run " + (dir / "case.toml").string() + " -o " + (dir / map).string());
    if (std::string(map) == "far") {
      CHECK_MESSAGE(run.exit_code == 1, run.output);
      CHECK(run.output.find("far.asc: its extent x 463811.2..524011.2") != std::string::npos);
      CHECK(run.output.find("do not overlap: the raster is of another place") != std::string::npos);
    } else {
      CHECK_MESSAGE(run.exit_code == 0, run.output);
      CHECK(run.output.find("% of the terrain; beyond it, points take its nearest edge cell") != std::string::npos);
    }
  }
}
