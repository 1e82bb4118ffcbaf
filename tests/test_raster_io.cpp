// write_raster: ESRI ASCII grids and GeoTIFFs read back through GDAL (the module's reader) with
// their coordinate system, NODATA value and values.
#include <bodyfit/app/config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/app/raster_io.hpp>

#include "gis_module.hpp"
#include "test_support.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

using namespace bodyfit;

namespace {

// A 7 × 5 raster in UTM zone 32N with values of every kind: integers, fractions no float holds
// exactly, NaN (not reached) and the NODATA marker itself.
HeightGrid sample_grid() {
  HeightGrid g;
  g.cols = 7;
  g.rows = 5;
  g.x_origin = 288000.5;
  g.y_origin = 5548000.25;
  g.cell_size = 25;
  g.nodata = -9999;
  g.crs = test::read_file(test::source_path("meshes/dem/luxembourg_elev_200m.prj"));
  for (std::size_t i = 0; i < g.rows * g.cols; ++i) g.heights.push_back(double(i) / 3.0 + 1e3 * double(i % 4));
  g.heights[3] = std::numeric_limits<double>::quiet_NaN();
  g.heights[11] = -9999;
  return g;
}

std::string command_output(const std::string& command) {
  std::string out;
  if (FILE* pipe = popen(command.c_str(), "r")) {
    char buffer[4096];
    while (std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
    pclose(pipe);
  }
  return out;
}

}  // namespace

TEST_CASE("write_raster: a GeoTIFF reads back with its CRS, NODATA and values") {
  if constexpr (!config::have_gdal) return;
  test::TempDir dir("raster_io_tif");
  const HeightGrid grid = sample_grid();
  const auto file = dir / "arrival.tif";
  write_raster(file, grid, {.units = "s", .description = "fire arrival time", .nodata = -1.0,
                            .items = {{"START_TIME", "2026-07-14T13:00:00Z"}}});
  const gis::Api& gis = gis::module_for(file);
  HeightGrid back;
  std::string error;
  REQUIRE(gis.read_raster(file, back, error));
  CHECK(back.cols == grid.cols);
  CHECK(back.rows == grid.rows);
  CHECK(back.x_origin == grid.x_origin);
  CHECK(back.y_origin == grid.y_origin);
  CHECK(back.cell_size == grid.cell_size);
  CHECK(back.nodata == -1.0);
  CHECK(gis.same_crs(back.crs, grid.crs));
  gis::CrsInfo info;
  REQUIRE(gis.describe_crs(back.crs, info, error));
  CHECK(info.epsg == 32632);
  for (std::size_t i = 0; i < grid.heights.size(); ++i) {
    INFO("cell " << i);
    if (i == 3 || i == 11) CHECK(back.heights[i] == -1.0);
    else CHECK(back.heights[i] == grid.heights[i]);
  }
  // No temporary left beside it.
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path())) ++files;
  CHECK(files == 1);
  // What QGIS shows: the units, description, metadata and compression (gdalinfo, from gdal-bin).
  if (std::system("command -v gdalinfo > /dev/null 2>&1") != 0) {
    MESSAGE("gdalinfo not found (Debian package gdal-bin): metadata check skipped");
    return;
  }
  const std::string info_text = command_output("gdalinfo '" + file.string() + "'");
  CHECK(info_text.find("Unit Type: s") != std::string::npos);
  CHECK(info_text.find("Description = fire arrival time") != std::string::npos);
  CHECK(info_text.find("START_TIME=2026-07-14T13:00:00Z") != std::string::npos);
  CHECK(info_text.find("COMPRESSION=DEFLATE") != std::string::npos);
  CHECK(info_text.find("NoData Value=-1") != std::string::npos);
}

TEST_CASE("write_raster: an ESRI ASCII grid with its .prj, NaN cells as NODATA") {
  test::TempDir dir("raster_io_asc");
  const HeightGrid grid = sample_grid();
  write_raster(dir / "ros.asc", grid, {.units = "m/s"});
  const HeightGrid back = read_esri_ascii(dir / "ros.asc");  // fills NODATA cells: compare the others
  CHECK(back.crs == test::read_file(test::source_path("meshes/dem/luxembourg_elev_200m.prj")).substr(0, back.crs.size()));
  CHECK(!back.crs.empty());
  const std::string text = test::read_file(dir / "ros.asc");
  CHECK(text.find("NODATA_value -9999\n") != std::string::npos);
  CHECK(text.find("nan") == std::string::npos);
  for (std::size_t i = 0; i < grid.heights.size(); ++i)
    if (i != 3 && i != 11) CHECK(back.heights[i] == grid.heights[i]);
}

TEST_CASE("write_raster: an unknown extension or an empty grid is an InputError, an unwritable file an IoError") {
  test::TempDir dir("raster_io_bad");
  const HeightGrid grid = sample_grid();
  CHECK_THROWS_AS(write_raster(dir / "a.png", grid), InputError);
  CHECK_THROWS_AS(write_raster(dir / "a.asc", HeightGrid{}), InputError);
  CHECK_THROWS_AS(write_raster(dir / "missing" / "a.asc", grid), IoError);
  if constexpr (config::have_gdal) CHECK_THROWS_AS(write_raster(dir / "missing" / "a.tif", grid), IoError);
}
