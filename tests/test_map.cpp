// Fire maps (map.hpp, app/map/): the layout against exact values, the isochrones of exact fields,
// and the picture Cairo draws read back and checked at known world points through the layout's
// own world→pixel transform: the hillshade's grey, the burnt disk's edge, the isochrones' radii,
// the scale bar's length.
#include "test_support.hpp"

#include <bodyfit/app/config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/app/map.hpp>
#include <bodyfit/app/render.hpp>

#include <doctest/doctest.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>

using namespace bodyfit;
namespace fs = std::filesystem;

namespace {

constexpr double kCentre = 5000, kBurntRadius = 2000;
constexpr double kSpeed = 3000.0 / 3600;  // m/s: the front is 3 km out after 1 h

// A procedural terrain of 10 km (a few thousand faces) burnt in a disk around its centre.
SurfaceMesh burnt_terrain() {
  SurfaceMesh mesh = make_terrain({.extent = 10000, .h = 250, .seed = 3, .max_height = 800, .feature_size = 3000});
  for (auto f : mesh.faces()) {
    Vec3 c(0, 0, 0);
    for (auto v : mesh.fv_range(f)) c += mesh.point(v) / 3;
    mesh.region(f) = std::hypot(c[0] - kCentre, c[1] - kCentre) < kBurntRadius ? kInside : kOutside;
  }
  update_interface_from_regions(mesh);
  return mesh;
}

// t = r / kSpeed around the centre, on 50 m cells over the terrain.
HeightGrid radial_arrival() {
  HeightGrid grid;
  grid.cols = grid.rows = 200;
  grid.cell_size = 50;
  grid.heights.resize(grid.cols * grid.rows);
  for (std::size_t r = 0; r < grid.rows; ++r)
    for (std::size_t c = 0; c < grid.cols; ++c) {
      const double x = (double(c) + 0.5) * 50, y = (double(grid.rows - 1 - r) + 0.5) * 50;
      grid.heights[r * grid.cols + c] = std::hypot(x - kCentre, y - kCentre) / kSpeed;
    }
  return grid;
}

MapLayout layout_of(const SurfaceMesh& mesh, const MapOptions& options) {
  const BoundingBox box = bounding_box(mesh);
  return map_layout(box.min[0], box.min[1], box.max[0], box.max[1], options);
}

Rgb pixel_at(const Image& image, const MapLayout& layout, double x, double y) {
  const MapPixel p = layout.to_pixel(x, y);
  return image.at(int(std::floor(p.x)), int(std::floor(p.y)));
}

bool reddish(Rgb c) { return c[0] > c[1] + 40 && c[0] > c[2] + 40; }
bool close_to(Rgb a, Rgb b, int tolerance) {
  for (int i = 0; i < 3; ++i)
    if (std::abs(int(a[i]) - int(b[i])) > tolerance) return false;
  return true;
}

}  // namespace

TEST_CASE("map: nice steps, time labels, automatic isochrone levels") {
  CHECK(nice_step_below(1) == 1);
  CHECK(nice_step_below(1999) == 1000);
  CHECK(nice_step_below(2000) == 2000);
  CHECK(nice_step_below(4999) == 2000);
  CHECK(nice_step_below(5000) == 5000);
  CHECK(nice_step_below(0.03) == doctest::Approx(0.02));
  CHECK_THROWS_AS(nice_step_below(0), InputError);

  MapOptions options;
  CHECK(time_label(5400, 1800, options) == "1.5 h");
  CHECK(time_label(2400, 600, options) == "40 min");
  CHECK(time_label(1200, 1200, options) == "20 min");
  options.time_unit = TimeUnit::minutes;
  CHECK(time_label(5400, 1800, options) == "90 min");
  options.time_unit = TimeUnit::automatic;

  // Arrivals from 42 s to 8485 s: span / 7 = 1206 s, above 30 min once rounded up in minutes
  // (50), so half-hours: 0.5, 1, 1.5 and 2 h.
  const HeightGrid arrival = radial_arrival();
  CHECK(isochrone_interval(arrival, options) == 1800);
  CHECK(isochrone_levels(arrival, options) == std::vector<double>{1800, 3600, 5400, 7200});
  options.isochrone_interval = 3600;
  CHECK(isochrone_levels(arrival, options) == std::vector<double>{3600, 7200});
  // Never reached (NaN) everywhere: no lines.
  HeightGrid none = arrival;
  for (double& t : none.heights) t = std::nan("");
  CHECK(isochrone_levels(none, options).empty());
  CHECK(isochrone_interval(none, options) == 0);
}

TEST_CASE("map: isochrones of exact fields (marching squares)") {
  // t = x: the contour t = 130 is the vertical line x = 130, across the whole raster.
  HeightGrid linear;
  linear.cols = 10, linear.rows = 6, linear.cell_size = 20;
  linear.heights.resize(60);
  for (std::size_t r = 0; r < 6; ++r)
    for (std::size_t c = 0; c < 10; ++c) linear.heights[r * 10 + c] = (double(c) + 0.5) * 20;
  auto segments = isochrone_segments(linear, 130);
  CHECK(segments.size() == 5);  // one per row of squares
  for (const auto& s : segments)
    for (const Vec3& p : s) CHECK(p[0] == doctest::Approx(130));

  // A radial field: every point within the interpolation error cell²/R of the circle.
  const HeightGrid radial = radial_arrival();
  segments = isochrone_segments(radial, 3600);
  CHECK(segments.size() > 100);
  for (const auto& s : segments)
    for (const Vec3& p : s) {
      const double r = std::hypot(p[0] - kCentre, p[1] - kCentre);
      CHECK(std::abs(r - 3000) < 50.0 * 50.0 / 3000);
    }

  // A NaN cell (never reached) breaks the line: no segment in the four squares around it.
  linear.heights[2 * 10 + 6] = std::nan("");
  segments = isochrone_segments(linear, 130);
  CHECK(segments.size() == 3);
  for (const auto& s : segments) {
    const double y = 0.5 * (s[0][1] + s[1][1]);  // squares of rows 1-2 (y from 50 to 90) are gone
    CHECK((y > 90 || y < 50));
  }
}

TEST_CASE("map: ignitions from the arrival time: a disk burning at t = 0 and a later point, at their centres") {
  // Two fires on 50 m cells: a disk of 500 m around (3000, 3000) burning at t = 0, and a point
  // at (7025, 6025) (a cell centre) lit at t = 1800 s; each spreads at 1 m/s; a cell takes the
  // earlier front. The northern strip is NODATA (off the terrain) and holds no ignition.
  HeightGrid grid;
  grid.cols = grid.rows = 200;
  grid.cell_size = 50;
  grid.nodata = -9999;
  grid.heights.resize(grid.cols * grid.rows);
  for (std::size_t r = 0; r < grid.rows; ++r)
    for (std::size_t c = 0; c < grid.cols; ++c) {
      const double x = (double(c) + 0.5) * 50, y = (double(grid.rows - 1 - r) + 0.5) * 50;
      const double first = std::max(0.0, std::hypot(x - 3000, y - 3000) - 500);
      const double second = 1800 + std::hypot(x - 7025, y - 6025);
      grid.heights[r * grid.cols + c] = y > 9000 ? grid.nodata : std::min(first, second);
    }
  std::vector<Vec3> points = ignitions_from_arrival(grid);
  REQUIRE(points.size() == 2);
  std::sort(points.begin(), points.end(), [](const Vec3& a, const Vec3& b) { return a[0] < b[0]; });
  CHECK(points[0][0] == doctest::Approx(3000).epsilon(1e-9));  // the disk's cells are symmetric about its centre
  CHECK(points[0][1] == doctest::Approx(3000).epsilon(1e-9));
  CHECK(points[1][0] == doctest::Approx(7025));
  CHECK(points[1][1] == doctest::Approx(6025));
  // Nothing reached: no ignition.
  std::fill(grid.heights.begin(), grid.heights.end(), grid.nodata);
  CHECK(ignitions_from_arrival(grid).empty());
}

TEST_CASE("map: labels placed without overlap, inside the panel, the first free candidate of each line") {
  MapLayout layout;
  layout.panel_left = 0, layout.panel_top = 0, layout.panel_right = 100, layout.panel_bottom = 100;
  // Line 0 takes its first box; line 1's first overlaps it, its second is free; line 2's only box
  // leaves the panel; line 3's boxes all overlap the chosen ones.
  const std::vector<std::vector<LabelBox>> candidates = {
      {{10, 10, 30, 20}},
      {{20, 15, 40, 25}, {50, 10, 70, 20}},
      {{90, 10, 110, 20}},
      {{15, 12, 25, 18}, {55, 12, 65, 18}},
  };
  const std::vector<int> chosen = place_labels(candidates, layout);
  CHECK(chosen == std::vector<int>{0, 1, -1, -1});
  // Boxes that only touch do not overlap.
  CHECK(place_labels({{{0, 0, 10, 10}}, {{10, 0, 20, 10}}}, layout) == std::vector<int>{0, 0});
}

TEST_CASE("map: the caption's time from the case's start, and the map's own time") {
  MapLayers layers;
  CHECK(map_time_caption(layers).empty());
  layers.clock_start = 1784034000;  // 2026-07-14T13:00:00Z
  CHECK(map_time_caption(layers) == "fire start 2026-07-14T13:00:00Z");
  layers.burnt_at = 5400;
  CHECK(map_time_caption(layers) == "map at 2026-07-14T14:30:00Z, fire start 2026-07-14T13:00:00Z");
  layers.datetime = "given";
  CHECK(map_time_caption(layers) == "given");
}

TEST_CASE("map: the layout keeps the aspect ratio and maps the box onto the panel") {
  MapOptions options;
  const MapLayout layout = map_layout(1000, 2000, 5000, 4000, options);  // 4 km × 2 km
  const MapPixel sw = layout.to_pixel(1000, 2000), ne = layout.to_pixel(5000, 4000);
  CHECK(sw.x == doctest::Approx(layout.panel_left));
  CHECK(sw.y == doctest::Approx(layout.panel_bottom));
  CHECK(ne.x == doctest::Approx(layout.panel_right));
  CHECK(ne.y == doctest::Approx(layout.panel_top));
  CHECK((ne.x - sw.x) == doctest::Approx(2 * (sw.y - ne.y)));  // equal scales: north is up, undistorted
  CHECK(layout.panel_right <= layout.legend_left);
  CHECK(layout.panel_left >= 0);
  CHECK(layout.panel_bottom <= options.height);
  const ScaleBar bar = scale_bar(layout);
  CHECK(bar.metres == 1000);  // a quarter of 4 km, rounded down to 1-2-5
  CHECK(bar.label == "1 km");
  CHECK(bar.pixels == doctest::Approx(1000 / layout.metres_per_pixel));
  CHECK_THROWS_AS(map_layout(0, 0, 1, 1, {.width = 100, .height = 100}), InputError);
  CHECK_THROWS_AS(map_layout(0, 0, 0, 1, options), InputError);
  CHECK(crs_name_of_wkt("PROJCS[\"WGS 84 / UTM zone 32N\",GEOGCS[\"WGS 84\"]]") == "WGS 84 / UTM zone 32N");
  CHECK(crs_name_of_wkt("").empty());
}

TEST_CASE("map: without Cairo a clear error, with it the hillshade grey of a plane is Lambert") {
  test::TempDir dir("map_hillshade");
  SurfaceMesh plane = make_plane({.size = 1000, .h = 50});
  if constexpr (!config::have_cairo) {
    try {
      draw_fire_map(dir / "flat.png", plane, {}, {});
      FAIL("no error without Cairo");
    } catch (const InputError& e) {
      CHECK(std::string(e.what()).find("libcairo2-dev") != std::string::npos);
    }
    return;
  }
  // Flat: n = +z, grey = 60 + 195·sin(altitude).
  MapOptions options;
  draw_fire_map(dir / "flat.png", plane, {}, options);
  Image image = read_png(dir / "flat.png");
  CHECK(image.width == options.width);
  CHECK(image.height == options.height);
  const MapLayout flat_layout = layout_of(plane, options);
  const auto grey = std::uint8_t(std::lround(60 + 195 * std::sin(45 * M_PI / 180)));
  CHECK(pixel_at(image, flat_layout, 100, -100) == Rgb{grey, grey, grey});
  // Tilted 30° up towards the east (z = x·tan 30°): its normal leans west, so a western sun at
  // 45° lights it at cos(15°) of the zenith's, an eastern one at cos(75°).
  for (auto v : plane.vertices()) plane.point(v)[2] = plane.point(v)[0] * std::tan(30 * M_PI / 180);
  const MapLayout layout = layout_of(plane, options);
  for (double azimuth : {270.0, 90.0}) {
    options.sun_azimuth = azimuth;
    draw_fire_map(dir / "tilted.png", plane, {}, options);
    image = read_png(dir / "tilted.png");
    const double lit = azimuth == 270 ? std::cos(15 * M_PI / 180) : std::cos(75 * M_PI / 180);
    const auto expected = std::uint8_t(std::lround(60 + 195 * lit));
    CAPTURE(azimuth);
    CHECK(pixel_at(image, layout, 100, -100) == Rgb{expected, expected, expected});
  }
  // Heights doubled for the shade only (z_factor 2): the slope seen by the sun is atan(2 tan 30°).
  options.sun_azimuth = 270;
  options.z_factor = 2;
  draw_fire_map(dir / "tilted.png", plane, {}, options);
  image = read_png(dir / "tilted.png");
  const double steeper = std::atan(2 * std::tan(30 * M_PI / 180));
  const auto exaggerated = std::uint8_t(std::lround(60 + 195 * std::cos(45 * M_PI / 180 - steeper)));
  CHECK(pixel_at(image, layout, 100, -100) == Rgb{exaggerated, exaggerated, exaggerated});
  options.z_factor = 0;
  CHECK_THROWS_AS(draw_fire_map(dir / "bad.png", plane, {}, options), InputError);
  options.z_factor = 1;
  options.sun_altitude = 95;
  CHECK_THROWS_AS(draw_fire_map(dir / "bad.png", plane, {}, options), InputError);
  CHECK_FALSE(fs::exists(dir / "bad.png"));
}

TEST_CASE("map: a burnt disk, radial isochrones and the scale bar where the layout puts them") {
  if constexpr (!config::have_cairo) return;  // the error without Cairo: the test above
  test::TempDir dir("map_disk");
  const SurfaceMesh mesh = burnt_terrain();
  REQUIRE(mesh.n_faces() > 2000);
  MapLayers layers;
  layers.arrival = radial_arrival();
  layers.ignitions = {Vec3(kCentre, kCentre, 0)};
  layers.crs_name = "WGS 84 / UTM zone 32N";
  MapOptions options;
  draw_fire_map(dir / "map.png", mesh, layers, options);
  const Image image = read_png(dir / "map.png");
  REQUIRE(image.width == options.width);
  REQUIRE(image.height == options.height);
  const MapLayout layout = layout_of(mesh, options);

  // Inside the disk reddish, outside grey, in the directions free of labels (they sit north).
  for (double angle : {0.0, 180.0, 225.0, 270.0, 315.0}) {
    const double ux = std::cos(angle * M_PI / 180), uy = std::sin(angle * M_PI / 180);
    CAPTURE(angle);
    for (double r : {700.0, 1100.0, 1800.0}) {
      CAPTURE(r);
      CHECK(reddish(pixel_at(image, layout, kCentre + r * ux, kCentre + r * uy)));
    }
    for (double r : {2200.0, 2600.0, 3700.0}) {
      CAPTURE(r);
      const Rgb c = pixel_at(image, layout, kCentre + r * ux, kCentre + r * uy);
      CHECK(std::abs(int(c[0]) - int(c[1])) < 10);
      CHECK(std::abs(int(c[1]) - int(c[2])) < 10);
    }
  }
  // The isochrone t_k lies at radius kSpeed·t_k: along the ray to the south-east corner (the
  // last line, 6 km out, only crosses the corners), a pixel of its colour within 2 px of there,
  // and none halfway to the next line.
  const std::vector<double> levels = isochrone_levels(layers.arrival, options);
  REQUIRE(levels.size() == 4);
  const double ux = std::sqrt(0.5), uy = -std::sqrt(0.5);
  for (std::size_t k = 0; k < levels.size(); ++k) {
    const Rgb colour = isochrone_colour(k, levels.size());
    const double r = kSpeed * levels[k];
    const MapPixel expected = layout.to_pixel(kCentre + r * ux, kCentre + r * uy);
    int found = 0;
    for (int dy = -2; dy <= 2; ++dy)
      for (int dx = -2; dx <= 2; ++dx)
        if (dx * dx + dy * dy <= 4)
          found += close_to(image.at(int(std::floor(expected.x)) + dx, int(std::floor(expected.y)) + dy), colour, 8);
    CAPTURE(k);
    CHECK(found > 0);
    const double between = r + kSpeed * 900;
    CHECK_FALSE(close_to(pixel_at(image, layout, kCentre + between * ux, kCentre + between * uy), colour, 8));
  }
  // The scale bar: the dark run along its centre row is as long as its stated length at the scale.
  const ScaleBar bar = scale_bar(layout);
  CHECK(bar.metres == 2000);  // a quarter of 10 km, rounded down to 1-2-5
  const int bar_row = int(std::floor(bar.left.y));
  int first = -1, last = -1;
  for (int x = int(bar.left.x) - 6; x < int(bar.left.x + bar.pixels) + 6; ++x) {
    const Rgb c = image.at(x, bar_row);
    if (c[0] < 100 && c[1] < 100 && c[2] < 100) {
      if (first < 0) first = x;
      last = x;
    }
  }
  REQUIRE(first >= 0);
  CHECK(std::abs(double(last - first + 1) - bar.metres / layout.metres_per_pixel) <= 1.0);
  // The ignition star at the centre, in its colour.
  const MapPixel centre = layout.to_pixel(kCentre, kCentre);
  CHECK(close_to(image.at(int(std::floor(centre.x)), int(std::floor(centre.y)) + 2), options.ignition_color, 8));
}

TEST_CASE("bodyfit map: a run directory (final mesh, arrival times, ignitions), and errors exit 1") {
  if constexpr (!config::have_cairo) return;
  test::TempDir dir("map_command");
  fs::create_directories(dir / "run");
  write_mesh(burnt_terrain(), dir / "run" / "final.mesh");
  HeightGrid arrival = radial_arrival();
  arrival.crs = "PROJCS[\"WGS 84 / UTM zone 32N\",GEOGCS[\"WGS 84\"]]";
  for (std::size_t i = 0; i < arrival.heights.size(); i += 7) arrival.heights[i] = arrival.nodata;  // never reached
  write_esri_ascii(dir / "run" / "arrival_time.asc", arrival);
  {
    std::ofstream out(dir / "run" / "case.toml");
    out << "[region]\nshape = \"disks\"\ncenters = [[5000.0, 5000.0], [2000, 8000]]\nradii = [100.0, 50.0]\n";
  }
  const RunMap run = load_run_map(dir / "run");
  CHECK(run.mesh.n_faces() == burnt_terrain().n_faces());
  CHECK(run.layers.arrival.cols == 200);
  CHECK(run.layers.arrival.at(0, 0) == arrival.nodata);  // NODATA kept, not filled
  CHECK(run.layers.crs_name == "WGS 84 / UTM zone 32N");
  REQUIRE(run.layers.ignitions.size() == 2);
  CHECK(run.layers.ignitions[1][0] == 2000);
  CHECK(run.layers.ignitions[1][1] == 8000);

  auto result = test::run_bodyfit(fmt::format("map {} -o {} --size 800x600 --title \"Test fire\"",
                                              (dir / "run").string(), (dir / "map.png").string()));
  INFO(result.output);
  REQUIRE(result.exit_code == 0);
  const Image image = read_png(dir / "map.png");
  CHECK(image.width == 800);
  CHECK(image.height == 600);

  auto missing = test::run_bodyfit(fmt::format("map {} -o {}", dir.path().string(), (dir / "none.png").string()));
  CHECK(missing.exit_code == 1);
  CHECK(missing.output.find("final.mesh") != std::string::npos);
  auto small = test::run_bodyfit(fmt::format("map {} -o {} --size 100x100", (dir / "run").string(), (dir / "small.png").string()));
  CHECK(small.exit_code == 1);
  CHECK(small.output.find("320x240") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "none.png"));
  CHECK_FALSE(fs::exists(dir / "small.png"));
}

TEST_CASE("map at a time: the burnt fill is the arrival raster's cells reached by then, not the final G") {
  if constexpr (!config::have_cairo) return;
  test::TempDir dir("map_at");
  const SurfaceMesh mesh = burnt_terrain();  // G: the disk of 2 km
  MapLayers layers;
  layers.arrival = radial_arrival();           // the front 1.5 km out at 30 min
  layers.burnt_at = 1800;
  MapOptions options;
  draw_fire_map(dir / "map.png", mesh, layers, options);
  const Image image = read_png(dir / "map.png");
  const MapLayout layout = layout_of(mesh, options);
  const std::vector<char> cells = burnt_cells(layers.arrival, 1800);
  const HeightGrid& grid = layers.arrival;
  // Every cell centre of the southern half (the labels sit north), off the centre's star and the
  // corners' scale bar, and over a cell from the front (its outline and the 30 min isochrone):
  // reddish exactly where the cell is reached by 30 min.
  std::size_t burnt = 0, checked = 0, wrong = 0;
  for (std::size_t row = 0; row < grid.rows; ++row)
    for (std::size_t col = 0; col < grid.cols; ++col) {
      const double x = grid.x_origin + (double(col) + 0.5) * grid.cell_size;
      const double y = grid.y_origin + (double(grid.rows - 1 - row) + 0.5) * grid.cell_size;
      const double r = std::hypot(x - kCentre, y - kCentre);
      if (y > kCentre - 300 || r < 300 || r > 3500 || std::abs(r - 1500) < 1.5 * grid.cell_size) continue;
      const bool reached = cells[row * grid.cols + col];
      CHECK(reached == (grid.at(row, col) <= 1800));
      const Rgb c = pixel_at(image, layout, x, y);
      const bool grey = std::abs(int(c[0]) - int(c[1])) < 10 && std::abs(int(c[1]) - int(c[2])) < 10;
      wrong += reached ? !reddish(c) : !grey;
      burnt += reached;
      ++checked;
    }
  CHECK(burnt > 300);                 // the half disk of 1.5 km: ≈ 1400 cells of 50 m
  CHECK(checked - burnt > 1000);      // and the ring beyond it, inside the final G up to 2 km
  CHECK(wrong == 0);
  // Without a time, the final G: the ring from 1.6 to 1.9 km south is burnt again.
  layers.burnt_at.reset();
  draw_fire_map(dir / "final.png", mesh, layers, options);
  CHECK(reddish(pixel_at(read_png(dir / "final.png"), layout, kCentre, kCentre - 1750)));
  CHECK_FALSE(reddish(pixel_at(image, layout, kCentre, kCentre - 1750)));

  // bodyfit map --at and --every on a run directory.
  fs::create_directories(dir / "run");
  write_mesh(mesh, dir / "run" / "final.mesh");
  write_esri_ascii(dir / "run" / "arrival_time.asc", layers.arrival);
  auto at = test::run_bodyfit(fmt::format("map {} -o {} --at 1800", (dir / "run").string(), (dir / "at.png").string()));
  REQUIRE_MESSAGE(at.exit_code == 0, at.output);
  CHECK(test::read_file(dir / "at.png") == test::read_file(dir / "map.png"));  // the picture drawn above
  // The latest arrival is at the corners, 5 √2 km / (0.83 m/s) ≈ 2.36 h: maps at 1, 2 and 3 h.
  auto every = test::run_bodyfit(fmt::format("map {} -o {} --every 3600", (dir / "run").string(), (dir / "m.png").string()));
  REQUIRE_MESSAGE(every.exit_code == 0, every.output);
  for (const char* name : {"m_003600s.png", "m_007200s.png", "m_010800s.png"}) CHECK(fs::exists(dir / name));
  CHECK_FALSE(fs::exists(dir / "m_014400s.png"));
  fs::remove(dir / "run" / "arrival_time.asc");
  auto none = test::run_bodyfit(fmt::format("map {} -o {} --at 60", (dir / "run").string(), (dir / "none.png").string()));
  CHECK(none.exit_code == 1);
  CHECK(none.output.find("arrival times") != std::string::npos);
  CHECK(test::run_bodyfit(fmt::format("map {} -o {} --at -5", (dir / "run").string(), (dir / "none.png").string()))
            .exit_code == 2);
}
