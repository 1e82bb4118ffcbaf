// The fire model's wind as a time series (plugins/fire/wind.hpp): CSV reading and its errors,
// linear interpolation in time on the components, the model's V at the (sub-)step's time, runs
// against the uniform wind they must reproduce, and a resumed run equal to an uninterrupted one.
#include "wind.hpp"

#include <bodyfit/app/clock_time.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/plugin_loader.hpp>
#include <bodyfit/projection.hpp>
#include <bodyfit/velocity_model.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <optional>
#include <cmath>
#include <fstream>

using namespace bodyfit;
using bodyfit::fire::WindField;
namespace fs = std::filesystem;

namespace {

void write_text(const fs::path& file, const std::string& text) { std::ofstream(file) << text; }

// TOML literal string of a path (no escapes: the test directories have no quote in their names).
std::string toml_path(const fs::path& file) { return fmt::format("'{}'", file.string()); }

WindField series_wind(const fs::path& csv) {
  WindField wind;
  wind.type = "series";
  wind.series = fire::read_wind_series(csv);
  return wind;
}

// A flat square terrain of edge h over [0, size]².
SurfaceMesh flat_terrain(double size, double h) {
  HeightGrid grid;
  grid.cell_size = h;
  grid.cols = grid.rows = std::size_t(size / h) + 1;
  grid.heights.assign(grid.cols * grid.rows, 0.0);
  return make_terrain_from_grid(grid, h);
}

struct FireRun {
  SurfaceMesh mesh;
  EvolutionResult result;
};

// A disk (x, y, r) burning for `steps` steps of `dt` with the fire model configured by `model_toml`,
// CFL sub-steps of at most one edge (V recomputed at each sub-step's time).
FireRun burn(SurfaceMesh surface, std::array<double, 3> disk, const std::string& model_toml, double dt, int steps) {
  ScalarField phi(surface.n_vertices());
  for (auto v : surface.vertices())
    phi[v.idx()] = std::hypot(surface.point(v)[0] - disk[0], surface.point(v)[1] - disk[1]) - disk[2];
  RemeshOptions remesh;
  remesh.hmax = edge_length_stats(surface).mean;
  remesh.hausd = 0.05;
  remesh.reference = std::make_shared<ReferenceSurface>(surface);
  mesh_initial_region(surface, phi, {}, remesh);
  LoadedModel model = load_plugin_file(fs::path(BODYFIT_PLUGIN_DIR) / "bodyfit_fire.so");
  configure_model(model, toml::parse(model_toml));
  EvolutionOptions options;
  options.dt = dt;
  options.max_iterations = steps;
  options.remesh = remesh;
  options.height_field = true;
  options.max_cfl = 1.0;
  options.cfl_length = remesh.hmax;
  FireRun run;
  run.result = evolve(surface, model.model(), options, {}, EvolutionHooks::quiet());
  run.mesh = std::move(surface);
  return run;
}

// Area-weighted centroid of G in plan view.
std::array<double, 2> burnt_centroid(const SurfaceMesh& mesh) {
  double area = 0, x = 0, y = 0;
  for (auto f : mesh.faces()) {
    if (mesh.region(f) != kInside) continue;
    const auto p = face_points(mesh, f);
    const double a = face_area(mesh, f);
    area += a;
    x += a * (p[0][0] + p[1][0] + p[2][0]) / 3;
    y += a * (p[0][1] + p[1][1] + p[2][1]) / 3;
  }
  return {x / area, y / area};
}

// The fire model's rates of spread at every vertex of a flat square with a disk of G's distance,
// at `time`.
ScalarField rates_at(const std::string& model_toml, double time, std::optional<double> clock_start = std::nullopt) {
  const SurfaceMesh mesh = test::grid_square(20, {.x0 = 0, .y0 = 0, .x1 = 1000, .y1 = 1000});
  ScalarField distance(mesh.n_vertices());
  for (auto v : mesh.vertices()) distance[v.idx()] = std::hypot(mesh.point(v)[0] - 500, mesh.point(v)[1] - 450) - 200;
  LoadedModel model = load_plugin_file(fs::path(BODYFIT_PLUGIN_DIR) / "bodyfit_fire.so");
  configure_model(model, toml::parse(model_toml));
  const StepContext context =
      StepContext::standalone(mesh, distance, {.time = time, .dt = 10, .iteration = 0, .output_dir = {}, .height_field = false, .clock_start = clock_start});
  return model->compute(context).normal_speed;
}

}  // namespace

TEST_CASE("wind series: u and v interpolated linearly in time, the end values held before and after") {
  test::TempDir dir("wind_series");
  write_text(dir / "wind.csv", "# a comment\ntime,u,v\n0,2,0\n100, 4 ,2\n\n300,-4,2\n");
  WindField wind = series_wind(dir / "wind.csv");
  REQUIRE(wind.series.times == std::vector<double>{0, 100, 300});
  CHECK_FALSE(wind.series.clock_times);
  wind.set_clock(std::nullopt);
  const Vec3 x(123, 456, 7);
  CHECK(wind.at(x, -50) == Vec3(2, 0, 0));
  CHECK(wind.at(x, 0) == Vec3(2, 0, 0));
  CHECK(wind.at(x, 50) == Vec3(3, 1, 0));
  CHECK(wind.at(x, 100) == Vec3(4, 2, 0));
  CHECK(wind.at(x, 250) == Vec3(-2, 2, 0));
  CHECK(wind.at(x, 300) == Vec3(-4, 2, 0));
  CHECK(wind.at(x, 1e6) == Vec3(-4, 2, 0));
  // Brackets: the weight of the later time, from 0 at a time to 1 (excluded) before the next.
  const fire::TimeBracket b = fire::bracket_time(wind.series.times, 175);
  CHECK(b.index == 1);
  CHECK(b.next == 2);
  CHECK(b.weight == 0.375);
}

TEST_CASE("wind series of speed and direction: on the components, not the angle, and date-times on the run's clock") {
  test::TempDir dir("wind_series_polar");
  // From the west (towards +x) to from the north (towards −y) in one minute.
  write_text(dir / "wind.csv", "time,speed,direction_deg\n2026-07-14T13:00:00Z,10,270\n2026-07-14T15:01:00+02:00,10,360\n");
  WindField wind = series_wind(dir / "wind.csv");
  CHECK(wind.series.clock_times);
  CHECK_THROWS_WITH_AS(wind.set_clock(std::nullopt), doctest::Contains("[time] start"), InputError);
  const double start = *parse_iso8601("2026-07-14T12:59:30Z");  // t = 0 half a minute before the first
  wind.set_clock(start);
  const Vec3 x(0, 0, 0);
  CHECK(wind.at(x, 0)[0] == doctest::Approx(10));
  CHECK(std::abs(wind.at(x, 0)[1]) < 1e-12);
  const Vec3 half = wind.at(x, 60);  // half way between 30 s and 90 s
  CHECK(half[0] == doctest::Approx(5));
  CHECK(half[1] == doctest::Approx(-5));
  CHECK(half.norm() == doctest::Approx(10 / std::sqrt(2.0)));  // a vector mean: slower than 10 m/s
  CHECK(std::abs(wind.at(x, 500)[0]) < 1e-12);
  CHECK(wind.at(x, 500)[1] == doctest::Approx(-10));
}

TEST_CASE("wind series errors name the file and the line") {
  test::TempDir dir("wind_series_errors");
  const fs::path csv = dir / "wind.csv";
  auto error_of = [&](const std::string& text) {
    write_text(csv, text);
    try {
      fire::read_wind_series(csv);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string at = csv.string();
  CHECK(error_of("time,u,v\n0,1,1\n10,1,1\n10,2,2\n") ==
        at + ":4: time 10 is not after the previous row's (line 3): times must increase");
  CHECK(error_of("time,u,v\n0,1,1\n-5,1,1\n").starts_with(at + ":3: time -5 is not after"));
  CHECK(error_of("time,u\n0,1\n") == at + ":1: no column 'v' (expected time,speed,direction_deg or time,u,v)");
  CHECK(error_of("time,speed\n0,1\n") == at + ":1: no column 'direction_deg' (expected time,speed,direction_deg or time,u,v)");
  CHECK(error_of("time,u,v,w\n0,1,1,1\n") == at + ":1: unknown column 'w' (expected time,speed,direction_deg or time,u,v)");
  CHECK(error_of("time,u,v\n0,1,1\n5,nan,1\n") == at + ":3: u: nan is not a finite number");
  CHECK(error_of("time,u,v\n0,1,inf\n") == at + ":2: v: inf is not a finite number");
  CHECK(error_of("time,u,v\n0,1,1\n5,1x,1\n") == at + ":3: u: '1x' is not a number");
  CHECK(error_of("time,u,v\n0,1\n") == at + ":2: 2 field(s), the header has 3 (time,u,v)");
  CHECK(error_of("time,speed,direction_deg\n0,-1,90\n") == at + ":2: speed: -1 is negative (m/s, expected ≥ 0)");
  // Beyond any wind near the ground: a unit mistake (km/h for m/s) or a damaged value.
  CHECK(error_of("time,speed,direction_deg\n0,10,90\n60,360,90\n").starts_with(at + ":3: a wind of 360 m/s is beyond 150"));
  CHECK(error_of("time,u,v\n0,1e300,0\n").starts_with(at + ":2: a wind of 1e+300 m/s"));
  CHECK(error_of("time,u,v\nnoon,1,1\n").starts_with(at + ":2: time: 'noon' is neither a number"));
  CHECK(error_of("time,u,v\n0,1,1\n2026-07-14T13:00:00Z,1,1\n").starts_with(at + ":3: time: '2026-07-14T13:00:00Z' is a date-time"));
  CHECK(error_of("time,u,v\n") == at + ":1: no row after the header (expected time,speed,direction_deg or time,u,v)");
  CHECK(error_of("").starts_with(at + ": no header line"));
  CHECK(error_of("time,u,u\n").starts_with(at + ":1: the header 'time,u,u' has an empty or repeated column"));
  // The case's keys: a series needs its file, which only a series takes.
  LoadedModel model = load_plugin_file(fs::path(BODYFIT_PLUGIN_DIR) / "bodyfit_fire.so");
  CHECK_THROWS_WITH_AS(configure_model(model, toml::parse("[wind]\ntype = 'uniform'\nspeed = 1e300\ndirection_deg = 0\n")),
                       doctest::Contains("[model.wind] speed: a wind of 1e+300 m/s is beyond 150 m/s"), InputError);
  CHECK_THROWS_WITH_AS(configure_model(model, toml::parse("[wind]\ntype = 'uniform'\nvelocity = [200.0, 0.0]\n")),
                       doctest::Contains("velocity: a wind of 200 m/s"), InputError);
  CHECK_THROWS_WITH_AS(configure_model(model, toml::parse("[wind]\ntype = 'series'\n")),
                       doctest::Contains("type = \"series\" needs file"), InputError);
  CHECK_THROWS_WITH_AS(configure_model(model, toml::parse("[wind]\ntype = 'uniform'\nfile = 'w.csv'\n")),
                       doctest::Contains("[model.wind] file is not used: it applies to type = \"series\" or \"grid_series\""), InputError);
  CHECK_THROWS_WITH_AS(configure_model(model, toml::parse("[wind]\ntype = 'series'\nfile = " + toml_path(dir / "none.csv") + "\n")),
                       doctest::Contains("none.csv: cannot open"), InputError);
}

TEST_CASE("wind grid series: rasters relative to the CSV, interpolated per cell in time, one frame") {
  test::TempDir dir("wind_grid_series");
  fs::create_directories(dir / "rasters");
  // 3 × 2 cells of 100 m from (0, 0); row 0 is the northern one.
  auto raster = [&](const std::string& name, const std::string& rows, double x0 = 0) {
    write_text(dir / "rasters" / name, fmt::format("ncols 3\nnrows 2\nxllcorner {}\nyllcorner 0\ncellsize 100\n"
                                                   "NODATA_value -9999\n{}",
                                                   x0, rows));
  };
  raster("u0.asc", "1 2 3\n4 5 6\n");
  raster("v0.asc", "0 0 0\n0 0 -9999\n");  // filled with the nearest valid value, 0
  raster("u1.asc", "3 4 5\n6 7 8\n");
  raster("v1.asc", "10 10 10\n10 10 10\n");
  raster("shifted.asc", "1 1 1\n1 1 1\n", 50);
  write_text(dir / "wind.csv", "time,u_file,v_file\n0,rasters/u0.asc,rasters/v0.asc\n600,rasters/u1.asc,rasters/v1.asc\n");
  WindField wind;
  wind.type = "grid_series";
  wind.series = fire::read_wind_grid_series(dir / "wind.csv");
  wind.set_clock(std::nullopt);
  // At cell centres the bilinear sampling is the cell's value.
  const Vec3 south_east(250, 50, 0), north_west(50, 150, 0);
  CHECK(wind.at(south_east, -1) == Vec3(6, 0, 0));
  CHECK(wind.at(south_east, 150) == Vec3(6.5, 2.5, 0));
  CHECK(wind.at(north_west, 300) == Vec3(2, 5, 0));
  CHECK(wind.at(north_west, 900) == Vec3(3, 10, 0));
  REQUIRE(wind.rasters().size() == 1);
  CHECK(wind.rasters().front().second == dir / "rasters" / "u0.asc");

  write_text(dir / "bad.csv", "time,u_file,v_file\n0,rasters/u0.asc,rasters/v0.asc\n600,rasters/shifted.asc,rasters/v1.asc\n");
  CHECK_THROWS_WITH_AS(fire::read_wind_grid_series(dir / "bad.csv"),
                       doctest::Contains(((dir / "bad.csv").string() + ":3: u_file: ").c_str()), InputError);
  CHECK_THROWS_WITH_AS(fire::read_wind_grid_series(dir / "bad.csv"), doctest::Contains("share one frame"), InputError);
  write_text(dir / "missing.csv", "time,u_file,v_file\n0,rasters/u0.asc,rasters/nothing.asc\n");
  CHECK_THROWS_WITH_AS(fire::read_wind_grid_series(dir / "missing.csv"),
                       doctest::Contains(((dir / "missing.csv").string() + ":2: v_file: ").c_str()), InputError);
}

TEST_CASE("the model's V at a time between two entries is that of the interpolated uniform wind") {
  test::TempDir dir("wind_series_model");
  write_text(dir / "wind.csv", "time,u,v\n0,2,0\n100,6,4\n");
  const std::string series = "[wind]\ntype = 'series'\nfile = " + toml_path(dir / "wind.csv") + "\n";
  // t = 25: (2, 0) + 0.25·(4, 4) = (3, 1); t = 400, after the last: (6, 4).
  const ScalarField at_25 = rates_at(series, 25);
  CHECK(at_25 == rates_at("[wind]\ntype = 'uniform'\nvelocity = [3.0, 1.0]\n", 25));
  CHECK(rates_at(series, 400) == rates_at("[wind]\ntype = 'uniform'\nvelocity = [6.0, 4.0]\n", 0));
  CHECK(at_25 != rates_at(series, 0));  // the wind matters here
  // Date-times need the run's clock: an error naming the file at the first compute without one.
  write_text(dir / "clock.csv", "time,u,v\n2026-07-14T13:00:00Z,2,0\n2026-07-14T13:01:40Z,6,4\n");
  const std::string clock = "[wind]\ntype = 'series'\nfile = " + toml_path(dir / "clock.csv") + "\n";
  CHECK(rates_at(clock, 35, *parse_iso8601("2026-07-14T12:59:50Z")) == at_25);
  CHECK_THROWS_WITH_AS(rates_at(clock, 0), doctest::Contains("clock.csv: its times are ISO 8601"), InputError);
}

TEST_CASE("a series of equal entries burns exactly as the uniform wind") {
  test::TempDir dir("wind_series_uniform");
  write_text(dir / "wind.csv", "time,speed,direction_deg\n0,8,250\n1000,8,250\n");
  const std::string series = "[wind]\ntype = 'series'\nfile = " + toml_path(dir / "wind.csv") + "\n";
  FireRun a = burn(flat_terrain(1200, 25), {500, 600, 120}, series, 60, 4);
  FireRun b = burn(flat_terrain(1200, 25), {500, 600, 120}, "[wind]\ntype = 'uniform'\nspeed = 8.0\ndirection_deg = 250.0\n",
                   60, 4);
  REQUIRE(a.result.records.size() == 4);
  CHECK(a.result.records.back().substeps > 1);
  REQUIRE(a.mesh.n_vertices() == b.mesh.n_vertices());
  std::size_t differ = 0;
  for (auto v : a.mesh.vertices()) differ += a.mesh.point(v) != b.mesh.point(VertexHandle(v.idx()));
  CHECK(differ == 0);
  CHECK(region_area(a.mesh, kInside) == region_area(b.mesh, kInside));
}

TEST_CASE("a wind turning from west to north half way shifts the burnt region east, then south") {
  test::TempDir dir("wind_series_turn");
  // 12 m/s from the west for 240 s, from the north from 300 s to the end (480 s).
  write_text(dir / "turn.csv", "time,speed,direction_deg\n0,12,270\n240,12,270\n300,12,360\n480,12,360\n");
  write_text(dir / "west.csv", "time,speed,direction_deg\n0,12,270\n480,12,270\n");
  auto shift = [&](const std::string& csv) {
    FireRun run = burn(flat_terrain(1400, 25), {700, 700, 100},
                       "[wind]\ntype = 'series'\nfile = " + toml_path(dir / csv) + "\n", 120, 4);
    const auto c = burnt_centroid(run.mesh);
    return std::array<double, 2>{c[0] - 700, c[1] - 700};
  };
  const auto turn = shift("turn.csv"), west = shift("west.csv");
  MESSAGE("centroid shift: turning (" << turn[0] << ", " << turn[1] << ") m, west only (" << west[0] << ", "
                                      << west[1] << ") m");
  CHECK(west[0] > 20);                          // the head runs east
  CHECK(std::abs(west[1]) < 0.05 * west[0]);    // and nowhere else
  CHECK(turn[0] > 0.2 * west[0]);               // east for the first half
  CHECK(turn[0] < 0.8 * west[0]);               // not for the second
  CHECK(turn[1] < -0.2 * west[0]);              // south for the second half
}

TEST_CASE("a run under a wind series killed and resumed writes every output as the uninterrupted run, byte for byte") {
  // A fire on a small procedural terrain under a wind given at clock times that turns and changes
  // speed, CFL sub-steps (V at each sub-step's time), every output on: VTUs, history, a checkpoint
  // per iteration, the GeoTIFFs and the GeoPackage of perimeters.
  test::TempDir dir("wind_series_resume");
  write_text(dir / "wind.csv", "time,speed,direction_deg\n"
                               "2026-07-14T13:00:00Z,6,270\n"
                               "2026-07-14T13:20:00Z,10,300\n"
                               "2026-07-14T13:40:00Z,4,360\n");
  write_text(dir / "case.toml", R"(
[surface]
generator = "terrain"
extent = 6000.0
h = 400.0
seed = 7
max_height = 600.0
feature_size = 2000.0
[region]
shape = "disks"
centers = [[3000.0, 3000.0]]
radii = [1000.0]
[model]
name = "fire"
[model.wind]
type = "series"
file = "wind.csv"
[model.arrival]
cell_size = 200.0
[time]
dt = 600.0
final_time = 2600.0
max_cfl = 2.0
start = "2026-07-14T12:55:00Z"
[remesh]
hmax = 400.0
[output]
vtu_every = 1
png_every = 0
checkpoint_every = 1
checkpoint_seconds = 0
)");
  auto run = [&](const std::string& out, const std::string& arguments) {
    return test::run_bodyfit("run " + (dir / "case.toml").string() + " -o " + (dir / out).string() + " " + arguments);
  };
  const auto full = run("full", "");
  REQUIRE_MESSAGE(full.exit_code == 0, full.output);
  const auto killed = run("killed", "--inject-fault checkpoint:2");
  REQUIRE_MESSAGE(killed.exit_code == 128 + 9, killed.output);
  const auto resumed = run("killed", "--resume");
  REQUIRE_MESSAGE(resumed.exit_code == 0, resumed.output);
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir / "full")) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  CHECK(std::count(names.begin(), names.end(), "perimeters.gpkg") == 1);
  CHECK(std::count(names.begin(), names.end(), "arrival_time.tif") == 1);
  for (const auto& name : names) {
    CAPTURE(name);
    REQUIRE(fs::exists(dir / "killed" / name));
    if (name == "history.csv")
      CHECK(test::history_without_timings(dir / "killed" / name) == test::history_without_timings(dir / "full" / name));
    else
      CHECK(test::read_file(dir / "killed" / name) == test::read_file(dir / "full" / name));
  }
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir / "killed")) ++files;
  CHECK(files == names.size());
}
