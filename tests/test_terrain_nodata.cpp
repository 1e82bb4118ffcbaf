// Terrains from DEMs with NODATA cells: the surface covers the valid cells only, its boundary
// follows the data mask (topology as the mask says, vertices over data, area within a lattice
// bound of the valid cells'), it stays so through a remesh, and pieces that touch at a point or are
// tiny are dealt with; `nodata = "fill"` keeps the old nearest-valid surface.
#include <bodyfit/error.hpp>
#include <bodyfit/app/dem.hpp>
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/remesh.hpp>
#include <bodyfit/validate.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>
#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <string>

using namespace bodyfit;

namespace {

constexpr double kCell = 10;

double plane(double x, double y) { return 100 + 0.3 * x - 0.2 * y; }

// A cols × rows raster of kCell cells from (500, 1000): the plane where `valid(col, south)` holds
// (south: row counted from the south), NODATA elsewhere.
HeightGrid masked_grid(std::size_t cols, std::size_t rows, const std::function<bool(long, long)>& valid) {
  HeightGrid g;
  g.cols = cols, g.rows = rows, g.x_origin = 500, g.y_origin = 1000, g.cell_size = kCell;
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t c = 0; c < cols; ++c) {
      const long south = long(rows - 1 - r);
      const double x = g.x_origin + (double(c) + 0.5) * kCell, y = g.y_origin + (double(south) + 0.5) * kCell;
      g.heights.push_back(valid(long(c), south) ? plane(x, y) : g.nodata);
    }
  return g;
}

// A staircase west side, the north-east corner cut out (an L) and a 6 × 6 hole in the middle:
// one piece with two boundary loops (χ = 0).
bool l_with_hole(long c, long s) {
  if (c < s / 6) return false;                        // staircase: one column more every 6 rows
  if (c >= 26 && s >= 18) return false;               // the L's missing corner
  if (c >= 12 && c < 18 && s >= 8 && s < 14) return false;  // the hole
  return true;
}

// Plan-view distance from (x, y) to the union of the valid cells (closed squares).
double distance_to_data(const HeightGrid& g, double x, double y) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t r = 0; r < g.rows; ++r)
    for (std::size_t c = 0; c < g.cols; ++c) {
      if (!g.valid(r, c)) continue;
      const double x0 = g.x_origin + double(c) * g.cell_size, y0 = g.y_origin + double(g.rows - 1 - r) * g.cell_size;
      const double dx = std::max({x0 - x, 0.0, x - (x0 + g.cell_size)});
      const double dy = std::max({y0 - y, 0.0, y - (y0 + g.cell_size)});
      best = std::min(best, std::hypot(dx, dy));
    }
  return best;
}

// Length of the mask's outline: the cell sides between a valid cell and a NODATA cell or the outside.
double outline_length(const HeightGrid& g) {
  auto valid = [&](long r, long c) {
    return r >= 0 && c >= 0 && r < long(g.rows) && c < long(g.cols) && g.valid(std::size_t(r), std::size_t(c));
  };
  double length = 0;
  for (long r = 0; r < long(g.rows); ++r)
    for (long c = 0; c < long(g.cols); ++c)
      if (valid(r, c))
        for (auto [dr, dc] : {std::pair{-1, 0}, std::pair{1, 0}, std::pair{0, -1}, std::pair{0, 1}})
          if (!valid(r + dr, c + dc)) length += g.cell_size;
  return length;
}

double plan_area(const SurfaceMesh& mesh) {
  double area = 0;
  for (auto f : mesh.faces()) {
    auto p = face_points(mesh, f);
    area += 0.5 * std::abs((p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]));
  }
  return area;
}

// Distance from p to the segment [a, b].
double segment_distance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 d = b - a;
  const double t = std::clamp(((p - a) | d) / d.sqrnorm(), 0.0, 1.0);
  return (p - (a + t * d)).norm();
}

std::string problems(const SurfaceMesh& mesh, long chi, std::size_t loops) {
  ValidateOptions options;
  options.euler_characteristic = chi;
  options.boundary_loops = loops;
  const ValidationReport report = validate_mesh(mesh, options);
  return report.ok() ? std::string() : report.summary();
}

}  // namespace

TEST_CASE("terrain over NODATA: an L with a staircase side and a hole is one piece with two loops") {
  const HeightGrid g = masked_grid(40, 30, l_with_hole);
  const SurfaceMesh mesh = make_terrain_from_grid(g);  // h = the cell size, NODATA as holes
  const std::string report = problems(mesh, 0, 2);
  INFO(report);
  CHECK(report.empty());
  CHECK(connected_components(mesh) == 1);

  // Every vertex lies over valid data (the lattice's points on cell sides included), at the
  // height of the plane within what a bilinear mean over the valid cells next to it can differ:
  // the cell centres used are within √2 cells, and the plane rises by |∇z| per metre.
  const double slope = std::hypot(0.3, 0.2);
  double worst_distance = 0, worst_height = 0;
  for (auto v : mesh.vertices()) {
    const Vec3 p = mesh.point(v);
    worst_distance = std::max(worst_distance, distance_to_data(g, p[0], p[1]));
    worst_height = std::max(worst_height, std::abs(p[2] - plane(p[0], p[1])));
  }
  CHECK(worst_distance <= 1e-9 * kCell);
  CHECK(worst_height <= std::sqrt(2.0) * kCell * slope);

  // Area in plan view against the valid cells': a valid point farther than a lattice edge (h)
  // from the outline has all the samples of its lattice triangle over data, so it is covered, and
  // a covered NODATA point is within 0.29 h of a sample over data: the two differ only in a band of
  // width h along the outline.
  const double valid_area = double(g.heights.size() - count_nodata(g)) * kCell * kCell;
  const double bound = outline_length(g) * kCell;
  const double area = plan_area(mesh);
  INFO("area " << area << ", valid cells " << valid_area << ", bound ±" << bound);
  CHECK(std::abs(area - valid_area) <= bound);
}

TEST_CASE("terrain over NODATA: remeshed at the defaults, it keeps its loops, χ and outline") {
  const HeightGrid g = masked_grid(40, 30, l_with_hole);
  const SurfaceMesh original = make_terrain_from_grid(g);
  SurfaceMesh mesh = original;
  remesh(mesh);
  const std::string report = problems(mesh, 0, 2);
  INFO(report);
  CHECK(report.empty());
  CHECK(connected_components(mesh) == 1);
  // Boundary vertices stay on the outline (a boundary edge of the surface meshed from the mask);
  // every vertex stays over data within half a cell.
  std::vector<std::pair<Vec3, Vec3>> outline;
  for (auto e : original.edges())
    if (original.is_boundary(e)) {
      auto h = original.halfedge_handle(e, 0);
      outline.emplace_back(original.point(original.from_vertex_handle(h)), original.point(original.to_vertex_handle(h)));
    }
  double off_outline = 0, off_data = 0;
  for (auto v : mesh.vertices()) {
    const Vec3 p = mesh.point(v);
    off_data = std::max(off_data, distance_to_data(g, p[0], p[1]));
    if (!mesh.is_boundary(v)) continue;
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& [a, b] : outline) nearest = std::min(nearest, segment_distance(p, a, b));
    off_outline = std::max(off_outline, nearest);
  }
  CHECK(off_outline <= 1e-6 * kCell);
  CHECK(off_data <= 0.5 * kCell);
}

TEST_CASE("terrain over NODATA: two separate blobs give two pieces, fill gives the whole rectangle") {
  auto two_blobs = [](long c, long s) { return s >= 2 && s < 14 && ((c >= 2 && c < 14) || (c >= 18 && c < 30)); };
  const HeightGrid g = masked_grid(32, 16, two_blobs);
  const SurfaceMesh mesh = make_terrain_from_grid(g);
  const std::string report = problems(mesh, 2, 2);
  INFO(report);
  CHECK(report.empty());
  CHECK(connected_components(mesh) == 2);

  const SurfaceMesh filled = make_terrain_from_grid(g, GridTerrainOptions{.nodata = NodataMode::fill});
  CHECK(problems(filled, 1, 1).empty());
  const BoundingBox box = bounding_box(filled);
  CHECK(box.min[0] == 500);
  CHECK(box.max[0] == 500 + 32 * kCell);
  CHECK(box.min[1] == 1000);
  CHECK(box.max[1] == 1000 + 16 * kCell);
}

TEST_CASE("terrain over NODATA: pieces touching at a corner are split, small islands dropped") {
  // Two 8 × 7 rectangles touching diagonally at one cell corner, (590, 1070): a vertex of the
  // lattice (an even row of 24 columns at y = 1000 + 8 · 140/16), where a fan of triangles over each
  // rectangle meets; and a 2 × 2 island (400 m², under the default 16 h² = 1600 m²).
  auto mask = [](long c, long s) {
    const bool south_west = c >= 1 && c < 9 && s >= 0 && s < 7;
    const bool north_east = c >= 9 && c < 17 && s >= 7 && s < 14;
    const bool island = c >= 20 && c < 22 && s >= 2 && s < 4;
    return south_west || north_east || island;
  };
  const HeightGrid g = masked_grid(24, 14, mask);
  const SurfaceMesh mesh = make_terrain_from_grid(g);
  const std::string report = problems(mesh, 2, 2);  // no vertex with two fans (validate_mesh checks it)
  INFO(report);
  CHECK(report.empty());
  CHECK(connected_components(mesh) == 2);
  // Islands of any size kept: three pieces.
  const SurfaceMesh all = make_terrain_from_grid(g, GridTerrainOptions{.min_island_area = 0});
  CHECK(connected_components(all) == 3);
  CHECK(validate_mesh(all).ok());
  // Nothing left: an error, not an empty surface.
  CHECK_THROWS_AS(make_terrain_from_grid(g, GridTerrainOptions{.min_island_area = 1e9}), InputError);
}

TEST_CASE("terrain over NODATA: bodyfit mesh terrain says how many cells it left out, --nodata fill") {
  test::TempDir dir("terrain_nodata_cli");
  HeightGrid g = masked_grid(40, 30, l_with_hole);
  write_esri_ascii(dir / "l.asc", g);
  const std::size_t missing = count_nodata(g);
  const auto hole = test::run_bodyfit(fmt::format("mesh terrain --dem {} -o {}", (dir / "l.asc").string(),
                                                  (dir / "hole.mesh").string()));
  INFO(hole.output);
  CHECK(hole.exit_code == 0);
  CHECK(hole.output.find(fmt::format("{} NODATA cell(s) of {} left out", missing, g.heights.size())) !=
        std::string::npos);
  CHECK(boundary_loops(read_mesh(dir / "hole.mesh")).size() == 2);
  const auto fill = test::run_bodyfit(fmt::format("mesh terrain --dem {} --nodata fill -o {}",
                                                  (dir / "l.asc").string(), (dir / "fill.mesh").string()));
  INFO(fill.output);
  CHECK(fill.exit_code == 0);
  CHECK(fill.output.find(fmt::format("{} NODATA cell(s) of {} filled", missing, g.heights.size())) !=
        std::string::npos);
  CHECK(boundary_loops(read_mesh(dir / "fill.mesh")).size() == 1);
  const auto bad = test::run_bodyfit(fmt::format("mesh terrain --dem {} --nodata zero -o {}",
                                                 (dir / "l.asc").string(), (dir / "bad.mesh").string()));
  CHECK(bad.exit_code == 2);
  // Without a DEM there is no NODATA: a usage error.
  const auto no_dem = test::run_bodyfit(fmt::format("mesh terrain --nodata fill -o {}", (dir / "p.mesh").string()));
  CHECK(no_dem.exit_code == 2);
}

TEST_CASE("DEM outliers: an undeclared NODATA marker is NODATA, a lone spike or pit takes its neighbours' median, "
          "a cliff and real DEMs are left as they are") {
  test::TempDir dir("dem_outliers");
  // A smooth slope 40 × 30 cells of 25 m, with a cliff of 400 m across it (a real feature: a whole
  // line of cells far off their neighbours), a spike of 1e6 m, a pit of −5000 m and an undeclared
  // −32768 marker.
  const int cols = 40, rows = 30;
  auto height = [](int r, int c) { return 300.0 + 2.0 * c + 1.5 * r + (c >= 20 ? 400.0 : 0.0); };
  std::vector<double> z;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) z.push_back(height(r, c));
  z[5 * cols + 7] = 1e6;
  z[12 * cols + 30] = -5000;
  z[20 * cols + 10] = -32768;
  std::string text = fmt::format("ncols {}\nnrows {}\nxllcorner 500000\nyllcorner 4000000\ncellsize 25\n"
                                 "NODATA_value -9999\n",
                                 cols, rows);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) text += fmt::format("{} ", z[std::size_t(r * cols + c)]);
    text += "\n";
  }
  std::ofstream(dir / "dem.asc") << text;
  const HeightGrid grid = read_dem(dir / "dem.asc");
  CHECK(grid.at(5, 7) == doctest::Approx(height(5, 7)).epsilon(0.02));  // the spike: its neighbours' median
  CHECK(grid.at(12, 30) == doctest::Approx(height(12, 30)).epsilon(0.02));  // the pit
  CHECK_FALSE(grid.valid(20, 10));  // the marker: NODATA
  std::size_t changed = 0;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      if (grid.valid(std::size_t(r), std::size_t(c)) && grid.at(std::size_t(r), std::size_t(c)) != height(r, c)) ++changed;
  CHECK(changed == 2);  // the cliff stays, and so does every other cell
  // The same cells as a raster of values (a fuel map, a wind grid): read as they are.
  const HeightGrid values = read_raster(dir / "dem.asc");
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      CAPTURE(r);
      CAPTURE(c);
      CHECK(values.at(std::size_t(r), std::size_t(c)) == z[std::size_t(r * cols + c)]);
    }
  // The shipped DEMs (a real one among them) come back exactly as written.
  for (const char* name : {"hill.asc", "luxembourg_elev_200m.asc"}) {
    CAPTURE(name);
    const auto path = test::source_path(std::string("meshes/dem/") + name);
    const HeightGrid screened = read_dem(path), raw = read_esri_ascii_values(path);
    REQUIRE(screened.heights.size() == raw.heights.size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < raw.heights.size(); ++i)
      differ += !(screened.heights[i] == raw.heights[i] || (std::isnan(screened.heights[i]) && raw.heights[i] == raw.nodata));
    CHECK(differ == 0);
  }
}
