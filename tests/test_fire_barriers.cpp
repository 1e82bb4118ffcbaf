// Barriers of the fire model and the coordinate system of a case (the surface's reaches the model).
#include "balbi.hpp"
#include "barriers.hpp"

#include <bodyfit/app/model_files.hpp>
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/app/config.hpp>
#include <bodyfit/app/coordinate_system.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/plugin_loader.hpp>
#include <bodyfit/projection.hpp>
#include <bodyfit/app/raster_io.hpp>
#include <bodyfit/app/vector_io.hpp>

#include "test_support.hpp"

#include <fmt/format.h>

#include <doctest/doctest.h>

#include <cmath>
#include <fstream>

using namespace bodyfit;

namespace {

// Flat ground over [0, size]², meshed by the DEM path of the generators, shifted by (x0, y0).
SurfaceMesh flat_ground(double size, double h, double x0 = 0, double y0 = 0) {
  HeightGrid grid;
  grid.cell_size = h;
  grid.x_origin = x0, grid.y_origin = y0;
  grid.cols = grid.rows = std::size_t(size / h) + 1;
  grid.heights.assign(grid.cols * grid.rows, 0.0);
  return make_terrain_from_grid(grid, h);
}

LoadedModel fire_model() { return load_plugin_file(std::filesystem::path(BODYFIT_PLUGIN_DIR) / "bodyfit_fire.so"); }

// Burn a disk (x, y, r) for `steps` steps of `dt` with CFL sub-steps at `max_cfl` (the fire cases'
// default, 4), the model configured by `toml_text` for a surface from `source`.
SurfaceMesh burn(SurfaceMesh surface, std::array<double, 3> disk, const std::string& toml_text, double dt, int steps,
                 const SurfaceSource& source = {}, const std::filesystem::path& output_dir = {}) {
  ScalarField phi(surface.n_vertices());
  for (auto v : surface.vertices())
    phi[v.idx()] = std::hypot(surface.point(v)[0] - disk[0], surface.point(v)[1] - disk[1]) - disk[2];
  RemeshOptions remesh;
  remesh.hmax = edge_length_stats(surface).mean;
  remesh.reference = std::make_shared<ReferenceSurface>(surface);
  mesh_initial_region(surface, phi, {}, remesh);
  LoadedModel model = fire_model();
  configure_model(model, toml::parse(toml_text), source);
  EvolutionOptions options;
  options.dt = dt;
  options.max_iterations = steps;
  options.remesh = remesh;
  options.height_field = true;
  options.output_dir = output_dir;
  options.max_cfl = 4;
  options.cfl_length = remesh.hmax;
  GridFiles grids(output_dir, "asc", model->outputs(), "fire");
  EvolutionHooks hooks = EvolutionHooks::quiet();
  if (!output_dir.empty()) hooks.outputs = &grids;
  evolve(surface, model.model(), options, {}, hooks);
  return surface;
}

// The vertices of the faces of G (the burnt region).
std::vector<Vec3> burnt_vertices(const SurfaceMesh& mesh) {
  std::vector<char> seen(mesh.n_vertices(), 0);
  std::vector<Vec3> points;
  for (auto f : mesh.faces())
    if (mesh.region(f) == kInside)
      for (auto v : mesh.fv_range(f))
        if (!seen[v.idx()]++) points.push_back(mesh.point(v));
  return points;
}

void write_text(const std::filesystem::path& file, const std::string& text) { std::ofstream(file) << text; }

/// The ESRI WKT of WGS 84 / UTM zone 32N and of WGS 84 (as gdalsrsinfo -o wkt_esri writes them).
const char* const kUtm32 =
    "PROJCS[\"WGS_1984_UTM_Zone_32N\",GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\","
    "6378137.0,298.257223563]],PRIMEM[\"Greenwich\",0.0],UNIT[\"Degree\",0.0174532925199433]],PROJECTION["
    "\"Transverse_Mercator\"],PARAMETER[\"False_Easting\",500000.0],PARAMETER[\"False_Northing\",0.0],"
    "PARAMETER[\"Central_Meridian\",9.0],PARAMETER[\"Scale_Factor\",0.9996],PARAMETER[\"Latitude_Of_Origin\","
    "0.0],UNIT[\"Meter\",1.0]]";
const char* const kUtm31 =
    "PROJCS[\"WGS_1984_UTM_Zone_31N\",GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\","
    "6378137.0,298.257223563]],PRIMEM[\"Greenwich\",0.0],UNIT[\"Degree\",0.0174532925199433]],PROJECTION["
    "\"Transverse_Mercator\"],PARAMETER[\"False_Easting\",500000.0],PARAMETER[\"False_Northing\",0.0],"
    "PARAMETER[\"Central_Meridian\",3.0],PARAMETER[\"Scale_Factor\",0.9996],PARAMETER[\"Latitude_Of_Origin\","
    "0.0],UNIT[\"Meter\",1.0]]";
const char* const kWgs84 =
    "GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\",6378137.0,298.257223563]],"
    "PRIMEM[\"Greenwich\",0.0],UNIT[\"Degree\",0.0174532925199433]]";

// A GeoJSON layer of LineStrings / Polygons (coordinates as written), without a CRS member.
std::string geojson(const std::vector<std::string>& geometries) {
  std::string features;
  for (const auto& g : geometries)
    features += (features.empty() ? "" : ",") + std::string(R"({"type":"Feature","properties":{},"geometry":)") + g + "}";
  return R"({"type":"FeatureCollection","features":[)" + features + "]}";
}

// The fire of the barrier tests: flat ground 1600 m square, h = 20 m, a 15 m/s wind along +x, a
// disk of 150 m at x = 400; its head reaches x = 900 + 5h within the run when nothing stops it.
constexpr double kSize = 1600, kH = 20, kLineX = 900, kDt = 20;
const std::string kWind = "[wind]\ntype = 'uniform'\nvelocity = [15.0, 0.0]\n"
                          "[perimeters]\nfile = ''\n";
int steps_past_the_line() {
  fire::BalbiParameters p;
  const double head = fire::rate_of_spread(std::atan(15.0 / p.u0), p);
  return int(std::ceil((kLineX + 5 * kH - 550) / (head * kDt)));
}

}  // namespace

TEST_CASE("barriers: a line narrower than the mesh stops a wind-driven fire, which crosses it without the barrier") {
  if (!config::have_gdal) return;
  bodyfit::test::TempDir dir("fire_barrier_line");
  // A road of no width, slightly slanted (x from 905 to 915 m: not along a lattice column), across
  // the whole domain ahead of the fire.
  const PlanPoint a = {kLineX + 5, -50}, b = {kLineX + 15, kSize + 50};
  write_text(dir / "road.geojson", geojson({fmt::format(R"({{"type":"LineString","coordinates":[[{},{}],[{},{}]]}})",
                                                        a[0], a[1], b[0], b[1])}));
  // How far beyond the line (towards +x) the farthest vertex of G lies.
  auto beyond_line = [&](const SurfaceMesh& mesh) {
    double farthest = -1e300;
    for (const auto& p : burnt_vertices(mesh))
      farthest = std::max(farthest, p[0] - (a[0] + (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1])));
    return farthest;
  };
  const int steps = steps_past_the_line();
  const double free_run = beyond_line(burn(flat_ground(kSize, kH), {400, 800, 150}, kWind, kDt, steps));
  CHECK(free_run > 3 * kH);  // the test can fail: unobstructed, the fire crosses the line

  const std::string with_road = kWind + fmt::format("[barriers]\nfile = '{}'\n", (dir / "road.geojson").string());
  const double blocked = beyond_line(burn(flat_ground(kSize, kH), {400, 800, 150}, with_road, kDt, steps));
  MESSAGE("h = " << kH << ", " << steps << " steps at max_cfl 4: the farthest vertex of G " << free_run
                 << " m beyond the line without the barrier, " << blocked << " m with it");
  // Every point of G lies in a face with a burning corner, and burning corners are farther than
  // the band's half-width (2 ĥ) from the line: G stays short of it (by ĥ at least).
  CHECK(blocked < 0);
  CHECK(blocked > -5 * kH);  // it did reach the barrier
}

TEST_CASE("barriers: a polygon (a lake) in the fire's path is not burnt, and the fire passes round it") {
  if (!config::have_gdal) return;
  bodyfit::test::TempDir dir("fire_barrier_lake");
  // A square lake 100 m wide across the head's path, on the fire's axis y = 800 (the fire is 300 m wide).
  const PlanPath lake = {{700, 750}, {800, 750}, {800, 850}, {700, 850}};
  write_text(dir / "lake.geojson",
             geojson({R"({"type":"Polygon","coordinates":[[[700,750],[800,750],[800,850],[700,850],[700,750]]]})"}));
  const std::string with_lake = kWind + fmt::format("[barriers]\nfile = '{}'\n", (dir / "lake.geojson").string());
  const SurfaceMesh run = burn(flat_ground(kSize, kH), {400, 800, 150}, with_lake, kDt, steps_past_the_line());
  const std::vector<Vec3> burnt = burnt_vertices(run);
  std::size_t in_lake = 0, beyond = 0;
  for (const auto& p : burnt) {
    in_lake += inside_ring(lake, p[0], p[1]);
    beyond += p[0] > 800;
  }
  MESSAGE("burnt vertices " << burnt.size() << ", beyond the lake " << beyond << ", in it " << in_lake);
  CHECK(in_lake == 0);
  CHECK(beyond > 0);  // the flanks went past the lake
}

TEST_CASE("barriers: the grid's distance and inside tests agree with the plan geometry's") {
  if (!config::have_gdal) return;
  bodyfit::test::TempDir dir("fire_barrier_grid");
  // A zigzag line and a polygon with a hole, queried on a lattice against brute force.
  write_text(dir / "mixed.geojson",
             geojson({R"({"type":"LineString","coordinates":[[0,0],[300,170],[20,400],[390,390]]})",
                      R"({"type":"Polygon","coordinates":[[[500,0],[900,50],[800,400],[520,300],[500,0]],)"
                      R"([[600,100],[700,100],[700,200],[600,200],[600,100]]]})"}));
  const fire::Barriers barriers = fire::Barriers::read({.file = dir / "mixed.geojson"}, {});
  const PlanPath line = {{0, 0}, {300, 170}, {20, 400}, {390, 390}};
  PlanPolygon polygon;
  polygon.rings = {{{500, 0}, {900, 50}, {800, 400}, {520, 300}}, {{600, 100}, {700, 100}, {700, 200}, {600, 200}}};
  std::size_t differ = 0, blocked = 0;
  for (double reach : {7.0, 35.0})
    for (double x = -53; x < 1000; x += 9.7)
      for (double y = -47; y < 500; y += 8.3) {
        const bool expected = distance_to_path(line, x, y, false) <= reach ||
                              signed_distance_to_polygon(polygon, x, y) <= reach;
        differ += barriers.blocks(x, y, reach) != expected;
        blocked += expected;
      }
  CHECK(blocked > 1000);
  CHECK(differ == 0);
}

TEST_CASE("coordinate systems: a model raster in another system than the DEM's is an error naming both") {
  if (!config::have_gdal) return;
  bodyfit::test::TempDir dir("fire_crs_mismatch");
  HeightGrid fuel;
  fuel.cols = fuel.rows = 4, fuel.x_origin = 300000, fuel.y_origin = 5500000, fuel.cell_size = 100;
  fuel.heights.assign(16, 1.0);
  fuel.crs = kUtm31;
  write_raster(dir / "fuel.asc", fuel);
  const SurfaceSource surface{.file = dir / "dem.tif", .crs = kUtm32};
  LoadedModel model = fire_model();
  const std::string toml_text = fmt::format("[fuel]\nmap = '{}'\n", (dir / "fuel.asc").string());
  try {
    configure_model(model, toml::parse(toml_text), surface);
    FAIL("no error");
  } catch (const InputError& e) {
    const std::string message = e.what();
    INFO(message);
    CHECK(message.find("fuel.asc") != std::string::npos);
    CHECK(message.find("dem.tif") != std::string::npos);
    CHECK(message.find("EPSG:32631 (WGS 84 / UTM zone 31N)") != std::string::npos);
    CHECK(message.find("EPSG:32632 (WGS 84 / UTM zone 32N)") != std::string::npos);
  }
  // A barrier layer too.
  write_text(dir / "road.geojson",
             R"({"type":"FeatureCollection","crs":{"type":"name","properties":{"name":"urn:ogc:def:crs:EPSG::32631"}},)"
             R"("features":[{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[0,0],[1,1]]}}]})");
  LoadedModel second = fire_model();
  CHECK_THROWS_WITH_AS(
      configure_model(second, toml::parse(fmt::format("[barriers]\nfile = '{}'\n", (dir / "road.geojson").string())), surface),
      doctest::Contains("EPSG:32631 (WGS 84 / UTM zone 31N)"), InputError);
  // The same raster in the surface's system is accepted; one without a system too (a warning).
  fuel.crs = kUtm32;
  write_raster(dir / "fuel32.asc", fuel);
  LoadedModel third = fire_model();
  CHECK_NOTHROW(configure_model(third, toml::parse(fmt::format("[fuel]\nmap = '{}'\n", (dir / "fuel32.asc").string())), surface));
  fuel.crs.clear();
  write_raster(dir / "fuel_none.asc", fuel);
  LoadedModel fourth = fire_model();
  CHECK_NOTHROW(configure_model(fourth, toml::parse(fmt::format("[fuel]\nmap = '{}'\n", (dir / "fuel_none.asc").string())), surface));
}

TEST_CASE("a fuel map is read as it is: a lone cell of another code is the map's, not a damaged height") {
  // 1 m cells: a lone code 7 among 1s stands 6 off its neighbours, twice the 3 cells' size beyond
  // which a DEM's lone cell is taken for a damaged one and given their median. In a fuel map it is
  // data: here a code the presets do not have, which the model must name rather than burn as 1.
  bodyfit::test::TempDir dir("fire_fuel_lone_cell");
  HeightGrid fuel;
  fuel.cols = fuel.rows = 8, fuel.cell_size = 1;
  fuel.heights.assign(64, 1.0);
  fuel.heights[3 * 8 + 4] = 7;
  write_raster(dir / "fuel.asc", fuel);
  LoadedModel model = fire_model();
  CHECK_THROWS_WITH_AS(configure_model(model, toml::parse(fmt::format("[fuel]\nmap = '{}'\n", (dir / "fuel.asc").string()))),
                       doctest::Contains("the fuel code 7 of the cell at row 4, column 5"), InputError);
}

TEST_CASE("coordinate systems: the outputs carry the DEM's system without [model.arrival] like") {
  if (!config::have_gdal) return;
  bodyfit::test::TempDir dir("fire_crs_outputs");
  // bodyfit run on a DEM with a .prj: arrival_time.tif, rate_of_spread.tif and perimeters.gpkg in its system.
  HeightGrid dem;
  dem.cols = dem.rows = 41, dem.x_origin = 300000, dem.y_origin = 5500000, dem.cell_size = 25;
  dem.heights.assign(dem.cols * dem.rows, 100.0);
  dem.crs = kUtm32;
  write_raster(dir / "dem.asc", dem);
  write_text(dir / "case.toml", R"([surface]
generator = "terrain"
dem = "dem.asc"
h = 25.0
[region]
shape = "disks"
centers = [[300500.0, 5500500.0]]
radii = [100.0]
[model]
name = "fire"
[time]
dt = 30.0
iterations = 3
[output]
vtu_every = 0
png_every = 0
)");
  const auto result = bodyfit::test::run_bodyfit(fmt::format("run '{}' -o '{}'", (dir / "case.toml").string(), (dir / "out").string()));
  INFO(result.output);
  REQUIRE(result.exit_code == 0);
  for (const char* raster : {"arrival_time.tif", "rate_of_spread.tif"}) {
    const HeightGrid written = read_raster_values(dir / "out" / raster);
    INFO(raster);
    CHECK(same_crs(written.crs, kUtm32));
  }
  const VectorLayer perimeters = read_vector_layer(dir / "out" / "perimeters.gpkg");
  CHECK(same_crs(perimeters.crs, kUtm32));
  CHECK(!perimeters.features.empty());
}

TEST_CASE("coordinate systems: with the DEM reprojected to UTM, a fuel map in degrees is warped onto the surface") {
  if (!config::have_gdal) return;
  bodyfit::test::TempDir dir("fire_crs_warp");
  // The surface: UTM zone 32N metres round (6.03° E, 50.0° N). The fuel map: WGS 84 degrees, cells
  // of 0.001°, code 1 (burnable) with a block of code 2 (non-burnable) over [6.02, 6.04]° E × [49.995, 50.005]° N.
  HeightGrid fuel;
  fuel.cols = 100, fuel.rows = 60, fuel.x_origin = 5.98, fuel.y_origin = 49.97, fuel.cell_size = 0.001;
  const double block_west = 6.02, block_east = 6.04, block_south = 49.995, block_north = 50.005;
  for (std::size_t r = 0; r < fuel.rows; ++r)
    for (std::size_t c = 0; c < fuel.cols; ++c) {
      const double lon = fuel.x_origin + (double(c) + 0.5) * fuel.cell_size;
      const double lat = fuel.y_origin + (double(fuel.rows - 1 - r) + 0.5) * fuel.cell_size;
      fuel.heights.push_back(lon > block_west && lon < block_east && lat > block_south && lat < block_north ? 2.0 : 1.0);
    }
  fuel.crs = kWgs84;
  write_raster(dir / "fuel.asc", fuel);
  // The surface's system as the case's warp makes it (EPSG:32632's WKT).
  HeightGrid dem = fuel;
  dem.heights.assign(dem.heights.size(), 200.0);
  write_raster(dir / "dem.asc", dem);
  const DemCoordinates coordinates = dem_coordinates(dir / "dem.asc", {.reproject = Reprojection::utm});
  REQUIRE(geographic_crs(coordinates.reprojected_from));
  REQUIRE(crs_label(coordinates.crs).find("EPSG:32632") == 0);
  const SurfaceSource surface{.file = dir / "dem.asc", .crs = coordinates.crs, .reprojected_from = coordinates.reprojected_from};

  // A flat mesh in UTM metres over the block's surroundings; no wind: R = R0 on fuel 1, 0 on fuel 2.
  std::vector<PlanPoint> centre = {{6.03, 50.0}};
  transform_points(kWgs84, coordinates.crs, centre, "centre");
  const SurfaceMesh mesh = flat_ground(3000, 50, centre[0][0] - 1500, centre[0][1] - 1500);
  LoadedModel model = fire_model();
  configure_model(model, toml::parse(fmt::format("[fuel]\nmap = '{}'\npresets = ['balbi2009']\nnon_burnable = [2]\n",
                                                 (dir / "fuel.asc").string())),
                  surface);
  ScalarField distance(mesh.n_vertices(), 1.0);
  StandaloneStep where;
  where.height_field = true;
  const StepContext context = StepContext::standalone(mesh, distance, where);
  const VelocityField field = model->compute(context);
  // Where each vertex lies in degrees (GDAL's transformation), against the speed the warped map gave it.
  std::vector<PlanPoint> lonlat;
  for (auto v : mesh.vertices()) lonlat.push_back({mesh.point(v)[0], mesh.point(v)[1]});
  transform_points(coordinates.crs, kWgs84, lonlat, "mesh");
  const double R0 = fire::BalbiParameters{}.R0;
  const double margin = 2 * fuel.cell_size;  // nearest resampling onto UTM cells of about a source cell
  std::size_t inside = 0, outside = 0, wrong = 0;
  for (std::size_t i = 0; i < lonlat.size(); ++i) {
    const double lon = lonlat[i][0], lat = lonlat[i][1];
    const bool in_block = lon > block_west + margin && lon < block_east - margin && lat > block_south + margin &&
                          lat < block_north - margin;
    const bool out_block = lon < block_west - margin || lon > block_east + margin || lat < block_south - margin ||
                           lat > block_north + margin;
    if (in_block) ++inside, wrong += field.normal_speed[i] != 0;
    if (out_block) ++outside, wrong += std::abs(field.normal_speed[i] - R0) > 1e-12;
  }
  CHECK(inside > 100);
  CHECK(outside > 1000);
  CHECK(wrong == 0);

  // A barrier layer in degrees (GeoJSON without a crs member: WGS 84, RFC 7946) is transformed to
  // the surface's UTM: a polygon over the block stops the fire exactly where its transformed corners
  // say, within the band of 2 × the longest edge.
  write_text(dir / "block.geojson",
             geojson({fmt::format(R"({{"type":"Polygon","coordinates":[[[{0},{2}],[{1},{2}],[{1},{3}],[{0},{3}],[{0},{2}]]]}})",
                                  block_west, block_east, block_south, block_north)}));
  std::vector<PlanPoint> corners = {{block_west, block_south}, {block_east, block_south}, {block_east, block_north},
                                    {block_west, block_north}};
  transform_points(kWgs84, coordinates.crs, corners, "corners");
  const PlanPolygon block{{corners}};
  LoadedModel barred = fire_model();
  configure_model(barred, toml::parse(fmt::format("[barriers]\nfile = '{}'\n", (dir / "block.geojson").string())), surface);
  const VelocityField barred_field = barred->compute(context);
  const double reach = 2 * fire::longest_plan_edge(mesh);
  std::size_t stopped = 0, mismatched = 0;
  for (auto v : mesh.vertices()) {
    const bool expected = signed_distance_to_polygon(block, mesh.point(v)[0], mesh.point(v)[1]) <= reach;
    stopped += expected;
    mismatched += expected ? barred_field.normal_speed[v.idx()] != 0 : barred_field.normal_speed[v.idx()] != R0;
  }
  CHECK(stopped > 300);
  CHECK(mismatched == 0);
}
