// Fuel moistures in time and per cell: the series and rasters of [model.moisture], their errors,
// and runs where moisture stops a fire (a wet half of the landscape, a rain at a given time).
#include "moisture.hpp"
#include "rothermel.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/parameters.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>
#include <fmt/format.h>
#include <toml++/toml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace bodyfit;
using namespace bodyfit::fire;
namespace fs = std::filesystem;

namespace {

std::string read_error(const std::string& table_text, const fs::path& dir) {
  const toml::table t = toml::parse(table_text, (dir / "case.toml").string());
  Parameters p(t, moisture_parameters(), "model");
  try {
    read_moisture(p.section("moisture"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

std::vector<double> areas_of(const fs::path& history) { return test::csv_column(history, "area"); }

const char* kFlatCase = R"([surface]
generator = "plane"
size = 2400.0
h = 24.0
[region]
shape = "disks"
centers = [[-200.0, 0.0]]
radii = [60.0]
[model]
name = "fire"
spread = "rothermel"
[model.fuel]
model = "GR2"
[model.wind]
type = "uniform"
speed = 4.4704
direction_deg = 270.0
height = "20ft"
[model.arrival]
cell_size = 24.0
[time]
dt = 300.0
final_time = 3600.0
[discretize]
drop_detached = true
[output]
vtu_every = 0
)";

}  // namespace

TEST_CASE("moisture series: linear in time, the ends held, on the run's clock, bad rows named by their line") {
  test::TempDir dir("moisture_series");
  std::ofstream(dir / "m.csv") << "time,dead_1h,dead_10h,dead_100h,live_herb,live_woody\n0,4,5,6,60,90\n600,8,9,10,120,150\n";
  MoistureField m = MoistureField::series(dir / "m.csv");
  CHECK(m.kind() == MoistureField::Kind::series);
  m.set_clock(std::nullopt);
  CHECK(m.at(0, 0, -5).value[dead_1h] == doctest::Approx(0.04));
  CHECK(m.at(0, 0, 300).value[dead_1h] == doctest::Approx(0.06));
  CHECK(m.at(0, 0, 300).value[live_herb] == doctest::Approx(0.90));
  CHECK(m.at(0, 0, 9000).value[live_woody] == doctest::Approx(1.50));
  auto error_of = [&](const std::string& text) {
    std::ofstream(dir / "bad.csv") << text;
    try {
      MoistureField::series(dir / "bad.csv");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string at = (dir / "bad.csv").string();
  CHECK(error_of("time,dead_1h,dead_10h,dead_100h,live_herb,live_woody\n0,0.04,5,6,60,90\n") ==
        at + ":2: dead_1h: 0.04 looks like a fraction: moistures are in percent (4 for 4 %)");
  CHECK(error_of("time,dead_1h,dead_10h,dead_100h,live_herb\n0,4,5,6,60\n").starts_with(at + ":1: no column 'live_woody'"));
  CHECK(error_of("time,dead_1h,dead_10h,dead_100h,live_herb,live_woody\n0,4,5,6,60,90\n0,4,5,6,60,90\n")
            .starts_with(at + ":3: time 0 is not after"));
  // Date-times need the run's start.
  std::ofstream(dir / "dated.csv") << "time,dead_1h,dead_10h,dead_100h,live_herb,live_woody\n"
                                      "2026-07-14T12:00:00Z,4,5,6,60,90\n2026-07-14T13:00:00Z,8,9,10,60,90\n";
  MoistureField dated = MoistureField::series(dir / "dated.csv");
  CHECK_THROWS_WITH_AS(dated.set_clock(std::nullopt), doctest::Contains("needs [time] start"), InputError);
}

TEST_CASE("[model.moisture]: a scenario, the classes, rasters or a file, one way at a time") {
  test::TempDir dir("moisture_table");
  std::ofstream(dir / "wet.asc") << "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 100\nNODATA_value -9999\n5 30\n";
  std::ofstream(dir / "fraction.asc") << "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 100\nNODATA_value -9999\n5 0.3\n";
  const std::string classes = "dead_10h = 7.0\ndead_100h = 8.0\nlive_herb = 60.0\nlive_woody = 90.0\n";
  CHECK(read_error("[moisture]\ndead_1h_map = 'wet.asc'\n" + classes, dir.path()) == "no error");
  CHECK(read_error("[moisture]\ndead_1h_map = 'fraction.asc'\n" + classes, dir.path())
            .find("the cell at row 1, column 2: 0.3 looks like a fraction") != std::string::npos);
  CHECK(read_error("[moisture]\ndead_1h = 5.0\ndead_1h_map = 'wet.asc'\n" + classes, dir.path()).find("not both") != std::string::npos);
  CHECK(read_error("[moisture]\nfile = 'm.csv'\ndead_1h = 5.0\n", dir.path()).find("not both") != std::string::npos);
  CHECK(read_error("[moisture]\nscenario = 'D1L1'\nfile = 'm.csv'\n", dir.path()).find("not several") != std::string::npos);
  CHECK(read_error("[moisture]\ndead_1h_map = 'wet.asc'\n", dir.path()).find("dead_10h") != std::string::npos);
  const toml::table t = toml::parse("[moisture]\ndead_1h_map = 'wet.asc'\n" + classes, (dir / "case.toml").string());
  Parameters p(t, moisture_parameters(), "model");
  const MoistureField m = read_moisture(p.section("moisture"));
  CHECK(m.kind() == MoistureField::Kind::maps);
  CHECK(m.at(50, 50, 0).value[dead_1h] == doctest::Approx(0.05));   // a cell centre
  CHECK(m.at(150, 50, 0).value[dead_1h] == doctest::Approx(0.30));
  CHECK(m.at(150, 50, 0).value[dead_10h] == doctest::Approx(0.07));  // the constant classes
}

TEST_CASE("a run: the head stops where the moisture raster reaches extinction") {
  // GR2 (moisture of extinction 15 %) under a wind towards +x: dry (5 %) west of x = 0, wet (30 %)
  // east of it. The head would run ~830 m in the hour; it stops at the wet side.
  test::TempDir dir("moisture_wet_half");
  {
    std::ofstream wet(dir / "m1h.asc");
    wet << "ncols 24\nnrows 24\nxllcorner -1200\nyllcorner -1200\ncellsize 100\nNODATA_value -9999\n";
    for (int row = 0; row < 24; ++row) {
      for (int col = 0; col < 24; ++col) wet << (col < 12 ? "5 " : "30 ");
      wet << "\n";
    }
  }
  std::ofstream(dir / "case.toml") << kFlatCase << "[model.moisture]\ndead_1h_map = 'm1h.asc'\ndead_10h = 6.0\n"
                                   << "dead_100h = 7.0\nlive_herb = 60.0\nlive_woody = 90.0\n";
  const auto result = test::run_bodyfit(fmt::format("run {} -o {}", (dir / "case.toml").string(), (dir / "out").string()));
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  const SurfaceMesh mesh = read_mesh(dir / "out" / "final.mesh");
  double head = -1e300, back = 1e300;
  for (auto e : mesh.edges())
    if (mesh.interface(e))
      for (int i = 0; i < 2; ++i) {
        const double x = mesh.point(mesh.to_vertex_handle(mesh.halfedge_handle(e, i)))[0];
        head = std::max(head, x), back = std::min(back, x);
      }
  CHECK(head > -140 + 100);  // it ran towards the wet side...
  CHECK(head < 50);          // ...and stopped there (the bilinear raster reaches 15 % at x = −10)
  CHECK(back < -260);        // the back burns on
}

TEST_CASE("a run: a moisture series that crosses extinction stops the fire at that time") {
  // Dry for 30 minutes, then a rain: every dead class at 30 % (GR2's extinction is 15 %).
  test::TempDir dir("moisture_rain");
  std::ofstream(dir / "m.csv") << "time,dead_1h,dead_10h,dead_100h,live_herb,live_woody\n"
                                  "0,5,6,7,60,90\n1800,5,6,7,60,90\n1860,30,30,30,200,200\n";
  std::ofstream(dir / "case.toml") << kFlatCase << "[model.moisture]\nfile = 'm.csv'\n";
  const auto result = test::run_bodyfit(fmt::format("run {} -o {}", (dir / "case.toml").string(), (dir / "out").string()));
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  const std::vector<double> areas = areas_of(dir / "out" / "history.csv");
  REQUIRE(areas.size() == 13);  // t = 0, 300, …, 3600
  CHECK(areas[6] > 3 * areas[0]);                                 // it grew while dry
  CHECK(areas[12] == doctest::Approx(areas[7]).epsilon(0.01));    // and not after the rain
}

TEST_CASE("moistures per fuel: a fuel's row replaces the field's moistures for that fuel only") {
  test::TempDir dir("moisture_per_fuel");
  std::ofstream(dir / "per_fuel.csv") << "code,dead_1h,dead_10h,dead_100h,live_herb,live_woody\n102,30,30,30,200,200\n";
  FuelMoisture d1l1;
  REQUIRE(moisture_scenario("D1L1", d1l1));
  MoistureField m = MoistureField::constant(d1l1);
  m.read_per_fuel(dir / "per_fuel.csv");
  CHECK(m.at(0, 0, 0, 102).value[dead_1h] == doctest::Approx(0.30));
  CHECK(m.at(0, 0, 0, 101).value[dead_1h] == doctest::Approx(0.03));
  CHECK(m.at(0, 0, 0).value[dead_1h] == doctest::Approx(0.03));
  auto error_of = [&](const std::string& text) {
    std::ofstream(dir / "bad.csv") << text;
    try {
      m.read_per_fuel(dir / "bad.csv");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string at = (dir / "bad.csv").string();
  const std::string header = "code,dead_1h,dead_10h,dead_100h,live_herb,live_woody\n";
  CHECK(error_of(header + "102,5,6,7,60,90\n102,5,6,7,60,90\n") == at + ":3: code 102 is given twice");
  CHECK(error_of(header + "1.5,5,6,7,60,90\n") == at + ":2: code: 1.5 is not a fuel code (a positive integer)");
  CHECK(error_of(header + "102,5,6,0.07,60,90\n").starts_with(at + ":2: dead_100h: 0.07 looks like a fraction"));

  // In a run: GR2 at its extinction by its row stays as it was lit.
  std::ofstream(dir / "case.toml") << kFlatCase << "[model.moisture]\nscenario = 'D1L1'\nper_fuel = 'per_fuel.csv'\n";
  const auto result = test::run_bodyfit(fmt::format("run {} -o {}", (dir / "case.toml").string(), (dir / "out").string()));
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  const std::vector<double> areas = areas_of(dir / "out" / "history.csv");
  CHECK(areas.back() == doctest::Approx(areas.front()).epsilon(0.01));
}

TEST_CASE("a moisture raster in another coordinate system than the fuel map is refused, naming both") {
  test::TempDir dir("moisture_crs");
  const std::string grid = "ncols 24\nnrows 24\nxllcorner -1200\nyllcorner -1200\ncellsize 100\nNODATA_value -9999\n";
  std::string fuel = grid, wet = grid;
  for (int i = 0; i < 24; ++i) {
    for (int j = 0; j < 24; ++j) fuel += "102 ", wet += "5 ";
    fuel += "\n", wet += "\n";
  }
  std::ofstream(dir / "fuel.asc") << fuel;
  std::ofstream(dir / "fuel.prj") << test::utm_prj(32);
  std::ofstream(dir / "m1h.asc") << wet;
  std::ofstream(dir / "m1h.prj") << test::utm_prj(31);
  std::string text = kFlatCase;
  text.replace(text.find("model = \"GR2\""), std::string("model = \"GR2\"").size(), "map = 'fuel.asc'");
  std::ofstream(dir / "case.toml") << text << "[model.moisture]\ndead_1h_map = 'm1h.asc'\ndead_10h = 6.0\n"
                                   << "dead_100h = 7.0\nlive_herb = 60.0\nlive_woody = 90.0\n";
  const auto result = test::run_bodyfit(fmt::format("run {} -o {}", (dir / "case.toml").string(), (dir / "out").string()));
  CHECK(result.exit_code == 1);
  CHECK(result.output.find("fuel.asc and") != std::string::npos);
  CHECK(result.output.find("m1h.asc have different coordinate systems") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir / "out" / "history.csv"));
}
