// Ignitions from a vector layer ([region] shape = "ignitions"): points as disks, lines as buffers,
// polygons as they are, each at its time; late ones join G when their time comes; a start
// date-time ([time] start) for times given as clock times.
#include <bodyfit/app/model_files.hpp>
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/app/clock_time.hpp>
#include <bodyfit/app/config.hpp>
#include <bodyfit/app/coordinate_system.hpp>
#include <bodyfit/app/raster_io.hpp>
#include <bodyfit/app/map.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/app/plan_geometry.hpp>
#include <bodyfit/plugin_loader.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>

using namespace bodyfit;

namespace {

constexpr double kCell = 20;  // the flat DEM's cell and the mesh size

// A flat DEM over [0, 2000]² in UTM zone 32N (the .prj of the Luxembourg DEM beside it).
void write_flat_dem(const std::filesystem::path& dir) {
  std::ofstream out(dir / "flat.asc");
  const int n = 101;
  out << "ncols " << n << "\nnrows " << n << "\nxllcorner 0\nyllcorner 0\ncellsize " << kCell << "\n";
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) out << "100 ";
    out << "\n";
  }
  std::filesystem::copy_file(test::source_path("meshes/dem/luxembourg_elev_200m.prj"), dir / "flat.prj");
}

void write_layer(const std::filesystem::path& file, const std::string& features, int epsg = 32632) {
  std::ofstream(file) << R"({"type": "FeatureCollection", "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::)"
                      << epsg << R"("}}, "features": [)" << features << "]}";
}

std::string feature(const std::string& geometry, const std::string& time = "null") {
  return R"({"type": "Feature", "properties": {"ignition": )" + time + R"(}, "geometry": )" + geometry + "}";
}

CaseConfig ignition_case(const std::filesystem::path& dir, const std::string& region_extra = "",
                         const std::string& time_extra = "") {
  const std::string text = "[surface]\ngenerator = \"terrain\"\ndem = \"flat.asc\"\nh = 20.0\n"
                           "[region]\nshape = \"ignitions\"\nfile = \"ignitions.geojson\"\n" + region_extra +
                           "\n[model]\nname = \"fire\"\n[time]\ndt = 50.0\nfinal_time = 100.0\n" + time_extra +
                           "\n[remesh]\nhmax = 20.0\n";
  return parse_case(toml::parse(text), dir);
}

// |G| of the initial state against the exact area: within a twentieth of an edge along the front.
void check_initial_area(const std::filesystem::path& dir, const std::string& radius, double exact, double front) {
  const CaseSetup setup = setup_case(ignition_case(dir, radius));
  const double area = region_plan_area(setup.mesh);
  const double bound = 0.05 * kCell * front;  // measured: 0.002-0.011 (the chords of the disks)
  INFO("area " << area << " exact " << exact << " bound " << bound);
  CHECK(std::abs(area - exact) <= bound);
}

}  // namespace

TEST_CASE("ignitions: a point, a line and a polygon with a hole give G(0) of their areas") {
  if constexpr (!config::have_gdal) return;
  test::TempDir dir("ignitions_shapes");
  write_flat_dem(dir.path());
  const auto layer = dir / "ignitions.geojson";
  const double pi = std::numbers::pi;
  SUBCASE("a point: a disk of the radius") {
    write_layer(layer, feature(R"({"type": "Point", "coordinates": [1000, 1000]})"));
    check_initial_area(dir.path(), "radius = 150.0", pi * 150 * 150, 2 * pi * 150);
  }
  SUBCASE("a line: a buffer of the radius, 2rL + πr²") {
    write_layer(layer, feature(R"({"type": "LineString", "coordinates": [[700, 1000], [1300, 1000]]})"));
    check_initial_area(dir.path(), "radius = 50.0", 2 * 50 * 600 + pi * 50 * 50, 2 * 600 + 2 * pi * 50);
  }
  SUBCASE("a polygon with a hole: its area (no radius needed)") {
    write_layer(layer, feature(R"({"type": "Polygon", "coordinates": [[[800, 800], [1200, 800], [1200, 1200], [800, 1200],
                                   [800, 800]], [[950, 950], [950, 1050], [1050, 1050], [1050, 950], [950, 950]]]})"));
    check_initial_area(dir.path(), "", 400 * 400 - 100 * 100, 4 * 400 + 4 * 100);
  }
  SUBCASE("all three in one layer, apart: the sum") {
    write_layer(layer, feature(R"({"type": "Point", "coordinates": [300, 300]})") + "," +
                           feature(R"({"type": "LineString", "coordinates": [[300, 1500], [900, 1500]]})") + "," +
                           feature(R"({"type": "Polygon", "coordinates": [[[1300, 300], [1700, 300], [1700, 700],
                                      [1300, 700], [1300, 300]]]})"));
    const double r = 100;
    check_initial_area(dir.path(), "radius = 100.0", pi * r * r + (2 * r * 600 + pi * r * r) + 400 * 400,
                       2 * pi * r + (2 * 600 + 2 * pi * r) + 1600);
  }
}

TEST_CASE("ignitions: points and lines need a radius, times need a start when they are date-times, CRS must match") {
  if constexpr (!config::have_gdal) return;
  test::TempDir dir("ignitions_errors");
  write_flat_dem(dir.path());
  const auto layer = dir / "ignitions.geojson";
  write_layer(layer, feature(R"({"type": "Point", "coordinates": [1000, 1000]})"));
  CHECK_THROWS_WITH_AS(setup_case(ignition_case(dir.path())), doctest::Contains("radius"), InputError);
  write_layer(layer, feature(R"({"type": "Point", "coordinates": [1000, 1000]})", "\"2026-07-14T13:30:00Z\""));
  CHECK_THROWS_WITH_AS(setup_case(ignition_case(dir.path(), "radius = 50.0\ntime_attribute = \"ignition\"")),
                       doctest::Contains("start"), InputError);
  write_layer(layer, feature(R"({"type": "Point", "coordinates": [1000, 1000]})", "600"));
  CHECK_THROWS_WITH_AS(setup_case(ignition_case(dir.path(), "radius = 50.0\ntime_attribute = \"ignition\"")),
                       doctest::Contains("no feature ignites at t = 0"), InputError);
  write_layer(layer, feature(R"({"type": "Point", "coordinates": [1000, 1000]})"), 32633);
  CHECK_THROWS_WITH_AS(setup_case(ignition_case(dir.path(), "radius = 50.0")),
                       doctest::Contains("is in EPSG:32633 (WGS 84 / UTM zone 33N), the surface in EPSG:32632"),
                       InputError);
  CHECK_THROWS_AS(ignition_case(dir.path(), "radius = 50.0", "start = \"2026-07-14T13:00:00\""), InputError);  // no zone
}

TEST_CASE("ignitions: a layer in degrees follows a DEM in degrees reprojected to UTM") {
  if constexpr (!config::have_gdal) return;
  test::TempDir dir("ignitions_reprojected");
  // A flat DEM in WGS 84 degrees around (6.03° E, 50.0° N), cells of 0.001°, warped to UTM 32N by
  // the case; one ignition point in degrees at its centre.
  HeightGrid dem;
  dem.cols = 100, dem.rows = 60, dem.x_origin = 5.98, dem.y_origin = 49.97, dem.cell_size = 0.001;
  dem.heights.assign(dem.cols * dem.rows, 200.0);
  dem.crs =
      "GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\",6378137.0,298.257223563]],"
      "PRIMEM[\"Greenwich\",0.0],UNIT[\"Degree\",0.0174532925199433]]";
  write_raster(dir / "dem.asc", dem);
  write_layer(dir / "ignitions.geojson", feature(R"({"type": "Point", "coordinates": [6.03, 50.0]})"), 4326);
  const std::string text = "[surface]\ngenerator = \"terrain\"\ndem = \"dem.asc\"\nreproject = \"utm\"\nh = 50.0\n"
                           "[region]\nshape = \"ignitions\"\nfile = \"ignitions.geojson\"\nradius = 300.0\n"
                           "[model]\nname = \"fire\"\n[time]\ndt = 50.0\nfinal_time = 100.0\n[remesh]\nhmax = 50.0\n";
  const CaseConfig config = parse_case(toml::parse(text), dir.path());
  const CaseSetup setup = setup_case(config);
  // G(0): a disk of 300 m around the point, in UTM metres.
  std::vector<PlanPoint> centre = {{6.03, 50.0}};
  transform_points(dem.crs, case_surface_source(config).crs, centre, "centre");
  const std::vector<PlanPolygon> outline = region_outline(setup.mesh);
  REQUIRE(outline.size() == 1);
  double cx = 0, cy = 0, n = 0;
  for (const PlanPoint& p : outline[0].rings[0]) cx += p[0], cy += p[1], ++n;
  INFO("G(0) centre (" << cx / n << ", " << cy / n << "), the point (" << centre[0][0] << ", " << centre[0][1] << ")");
  CHECK(std::hypot(cx / n - centre[0][0], cy / n - centre[0][1]) < 10);
  CHECK(polygon_area(outline[0]) == doctest::Approx(std::numbers::pi * 300 * 300).epsilon(0.02));
}

TEST_CASE("ignitions: a late ignition joins G at its time (the step lands on it), and the arrival raster says so") {
  if constexpr (!config::have_gdal) return;
  test::TempDir dir("ignitions_late");
  write_flat_dem(dir.path());
  // One point at t = 0, one at 13:01 (t = 60 s after the start 13:00).
  write_layer(dir / "ignitions.geojson",
              feature(R"({"type": "Point", "coordinates": [500, 1000]})", "\"2026-07-14T13:00:00Z\"") + "," +
                  feature(R"({"type": "Point", "coordinates": [1500, 1000]})", "\"2026-07-14T15:01:00+02:00\""));
  const CaseConfig config = ignition_case(dir.path(), "radius = 100.0\ntime_attribute = \"ignition\"",
                                          "start = \"2026-07-14T13:00:00Z\"");
  CaseSetup setup = setup_case(config);
  REQUIRE(setup.options.additions.size() == 1);
  CHECK(setup.options.additions[0].time == 60);
  CHECK(region_components(setup.mesh, kInside) == 1);
  REQUIRE(setup.options.clock_start);
  CHECK(format_iso8601(*setup.options.clock_start) == "2026-07-14T13:00:00Z");
  LoadedModel model = load_plugin_file(std::filesystem::path(BODYFIT_PLUGIN_DIR) / "bodyfit_fire.so");
  configure_model(model, toml::parse("[perimeters]\nfile = \"\"\n"));
  setup.options.output_dir = dir.path();
  GridFiles grids(dir.path(), "asc", model->outputs(), "fire");
  EvolutionHooks hooks = EvolutionHooks::quiet();
  hooks.outputs = &grids;
  const EvolutionResult result = evolve(setup.mesh, model.model(), setup.options, {}, hooks);
  REQUIRE(result.records.size() == 3);  // 0 → 50 → 60 (the ignition) → 100
  CHECK(result.records[0].time == doctest::Approx(50));
  CHECK(result.records[1].time == doctest::Approx(60));
  CHECK(result.records[0].components == 1);
  CHECK(result.records[1].components == 2);
  // Both disks grew at R0 on flat ground: radii 100 + R0·100 and 100 + R0·40.
  const double R0 = 0.398, pi = std::numbers::pi;
  const double r1 = 100 + R0 * 100, r2 = 100 + R0 * 40;
  const double exact = pi * (r1 * r1 + r2 * r2), area = region_plan_area(setup.mesh);
  INFO("area " << area << " exact " << exact);
  CHECK(std::abs(area - exact) <= 0.05 * kCell * 2 * pi * (r1 + r2));  // measured: 0.017
  // The arrival raster: 0 at the first ignition, 60 s at the second one's centre.
  const HeightGrid arrival = read_esri_ascii(dir / "arrival_time.asc");
  CHECK(arrival.sample(500, 1000) == doctest::Approx(0));
  CHECK(arrival.sample(1500, 1000) == doctest::Approx(60));
  // A map marks both, found where the arrival times start (a layer's ignitions are not disks of
  // the case), within a cell of the layer's points.
  std::vector<Vec3> points = ignitions_from_arrival(arrival);
  REQUIRE(points.size() == 2);
  std::sort(points.begin(), points.end(), [](const Vec3& a, const Vec3& b) { return a[0] < b[0]; });
  CHECK(std::hypot(points[0][0] - 500, points[0][1] - 1000) < arrival.cell_size);
  CHECK(std::hypot(points[1][0] - 1500, points[1][1] - 1000) < arrival.cell_size);
}
