// Vector layers: a mesh region's outline in plan view (parts, holes, parts touching at a point)
// written as GeoPackage and GeoJSON and read back through OGR (the GDAL module): CRS, validity,
// feature count, areas against the mesh's; features of every kind read from a GeoJSON file.
#include <bodyfit/app/config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/app/plan_geometry.hpp>
#include <bodyfit/app/vector_io.hpp>

#include "gis_module.hpp"
#include "test_support.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <thread>
#include <variant>

using namespace bodyfit;

namespace {

// A 10 × 10 grid over [0, 10]² on a bumpy height field, with G made of: a 4 × 4 block of cells
// (x, y in [1, 5]) with a one-cell hole at [2, 3]², the cell [5, 6]² touching the block at the
// point (5, 5) only, and a 3 × 2 block [6, 9] × [6, 8] touching that cell at (6, 6) only.
// Planar areas: 15, 1 and 6.
SurfaceMesh three_parts() {
  SurfaceMesh mesh = test::grid_square(10, {.x0 = 0, .y0 = 0, .x1 = 10, .y1 = 10});
  for (auto v : mesh.vertices()) {
    Vec3& p = mesh.point(v);
    p[2] = 0.3 * p[0] + 0.1 * p[1] * p[1];
  }
  for (auto f : mesh.faces()) {
    Vec3 c(0, 0, 0);
    for (auto v : mesh.fv_range(f)) c += mesh.point(v);
    c /= 3;
    const int i = int(std::floor(c[0])), j = int(std::floor(c[1]));
    const bool block = i >= 1 && i <= 4 && j >= 1 && j <= 4 && !(i == 2 && j == 2);
    const bool cell = i == 5 && j == 5;
    const bool second = i >= 6 && i <= 8 && j >= 6 && j <= 7;
    mesh.region(f) = block || cell || second ? kInside : kOutside;
  }
  return mesh;
}

const std::string kUtm32 = "EPSG:32632";

double layer_feature_area(const VectorFeature& f) {
  double area = 0;
  for (const auto& p : f.geometry.polygons) area += polygon_area(p);
  return area;
}

}  // namespace

TEST_CASE("region_outline: parts, a hole, parts touching at a point, outer CCW, holes CW, areas exact") {
  const SurfaceMesh mesh = three_parts();
  std::vector<PlanPolygon> polygons = region_outline(mesh);
  REQUIRE(polygons.size() == 3);
  std::sort(polygons.begin(), polygons.end(),
            [](const PlanPolygon& a, const PlanPolygon& b) { return polygon_area(a) < polygon_area(b); });
  CHECK(polygon_area(polygons[0]) == doctest::Approx(1).epsilon(1e-12));
  CHECK(polygon_area(polygons[1]) == doctest::Approx(6).epsilon(1e-12));
  CHECK(polygon_area(polygons[2]) == doctest::Approx(15).epsilon(1e-12));
  CHECK(polygons[0].rings.size() == 1);
  CHECK(polygons[1].rings.size() == 1);
  REQUIRE(polygons[2].rings.size() == 2);
  for (const auto& p : polygons) {
    CHECK(signed_ring_area(p.rings[0]) > 0);
    for (std::size_t k = 1; k < p.rings.size(); ++k) CHECK(signed_ring_area(p.rings[k]) < 0);
  }
  CHECK(std::abs(signed_ring_area(polygons[2].rings[1])) == doctest::Approx(1));
  // Perimeters: 4 for the cell, 10 for the 3 × 2 block, 16 + 4 for the block with its hole.
  CHECK(polygon_perimeter(polygons[0]) == doctest::Approx(4));
  CHECK(polygon_perimeter(polygons[1]) == doctest::Approx(10));
  CHECK(polygon_perimeter(polygons[2]) == doctest::Approx(20));
  CHECK(region_plan_area(mesh) == doctest::Approx(22).epsilon(1e-12));
}

TEST_CASE("cells_inside: the cells whose centre is in the outline, holes out, as the point test decides") {
  const std::vector<PlanPolygon> polygons = region_outline(three_parts());
  // Cells of 0.25 over [-0.5, 10.5]²: each of the 22 unit squares holds exactly 16 centres.
  const std::size_t n = 44;
  const double cell = 0.25, x0 = -0.5, y0 = -0.5;
  const std::vector<bool> inside = cells_inside(polygons, n, n, x0, y0, cell);
  REQUIRE(inside.size() == n * n);
  std::size_t count = 0;
  for (std::size_t row = 0; row < n; ++row)
    for (std::size_t col = 0; col < n; ++col) {
      const double x = x0 + (double(col) + 0.5) * cell, y = y0 + (double(n - row) - 0.5) * cell;
      bool expected = false;
      for (const PlanPolygon& p : polygons) expected = expected || signed_distance_to_polygon(p, x, y) < 0;
      INFO("cell (" << row << ", " << col << ") at (" << x << ", " << y << ")");
      CHECK(inside[row * n + col] == expected);
      count += inside[row * n + col];
    }
  CHECK(count == 22 * 16);  // the planar area 22, in cells of 1/16
  // A grid beside the polygons (nothing inside), and one within the 3 × 2 block (everything).
  const std::vector<bool> shifted = cells_inside(polygons, 4, 4, 9.5, 6.5, 1);  // centres x 10..13, y 7..10
  CHECK(std::count(shifted.begin(), shifted.end(), true) == 0);
  const std::vector<bool> corner = cells_inside(polygons, 2, 2, 7, 6, 1);  // centres (7.5|8.5, 6.5|7.5)
  CHECK(std::count(corner.begin(), corner.end(), true) == 4);
}

TEST_CASE("write_polygon_layer: a GeoPackage and a GeoJSON read back by OGR with CRS, valid geometries and areas") {
  if constexpr (!config::have_gdal) return;
  const SurfaceMesh mesh = three_parts();
  const double mesh_area = region_plan_area(mesh);
  VectorLayer layer{.name = "perimeters", .crs = kUtm32};
  // Three "output times": the whole region, then each part alone (as a region of the mesh).
  for (int k = 0; k < 3; ++k) {
    VectorFeature f;
    f.geometry.polygons = region_outline(mesh);
    if (k > 0) f.geometry.polygons.resize(std::size_t(k));
    f.attributes = {{"iteration", std::int64_t(k)}, {"time", 60.0 * k}, {"datetime", std::string("2026-07-14T13:00:00Z")}};
    layer.features.push_back(std::move(f));
  }
  for (const char* name : {"perimeters.gpkg", "perimeters.geojson"}) {
    CAPTURE(name);
    test::TempDir dir("vector_io_write");
    const auto file = dir / name;
    write_polygon_layer(file, layer);
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path())) ++files;
    CHECK(files == 1);  // no temporary, no journal left
    const VectorLayer back = read_vector_layer(file);
    REQUIRE(back.features.size() == 3);
    const gis::Api& gis = gis::module_for(file);
    CHECK(gis.same_crs(back.crs, kUtm32));
    for (std::size_t k = 0; k < 3; ++k) {
      const VectorFeature& f = back.features[k];
      CHECK(f.valid);
      CHECK(f.geometry.points.empty());
      CHECK(f.geometry.lines.empty());
      CHECK(f.geometry.polygons.size() == layer.features[k].geometry.polygons.size());
      CHECK(std::get<std::int64_t>(f.attribute("iteration")) == std::int64_t(k));
      CHECK(std::get<double>(f.attribute("time")) == 60.0 * double(k));
      CHECK(std::get<std::string>(f.attribute("datetime")) == "2026-07-14T13:00:00Z");
      CHECK(std::abs(layer_feature_area(f) - layer_feature_area(layer.features[k])) <= 1e-9 * mesh_area);
    }
    CHECK(std::abs(layer_feature_area(back.features[0]) - mesh_area) <= 1e-9 * mesh_area);
  }
}

TEST_CASE("write_polygon_layer: the same layer written a second later gives the same bytes (GeoPackage stamp)") {
  if constexpr (!config::have_gdal) return;
  VectorLayer layer{.name = "perimeters", .crs = kUtm32};
  VectorFeature f;
  f.geometry.polygons = region_outline(three_parts());
  f.attributes = {{"iteration", std::int64_t(1)}, {"time", 60.0}};
  layer.features.push_back(std::move(f));
  test::TempDir dir("vector_io_stamp");
  for (const char* extension : {".gpkg", ".geojson"}) {
    CAPTURE(extension);
    const auto first = dir / (std::string("first") + extension), second = dir / (std::string("second") + extension);
    write_polygon_layer(first, layer);
    std::this_thread::sleep_for(std::chrono::milliseconds(1100));
    write_polygon_layer(second, layer);
    const std::string bytes = test::read_file(first);
    CHECK(bytes.size() > 0);
    CHECK(bytes == test::read_file(second));
  }
  // The stamp a GeoPackage carries (gpkg_contents.last_change): the epoch, or the layer's timestamp.
  CHECK(test::read_file(dir / "first.gpkg").find("1970-01-01T00:00:00.000Z") != std::string::npos);
  layer.timestamp = 1784034000.0;  // 2026-07-14T13:00:00Z
  write_polygon_layer(dir / "stamped.gpkg", layer);
  const std::string stamped = test::read_file(dir / "stamped.gpkg");
  CHECK(stamped.find("2026-07-14T13:00:00.000Z") != std::string::npos);
  CHECK(stamped.find("1970-01-01T00:00:00.000Z") == std::string::npos);
}

TEST_CASE("read_vector_layer: points, lines, polygons with holes and multi-parts from GeoJSON, errors name the file") {
  if constexpr (!config::have_gdal) return;
  test::TempDir dir("vector_io_read");
  const auto file = dir / "ignitions.geojson";
  std::ofstream(file) << R"({"type": "FeatureCollection",
 "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::32632"}},
 "features": [
  {"type": "Feature", "properties": {"time": 0}, "geometry": {"type": "Point", "coordinates": [100, 200]}},
  {"type": "Feature", "properties": {"time": 600.5}, "geometry": {"type": "LineString", "coordinates": [[0, 0], [30, 40], [30, 90]]}},
  {"type": "Feature", "properties": {"time": "2026-07-14T14:00:00Z"}, "geometry": {"type": "Polygon", "coordinates":
     [[[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]], [[2, 2], [2, 4], [4, 4], [4, 2], [2, 2]]]}},
  {"type": "Feature", "properties": {"time": null}, "geometry": {"type": "MultiPoint", "coordinates": [[1, 2], [3, 4]]}}
 ]})";
  const VectorLayer layer = read_vector_layer(file);
  REQUIRE(layer.features.size() == 4);
  CHECK(gis::module_for(file).same_crs(layer.crs, kUtm32));
  CHECK(layer.features[0].geometry.points == std::vector<PlanPoint>{{100, 200}});
  CHECK(layer.features[1].geometry.lines.size() == 1);
  CHECK(path_length(layer.features[1].geometry.lines[0], false) == doctest::Approx(100));
  REQUIRE(layer.features[2].geometry.polygons.size() == 1);
  CHECK(layer.features[2].geometry.polygons[0].rings.size() == 2);
  CHECK(layer.features[2].geometry.polygons[0].rings[0].size() == 4);  // not closed
  CHECK(polygon_area(layer.features[2].geometry.polygons[0]) == doctest::Approx(96));
  CHECK(layer.features[3].geometry.points.size() == 2);
  CHECK(std::holds_alternative<std::monostate>(layer.features[3].attribute("time")));
  CHECK(std::holds_alternative<std::monostate>(layer.features[0].attribute("no such attribute")));
  CHECK_THROWS_AS(read_vector_layer(dir / "missing.geojson"), InputError);
  std::ofstream(dir / "bad.geojson") << "{ not json";
  CHECK_THROWS_AS(read_vector_layer(dir / "bad.geojson"), InputError);
  CHECK_THROWS_AS(write_polygon_layer(dir / "out.kml", VectorLayer{}), InputError);
}
