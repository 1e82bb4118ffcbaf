// Generators: geodesic spheres (counts, quality, radius, topology), flat squares (counts, flatness,
// boundary, quality), procedural terrains (boundary, topology, heights, reproducibility, edge
// lengths), DEM rasters (.asc, GeoTIFF).
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/app/config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>
#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>

using namespace bodyfit;

namespace {

void check_sphere(std::size_t n, double radius) {
  CAPTURE(n);
  auto mesh = make_sphere({.faces = n, .radius = radius, .center = {1, -2, 3}});
  const double count = double(mesh.n_faces());
  CHECK(std::abs(count - double(n)) <= 0.1 * double(n));
  CHECK(quality_stats(mesh).min >= 0.7);
  double worst = 0;
  for (auto v : mesh.vertices()) worst = std::max(worst, std::abs((mesh.point(v) - Vec3(1, -2, 3)).norm() - radius));
  CHECK(worst <= 1e-12 * radius);
  CHECK(euler_characteristic(mesh) == 2);
  CHECK(connected_components(mesh) == 1);
  CHECK(boundary_loops(mesh).empty());
  // Outward orientation: every face normal points away from the centre.
  int inward = 0;
  for (auto f : mesh.faces()) {
    auto p = face_points(mesh, f);
    if (OpenMesh::dot(face_normal(mesh, f), (p[0] + p[1] + p[2]) / 3 - Vec3(1, -2, 3)) <= 0) ++inward;
  }
  CHECK(inward == 0);
}

}  // namespace

TEST_CASE("sphere: every face count from 20 to 330 within 10 %, quality >= 0.7, on the sphere") {
  // Below ~300 some counts have no geodesic sphere within 10 % (e.g. 40, 290): all are checked.
  for (std::size_t n = 20; n <= 330; ++n) check_sphere(n, 2.5);
  for (std::size_t n = 331; n <= 1500; n += 13) check_sphere(n, 0.5);
}

TEST_CASE("sphere: larger counts up to 100k") {
  for (std::size_t n : {450, 600, 777, 1000, 1500, 2000, 3001, 5000, 7777, 12000, 20000, 33333, 50000, 100000})
    check_sphere(n, 1.0);
}

TEST_CASE("sphere: benchmark sizes are exactly the class-I spheres") {
  for (int k : {11, 22, 44, 88}) {
    std::size_t n = 20u * std::size_t(k) * std::size_t(k);
    auto mesh = make_sphere({.faces = n});
    CHECK(mesh.n_faces() == n);
    CHECK(mesh.n_vertices() == 10u * std::size_t(k) * std::size_t(k) + 2u);
    // Class I: exactly 12 vertices of valence 5, the others 6.
    int five = 0, six = 0;
    for (auto v : mesh.vertices()) {
      auto val = mesh.valence(v);
      five += val == 5;
      six += val == 6;
    }
    CHECK(five == 12);
    CHECK(six == int(mesh.n_vertices()) - 12);
  }
}

TEST_CASE("sphere: the area converges to 4 pi r^2 from below") {
  auto mesh = make_sphere({.faces = 20000, .radius = 3.0});
  const double exact = 4 * M_PI * 9.0;
  CHECK(total_area(mesh) < exact);
  CHECK(total_area(mesh) > 0.998 * exact);
}

TEST_CASE("sphere: bad options are input errors") {
  CHECK_THROWS_AS(make_sphere({.faces = 19}), InputError);
  CHECK_THROWS_AS(make_sphere({.faces = 100, .radius = 0}), InputError);
}

// ---- planes --------------------------------------------------------------------------------------

TEST_CASE("plane: a flat square of near-equilateral rows, one boundary loop on the square's sides") {
  auto mesh = make_plane({.size = 2.0, .h = 0.1});
  // 23 rows of triangles of height ≈ h·√3/2, each 2·20 triangles; 24 rows of 21 vertices.
  CHECK(mesh.n_faces() == 23u * 40u);
  CHECK(mesh.n_vertices() == 24u * 21u);
  CHECK(euler_characteristic(mesh) == 1);
  CHECK(connected_components(mesh) == 1);
  for (auto v : mesh.vertices()) CHECK(mesh.point(v)[2] == 0);
  for (auto f : mesh.faces()) {
    CHECK(face_normal(mesh, f)[2] == doctest::Approx(1.0));  // flat, oriented up
    CHECK(mesh.region(f) == kOutside);
  }
  CHECK(total_area(mesh) == doctest::Approx(4.0).epsilon(1e-12));
  auto loops = boundary_loops(mesh);
  REQUIRE(loops.size() == 1);
  double length = 0;
  for (std::size_t i = 0; i < loops[0].size(); ++i) {
    const Vec3 a = mesh.point(loops[0][i]), b = mesh.point(loops[0][(i + 1) % loops[0].size()]);
    CHECK((std::abs(a[0]) == 1.0 || std::abs(a[1]) == 1.0));
    CHECK((a[0] == b[0] || a[1] == b[1]));  // along one side
    length += (b - a).norm();
  }
  CHECK(length == doctest::Approx(8.0).epsilon(1e-12));
  // The half cells at the row ends are the worst triangles.
  CHECK(quality_stats(mesh).min > 0.5);
  CHECK(quality_stats(mesh).mean > 0.9);
  CHECK(edge_length_stats(mesh).mean == doctest::Approx(0.1).epsilon(0.1));
}

TEST_CASE("plane: bad options are input errors") {
  CHECK_THROWS_AS(make_plane({.size = 0}), InputError);
  CHECK_THROWS_AS(make_plane({.size = 2, .h = -0.1}), InputError);
  CHECK_THROWS_AS(make_plane({.size = 2, .h = std::nan("")}), InputError);
  CHECK_THROWS_AS(make_plane({.size = 1e6, .h = 1e-3}), InputError);  // 10^18 vertices
}

// ---- terrains ------------------------------------------------------------------------------------

namespace {

TerrainOptions small_terrain(std::uint64_t seed = 7) {
  return {.extent = 20000, .h = 500, .seed = seed, .max_height = 2500, .feature_size = 8000};
}

double plan_quality(const SurfaceMesh& mesh, FaceHandle f) {
  auto p = face_points(mesh, f);
  for (auto& x : p) x[2] = 0;
  return triangle_quality(p[0], p[1], p[2]);
}

bool on_square_side(const Vec3& p, double extent) {
  return p[0] == 0 || p[0] == extent || p[1] == 0 || p[1] == extent;
}

}  // namespace

TEST_CASE("terrain: an open disc over the square, straight sides, corners at the domain corners") {
  const auto options = small_terrain();
  auto mesh = make_terrain(options);
  CHECK(euler_characteristic(mesh) == 1);
  CHECK(connected_components(mesh) == 1);
  auto loops = boundary_loops(mesh);
  REQUIRE(loops.size() == 1);
  double plan_length = 0;
  for (std::size_t i = 0; i < loops[0].size(); ++i) {
    Vec3 a = mesh.point(loops[0][i]), b = mesh.point(loops[0][(i + 1) % loops[0].size()]);
    CHECK(on_square_side(a, options.extent));
    // Each boundary edge lies along one side: x or y constant.
    CHECK((a[0] == b[0] || a[1] == b[1]));
    a[2] = b[2] = 0;
    plan_length += (b - a).norm();
  }
  CHECK(plan_length == doctest::Approx(4 * options.extent).epsilon(1e-12));
  std::vector<Vec3> corners;
  for (auto v : mesh.vertices())
    if (mesh.corner(v)) corners.push_back(mesh.point(v));
  REQUIRE(corners.size() == 4);
  for (auto [x, y] : {std::pair{0.0, 0.0}, {options.extent, 0.0}, {0.0, options.extent}, {options.extent, options.extent}}) {
    int found = 0;
    for (const auto& c : corners) found += c[0] == x && c[1] == y;
    CHECK(found == 1);
  }
}

TEST_CASE("terrain: heights are the height function, within [0, max], and vary") {
  const auto options = small_terrain();
  auto mesh = make_terrain(options);
  double lo = 1e300, hi = -1e300;
  for (auto v : mesh.vertices()) {
    const auto p = mesh.point(v);
    CHECK(p[2] == terrain_height(options, p[0], p[1]));
    CHECK(p[2] >= 0);
    CHECK(p[2] <= options.max_height);
    lo = std::min(lo, p[2]), hi = std::max(hi, p[2]);
  }
  // A landscape, not a plateau: hundreds of metres of relief over 20 km.
  CHECK(hi - lo > 0.2 * options.max_height);
  // Smooth: the height function is continuous (tiny steps give tiny changes).
  for (double x : {1234.5, 7777.7, 15000.1}) {
    double z = terrain_height(options, x, 4321.0);
    CHECK(std::abs(terrain_height(options, x + 1e-3, 4321.0) - z) < 1e-2);
  }
}

TEST_CASE("terrain: near-equilateral in plan view, edges about h, normals up") {
  const auto options = small_terrain();
  auto mesh = make_terrain(options);
  double min_q = 1;
  for (auto f : mesh.faces()) {
    min_q = std::min(min_q, plan_quality(mesh, f));
    CHECK(face_normal(mesh, f)[2] > 0);
  }
  CHECK(min_q >= 0.74);
  std::size_t in_range = 0;
  for (auto e : mesh.edges()) {
    double l = edge_length(mesh, e);
    in_range += l >= 0.7 * options.h && l <= 1.4 * options.h;
  }
  CHECK(double(in_range) >= 0.95 * double(mesh.n_edges()));
  // About (extent / h)² · 2/√3 · 2 faces.
  const double expected = 2 * (options.extent / options.h) * (options.extent / (options.h * std::sqrt(3.0) / 2));
  CHECK(std::abs(double(mesh.n_faces()) - expected) < 0.05 * expected);
}

TEST_CASE("terrain: reproducible for a seed, different for another") {
  auto a = make_terrain(small_terrain(7)), b = make_terrain(small_terrain(7)), c = make_terrain(small_terrain(8));
  REQUIRE(a.n_vertices() == b.n_vertices());
  REQUIRE(a.n_vertices() == c.n_vertices());
  bool same = true;
  std::size_t differ = 0;
  for (auto v : a.vertices()) {
    same = same && a.point(v) == b.point(v);
    differ += std::abs(a.point(v)[2] - c.point(v)[2]) > 1.0;
  }
  CHECK(same);
  CHECK(differ > a.n_vertices() / 2);
  for (auto f : a.faces()) CHECK(face_vertices(a, f) == face_vertices(b, f));
}

TEST_CASE("terrain: bad options are input errors") {
  auto o = small_terrain();
  o.h = 0;
  CHECK_THROWS_AS(make_terrain(o), InputError);
  o = small_terrain();
  o.extent = -1;
  CHECK_THROWS_AS(make_terrain(o), InputError);
  o = small_terrain();
  o.h = 0.01;  // 4·10¹² triangles
  CHECK_THROWS_AS(make_terrain(o), InputError);
}

// ---- DEM rasters ---------------------------------------------------------------------------------

namespace {

// Heights of the plane z = 100 + 0.5 x − 0.25 y at the cell centres.
HeightGrid plane_grid() {
  HeightGrid g;
  g.cols = 7, g.rows = 5, g.x_origin = 1000, g.y_origin = 2000, g.cell_size = 30;
  for (std::size_t r = 0; r < g.rows; ++r)
    for (std::size_t c = 0; c < g.cols; ++c) {
      double x = g.x_origin + (double(c) + 0.5) * g.cell_size;
      double y = g.y_origin + (double(g.rows - r) - 0.5) * g.cell_size;
      g.heights.push_back(100 + 0.5 * x - 0.25 * y);
    }
  return g;
}

double plane(double x, double y) { return 100 + 0.5 * x - 0.25 * y; }

void write_text(const std::filesystem::path& file, const std::string& text) {
  std::ofstream(file) << text;
}

std::string error_of(const std::filesystem::path& file) {
  try {
    read_esri_ascii(file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("dem: bilinear sampling is exact on a plane inside the cell centres, clamped outside") {
  const auto g = plane_grid();
  for (double x : {1015.0, 1030.0, 1047.3, 1100.0, 1195.0})
    for (double y : {2015.0, 2033.3, 2100.0, 2135.0}) CHECK(g.sample(x, y) == doctest::Approx(plane(x, y)).epsilon(1e-13));
  // Outside the centres the value is the nearest centre row/column's.
  CHECK(g.sample(1000.0, 2015.0) == doctest::Approx(plane(1015.0, 2015.0)));
  CHECK(g.sample(5000.0, 9000.0) == doctest::Approx(plane(1195.0, 2135.0)));
}

TEST_CASE("dem: ESRI ASCII round trip is exact") {
  bodyfit::test::TempDir dir("dem_roundtrip");
  auto g = plane_grid();
  g.heights[3] = 1.0 / 3.0;
  write_esri_ascii(dir / "g.asc", g);
  auto r = read_esri_ascii(dir / "g.asc");
  CHECK(r.cols == g.cols);
  CHECK(r.rows == g.rows);
  CHECK(r.x_origin == g.x_origin);
  CHECK(r.y_origin == g.y_origin);
  CHECK(r.cell_size == g.cell_size);
  CHECK(r.heights == g.heights);
  auto d = read_dem(dir / "g.asc");
  CHECK(d.heights == g.heights);
}

TEST_CASE("dem: header variants: centre registration, any case, optional NODATA") {
  bodyfit::test::TempDir dir("dem_header");
  write_text(dir / "c.asc", "NCOLS 2\nNROWS 2\nXLLCENTER 10\nYLLCENTER 20\nCELLSIZE 4\n1 2\n3 4\n");
  auto g = read_esri_ascii(dir / "c.asc");
  CHECK(g.x_origin == 8);
  CHECK(g.y_origin == 18);
  CHECK(g.at(0, 1) == 2);
  CHECK(g.at(1, 0) == 3);
  // South-west cell centre is (10, 20): value 3 (row 1 is the south row).
  CHECK(g.sample(10, 20) == 3);
}

TEST_CASE("dem: NODATA cells are read as they are, fill_nodata gives them the nearest valid height, all-NODATA is an error") {
  bodyfit::test::TempDir dir("dem_nodata");
  write_text(dir / "n.asc",
             "ncols 4\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9999\n"
             "5 5 -9999 7\n5 5 6 -9999\n-9999 -9999 -9999 8\n");
  auto g = read_esri_ascii(dir / "n.asc");
  CHECK(count_nodata(g) == 5);
  CHECK(!g.valid(0, 2));
  CHECK(g.valid(0, 3));
  CHECK(g.at(0, 2) == -9999);
  // Bilinear sampling over the valid cells only: between the centres of (1, 1) = 5 and (1, 2) = 6
  // with NODATA (2, 1), (2, 2) below, the weights of the valid row are renormalised.
  CHECK(g.sample(1.5 + 0.25, 1.0 + 0.25) == doctest::Approx(5.25).epsilon(1e-14));
  // Four NODATA cells around the point: no value.
  HeightGrid corner;
  corner.cols = corner.rows = 3;
  corner.heights.assign(9, corner.nodata);
  corner.heights[0] = 1;  // the north-west cell only
  CHECK(corner.sample(0.5, 2.5) == 1);
  CHECK(std::isnan(corner.sample(2.5, 0.5)));

  HeightGrid filled = g;
  CHECK(fill_nodata(filled) == 5);
  CHECK(count_nodata(filled) == 0);
  // Each filled cell takes the value of a valid cell among its direct neighbours.
  CHECK((filled.at(0, 2) == 5 || filled.at(0, 2) == 6 || filled.at(0, 2) == 7));
  // (1, 3) touches 7, 6 and 8; the breadth-first fill takes a direct neighbour's value.
  CHECK((filled.at(1, 3) == 7 || filled.at(1, 3) == 6 || filled.at(1, 3) == 8));
  CHECK((filled.at(2, 0) == 5));
  write_text(dir / "all.asc", "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -1\n-1 -1\n");
  CHECK(error_of(dir / "all.asc").find("NODATA") != std::string::npos);
}

TEST_CASE("dem: malformed ESRI ASCII grids name the file and the line") {
  bodyfit::test::TempDir dir("dem_bad");
  const std::string header = "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 10\n";
  struct Case {
    std::string name, text, line, what;
  };
  const Case cases[] = {
      {"missing_key", "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\n1 2 3\n4 5 6\n", ":5:", "cellsize"},
      {"missing_origin", "ncols 3\nnrows 2\nxllcorner 0\ncellsize 1\n1 2 3\n4 5 6\n", ":5:", "yllcorner"},
      {"too_few", header + "1 2 3\n4 5\n", ":7:", "truncated"},
      {"too_many", header + "1 2 3\n4 5 6\n7\n", ":8:", "too many"},
      {"not_a_number", header + "1 2 3\n4 x5 6\n", ":7:", "x5"},
      {"bad_header_value", "ncols 3\nnrows two\nxllcorner 0\nyllcorner 0\ncellsize 10\n1 2 3\n4 5 6\n", ":2:", "two"},
      {"unknown_key", "ncols 3\nnrows 2\nzllcorner 0\n", ":3:", "zllcorner"},
      {"fractional_count", "ncols 3.5\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 10\n1 2 3\n", ":1:", "ncols"},
      {"empty", "", ":1:", "ncols"},
  };
  for (const auto& c : cases) {
    CAPTURE(c.name);
    auto file = dir / (c.name + ".asc");
    write_text(file, c.text);
    std::string message = error_of(file);
    CAPTURE(message);
    CHECK(message.find(file.string() + c.line) == 0);
    CHECK(message.find(c.what) != std::string::npos);
  }
  CHECK_THROWS_AS(read_esri_ascii(dir / "does_not_exist.asc"), InputError);
  CHECK_THROWS_AS(read_dem(dir / "x.xyz"), InputError);
}

/// The ESRI WKT of WGS 84 / UTM zone `zone` north, as `gdalsrsinfo -o wkt_esri EPSG:326zz` writes it.

TEST_CASE("dem: coordinate systems — geographic ones refused with the UTM zone to use, a projected one kept and written") {
  bodyfit::test::TempDir dir("dem_crs");
  HeightGrid g = plane_grid();
  if (!config::have_gdal) {
    write_esri_ascii(dir / "g.asc", g);
    write_text(dir / "g.prj", test::utm_prj(32));
    CHECK_THROWS_WITH_AS(read_dem(dir / "g.asc"), doctest::Contains("without GDAL"), InputError);
    return;
  }
  // SRTM-style degrees over Luxembourg (6° E, 49.6° N): the error names zone 32N (EPSG:32632).
  HeightGrid degrees = g;
  degrees.x_origin = 6.0;
  degrees.y_origin = 49.6;
  degrees.cell_size = 0.003;
  write_esri_ascii(dir / "deg.asc", degrees);
  write_text(dir / "deg.prj",
             "GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\",6378137.0,298.257223563]],"
             "PRIMEM[\"Greenwich\",0.0],UNIT[\"Degree\",0.0174532925199433]]");
  CHECK_THROWS_WITH_AS(read_dem(dir / "deg.asc"), doctest::Contains("geographic"), InputError);
  CHECK_THROWS_WITH_AS(read_dem(dir / "deg.asc"), doctest::Contains("EPSG:32632"), InputError);
  // A projected system in US feet is refused too.
  write_esri_ascii(dir / "feet.asc", g);
  std::string feet = test::utm_prj(18);
  feet.replace(feet.find("UNIT[\"Meter\",1.0]"), std::string("UNIT[\"Meter\",1.0]").size(),
               "UNIT[\"Foot_US\",0.3048006096012192]");
  write_text(dir / "feet.prj", feet);
  CHECK_THROWS_WITH_AS(read_dem(dir / "feet.asc"), doctest::Contains("units of 0.3048"), InputError);

  // UTM: kept with the grid, written beside what is written, the same system when read back.
  write_esri_ascii(dir / "utm.asc", g);
  write_text(dir / "utm.prj", test::utm_prj(32));
  HeightGrid utm = read_dem(dir / "utm.asc");
  REQUIRE(!utm.crs.empty());
  write_esri_ascii(dir / "copy.asc", utm);
  REQUIRE(std::filesystem::exists(dir / "copy.prj"));
  HeightGrid copy = read_dem(dir / "copy.asc");
  CHECK(copy.crs == utm.crs);
  CHECK_NOTHROW(require_same_crs(utm, dir / "utm.asc", copy, dir / "copy.asc"));
  // Another zone is another system: an error naming both files; an unknown system matches any.
  write_esri_ascii(dir / "zone31.asc", g);
  write_text(dir / "zone31.prj", test::utm_prj(31));
  HeightGrid zone31 = read_dem(dir / "zone31.asc");
  CHECK_THROWS_WITH_AS(require_same_crs(utm, dir / "utm.asc", zone31, dir / "zone31.asc"),
                       doctest::Contains("zone31.asc"), InputError);
  CHECK_NOTHROW(require_same_crs(utm, dir / "utm.asc", g, dir / "none.asc"));
}

TEST_CASE("dem: a GeoTIFF made by gdal_translate reads as the .asc it came from") {
  bodyfit::test::TempDir dir("dem_tif");
  auto g = plane_grid();
  g.heights[0] = g.nodata;  // NODATA in both files
  g.heights[9] = 0.1;       // not a float: the .asc is read and the .tif written as Float64
  write_esri_ascii(dir / "g.asc", g);
  const auto tif = dir / "g.tif";
  if (!config::have_gdal) {
    write_text(tif, "not really a tiff");
    CHECK_THROWS_WITH_AS(read_geotiff(tif), doctest::Contains("without GDAL"), InputError);
    return;
  }
  if (std::system("command -v gdal_translate > /dev/null 2>&1") != 0) {
    MESSAGE("gdal_translate not found (Debian package gdal-bin): GeoTIFF comparison skipped");
    return;
  }
  const std::string command = "gdal_translate -q -oo DATATYPE=Float64 -of GTiff -ot Float64 '" + (dir / "g.asc").string() + "' '" +
                              tif.string() + "'";
  REQUIRE(std::system(command.c_str()) == 0);
  auto a = read_esri_ascii(dir / "g.asc");
  auto t = read_dem(tif);
  CHECK(t.cols == a.cols);
  CHECK(t.rows == a.rows);
  CHECK(t.x_origin == a.x_origin);
  CHECK(t.y_origin == a.y_origin);
  CHECK(t.cell_size == a.cell_size);
  CHECK(t.heights == a.heights);
  write_text(dir / "bad.tif", "not a tiff");
  CHECK_THROWS_AS(read_geotiff(dir / "bad.tif"), InputError);
}

TEST_CASE("dem: terrain over the raster's extent, heights bilinear") {
  const auto g = plane_grid();
  auto mesh = make_terrain_from_grid(g);
  CHECK(euler_characteristic(mesh) == 1);
  REQUIRE(boundary_loops(mesh).size() == 1);
  auto box = bounding_box(mesh);
  CHECK(box.min[0] == 1000);
  CHECK(box.max[0] == 1000 + 7 * 30);
  CHECK(box.min[1] == 2000);
  CHECK(box.max[1] == 2000 + 5 * 30);
  for (auto v : mesh.vertices()) {
    auto p = mesh.point(v);
    CHECK(p[2] == doctest::Approx(g.sample(p[0], p[1])).epsilon(1e-14));
    // Inside the band of cell centres the plane is reproduced exactly.
    if (p[0] >= 1015 && p[0] <= 1195 && p[1] >= 2015 && p[1] <= 2135)
      CHECK(p[2] == doctest::Approx(plane(p[0], p[1])).epsilon(1e-12));
  }
  // Default edge length: the cell size.
  CHECK(edge_length_stats(mesh).mean == doctest::Approx(30).epsilon(0.15));
  auto finer = make_terrain_from_grid(g, 10);
  CHECK(finer.n_faces() > 5 * mesh.n_faces());
}

namespace {

/// WGS 84 / UTM zone `zone` north coordinates of (lon, lat) in degrees: the Transverse Mercator
/// series of Snyder, "Map Projections — A Working Manual" (1987), eqs. 8-9 to 8-10 (sub-metre
/// within a zone).
std::pair<double, double> utm_north(int zone, double lon_degrees, double lat_degrees) {
  const double a = 6378137, f = 1 / 298.257223563, e2 = f * (2 - f), ep2 = e2 / (1 - e2), k0 = 0.9996;
  const double phi = lat_degrees * M_PI / 180, dlambda = (lon_degrees - (6 * zone - 183)) * M_PI / 180;
  const double n = a / std::sqrt(1 - e2 * std::sin(phi) * std::sin(phi));
  const double t = std::tan(phi) * std::tan(phi), c = ep2 * std::cos(phi) * std::cos(phi), A = dlambda * std::cos(phi);
  const double e4 = e2 * e2, e6 = e4 * e2;
  const double m = a * ((1 - e2 / 4 - 3 * e4 / 64 - 5 * e6 / 256) * phi -
                        (3 * e2 / 8 + 3 * e4 / 32 + 45 * e6 / 1024) * std::sin(2 * phi) +
                        (15 * e4 / 256 + 45 * e6 / 1024) * std::sin(4 * phi) - (35 * e6 / 3072) * std::sin(6 * phi));
  const double x = k0 * n * (A + (1 - t + c) * std::pow(A, 3) / 6 +
                             (5 - 18 * t + t * t + 72 * c - 58 * ep2) * std::pow(A, 5) / 120);
  const double y = k0 * (m + n * std::tan(phi) *
                                 (A * A / 2 + (5 - t + 9 * c + 4 * c * c) * std::pow(A, 4) / 24 +
                                  (61 - 58 * t + t * t + 600 * c - 330 * ep2) * std::pow(A, 6) / 720));
  return {500000 + x, y};
}

}  // namespace

TEST_CASE("dem: a GeoTIFF in degrees is refused, or reprojected to its UTM zone on request") {
  bodyfit::test::TempDir dir("dem_reproject");
  // 30 × 20 cells of 0.01° from (6.0° E, 49.5° N), height 300, a 6 × 6 block of NODATA in the middle.
  HeightGrid g;
  g.cols = 30, g.rows = 20, g.x_origin = 6.0, g.y_origin = 49.5, g.cell_size = 0.01;
  for (std::size_t r = 0; r < g.rows; ++r)
    for (std::size_t c = 0; c < g.cols; ++c)
      g.heights.push_back(c >= 12 && c < 18 && r >= 7 && r < 13 ? g.nodata : 300.0);
  write_esri_ascii(dir / "deg.asc", g);
  if (!config::have_gdal) return;
  if (std::system("command -v gdal_translate > /dev/null 2>&1") != 0) {
    MESSAGE("gdal_translate not found (Debian package gdal-bin): reprojection test skipped");
    return;
  }
  const auto tif = dir / "deg.tif";
  const std::string command = "gdal_translate -q -a_srs EPSG:4326 -of GTiff -ot Float64 '" + (dir / "deg.asc").string() +
                              "' '" + tif.string() + "'";
  REQUIRE(std::system(command.c_str()) == 0);
  CHECK_THROWS_WITH_AS(read_dem(tif), doctest::Contains("geographic"), InputError);
  CHECK_THROWS_WITH_AS(read_dem(tif), doctest::Contains("reproject = \"utm\""), InputError);

  const HeightGrid utm = read_dem(tif, {.reproject = Reprojection::utm});
  CHECK(utm.crs.find("UTM zone 32N") != std::string::npos);
  CHECK(utm.crs.find("AUTHORITY[\"EPSG\",\"32632\"]") != std::string::npos);
  // Cells: GDAL's suggestion, between the source cell's east-west (0.01° ≈ 721 m at 49.6° N) and
  // north-south (≈ 1113 m) lengths, rounded to two significant figures.
  const double cell = utm.cell_size;
  CHECK(cell >= 700);
  CHECK(cell <= 1120);
  CHECK(std::fmod(cell, 10.0) == 0);
  // Extent: the source's outline projected (Snyder's series, independent of GDAL) fits in the
  // raster, which exceeds it by at most two cells on each side (GDAL's suggested extent ends on a
  // whole number of its cells; bodyfit snaps the corners outward to multiples of the cell).
  double west = 1e300, east = -1e300, south = 1e300, north = -1e300;
  for (int i = 0; i <= 100; ++i) {
    const double t = i / 100.0;
    for (auto [lon, lat] : {std::pair{6.0 + 0.3 * t, 49.5}, std::pair{6.0 + 0.3 * t, 49.7}, std::pair{6.0, 49.5 + 0.2 * t},
                            std::pair{6.3, 49.5 + 0.2 * t}}) {
      const auto [x, y] = utm_north(32, lon, lat);
      west = std::min(west, x), east = std::max(east, x), south = std::min(south, y), north = std::max(north, y);
    }
  }
  const double x0 = utm.x_origin, x1 = x0 + double(utm.cols) * cell;
  const double y0 = utm.y_origin, y1 = y0 + double(utm.rows) * cell;
  INFO("raster [" << x0 << ", " << x1 << "] × [" << y0 << ", " << y1 << "], outline [" << west << ", " << east
                  << "] × [" << south << ", " << north << "], cell " << cell);
  CHECK(x0 <= west + 1);
  CHECK(x1 >= east - 1);
  CHECK(y0 <= south + 1);
  CHECK(y1 >= north - 1);
  CHECK(x0 >= west - 2 * cell);
  CHECK(x1 <= east + 2 * cell);
  CHECK(y0 >= south - 2 * cell);
  CHECK(y1 <= north + 2 * cell);
  // Values: 300 wherever there is data (bilinear over valid cells of a constant); NODATA over the
  // block's centre (6.15° E, 49.6° N) and outside the source, data at a point far from both.
  std::size_t nodata = 0;
  for (std::size_t r = 0; r < utm.rows; ++r)
    for (std::size_t c = 0; c < utm.cols; ++c)
      if (utm.valid(r, c)) CHECK(utm.at(r, c) == doctest::Approx(300).epsilon(1e-12));
      else ++nodata;
  CHECK(nodata == count_nodata(utm));
  auto cell_at = [&](double lon, double lat) {
    const auto [x, y] = utm_north(32, lon, lat);
    const std::size_t col = std::size_t((x - x0) / cell), south_row = std::size_t((y - y0) / cell);
    return std::pair{utm.rows - 1 - south_row, col};
  };
  const std::pair<std::size_t, std::size_t> hole = cell_at(6.15, 49.6), data = cell_at(6.05, 49.65);
  CHECK(!utm.valid(hole.first, hole.second));
  CHECK(utm.valid(data.first, data.second));
  CHECK(!utm.valid(0, 0));  // the north-west corner: outside the (rotated) source

  // The .asc with a geographic .prj beside it takes the same path; and the command says what it did.
  write_text(dir / "deg.prj",
             "GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\",6378137.0,298.257223563]],"
             "PRIMEM[\"Greenwich\",0.0],UNIT[\"Degree\",0.0174532925199433]]");
  CHECK(read_dem(dir / "deg.asc", {.reproject = Reprojection::utm}).crs.find("UTM zone 32N") != std::string::npos);
  // A case's [surface] reproject = "utm" takes it too: a terrain in metres over zone 32N's raster.
  const std::string case_text = fmt::format(
      "[surface]\ngenerator = \"terrain\"\ndem = '{}'\nh = 1000.0\nreproject = \"utm\"\n"
      "[region]\nshape = \"disks\"\ncenters = [[290000.0, 5500000.0]]\nradii = [2000.0]\n"
      "[model]\nname = \"fire\"\n[time]\ndt = 60.0\niterations = 1\n",
      tif.string());
  const SurfaceMesh surface = make_case_surface(parse_case(toml::parse(case_text)));
  const BoundingBox box = bounding_box(surface);
  CHECK(box.min[0] >= x0);
  CHECK(box.max[0] <= x1);
  CHECK(box.min[1] >= y0);
  CHECK(box.max[1] <= y1);
  CHECK(boundary_loops(surface).size() == 2);  // the outline and the NODATA block's hole
  const auto refused = bodyfit::test::run_bodyfit("mesh terrain --dem '" + tif.string() + "' -o '" +
                                                  (dir / "t.mesh").string() + "'");
  CHECK(refused.exit_code == 1);
  const auto done = bodyfit::test::run_bodyfit("mesh terrain --dem '" + tif.string() + "' --reproject utm -o '" +
                                               (dir / "t.mesh").string() + "'");
  INFO(done.output);
  CHECK(done.exit_code == 0);
  CHECK(done.output.find(fmt::format("reprojected from WGS 84 to WGS 84 / UTM zone 32N, {} m cells", cell)) !=
        std::string::npos);
}
