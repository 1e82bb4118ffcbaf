// Crown fire: Van Wagner's (1977) initiation and critical spread rate, Rothermel's (1991) crown
// rate, the classes surface / passive / active, and a run where an active crown fire outruns its
// surface fire by the crown rate (and its fire_type raster says so).
#include "crown.hpp"
#include "fuel.hpp"
#include "rothermel.hpp"

#include <bodyfit/app/dem.hpp>
#include <bodyfit/io.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

using namespace bodyfit;
using namespace bodyfit::fire;
namespace fs = std::filesystem;

TEST_CASE("crown fire: Van Wagner's thresholds, Rothermel's crown rate and the three classes") {
  FuelMoisture moisture;
  REQUIRE(moisture_scenario("D1L1", moisture));
  const SurfaceFire tu5 = surface_fire(*fuel_table("scott_burgan40").find("TU5"), moisture);
  const SurfaceFire fm10 = surface_fire(*fuel_table("anderson13").find("FM10"), moisture);
  const double u20 = 15 * 0.44704;  // 15 mi/h at 20 ft
  const Vec3 wind20(u20, 0, 0), upslope(1, 0, 0);
  const HeadSpread surface =
      head_spread(tu5, wind_adjustment_factor(0.3048) * wind20, upslope, 0);  // TU5's bed is 1 ft deep
  const double intensity = fireline_intensity(tu5.heat_per_unit_area, surface.head);

  // Initiation: (0.010 · CBH · (460 + 25.9 · FMC))^1.5 kW/m; with CBH 1 m and FMC 100 %: 30.5^1.5.
  const CrownFire passive = crown_fire(surface, tu5.heat_per_unit_area, {1.0, 0.05, 1.0}, fm10, wind20, upslope, 0);
  CHECK(passive.initiation_intensity == doctest::Approx(std::pow(30.5, 1.5)));
  // Critical active rate: 3.0 / CBD m/min.
  CHECK(passive.critical_active_rate == doctest::Approx(3.0 / 0.05 / 60));
  // Crown rate: 3.34 × FM10's head under 0.4 × the 20-ft wind.
  CHECK(passive.active_rate == doctest::Approx(3.34 * head_spread(fm10, 0.4 * wind20, upslope, 0).head));
  REQUIRE(intensity > passive.initiation_intensity);
  CHECK(passive.type == FireType::passive);  // the crown rate is below 1 m/s = 3.0/0.05 m/min
  CHECK(passive.spread.head == surface.head);

  const CrownFire active = crown_fire(surface, tu5.heat_per_unit_area, {1.0, 0.2, 1.0}, fm10, wind20, upslope, 0);
  CHECK(active.type == FireType::active);
  CHECK(active.spread.head == doctest::Approx(active.active_rate));
  CHECK(active.spread.head > 3 * surface.head);
  CHECK(active.spread.length_to_width == doctest::Approx(1 + 0.125 * 15));

  // A high canopy base: the surface fire does not reach the crowns.
  const CrownFire high = crown_fire(surface, tu5.heat_per_unit_area, {20.0, 0.2, 1.0}, fm10, wind20, upslope, 0);
  CHECK(high.initiation_intensity > intensity);
  CHECK(high.type == FireType::surface);
  // No canopy: no crown fire.
  CHECK(crown_fire(surface, tu5.heat_per_unit_area, {1.0, 0.0, 1.0}, fm10, wind20, upslope, 0).type == FireType::surface);
}

TEST_CASE("a run under an active crown fire: the head runs at the crown rate, fire_type says active") {
  FuelMoisture moisture;
  REQUIRE(moisture_scenario("D1L1", moisture));
  const SurfaceFire fm10 = surface_fire(*fuel_table("anderson13").find("FM10"), moisture);
  const Vec3 wind20(15 * 0.44704, 0, 0);
  const double crown_rate = 3.34 * head_spread(fm10, 0.4 * wind20, Vec3(1, 0, 0), 0).head;

  test::TempDir dir("fire_crown_run");
  auto run = [&](const std::string& name, const std::string& canopy) {
    std::ofstream(dir / (name + ".toml")) << R"([surface]
generator = "plane"
size = 3000.0
h = 30.0
[region]
shape = "disks"
centers = [[-1000.0, 0.0]]
radii = [100.0]
[model]
name = "fire"
spread = "rothermel"
[model.fuel]
model = "TU5"
[model.moisture]
scenario = "D1L1"
[model.wind]
type = "uniform"
speed = 6.7056
direction_deg = 270.0
height = "20ft"
[model.arrival]
cell_size = 30.0
[time]
dt = 300.0
final_time = 3600.0
[discretize]
drop_detached = true
[output]
vtu_every = 0
)" << canopy;
    const auto result = test::run_bodyfit(
        fmt::format("run {} -o {}", (dir / (name + ".toml")).string(), (dir / name).string()));
    REQUIRE_MESSAGE(result.exit_code == 0, result.output);
    const SurfaceMesh mesh = read_mesh(dir / name / "final.mesh");
    double head = -1e300;
    for (auto e : mesh.edges())
      if (mesh.interface(e))
        for (int i = 0; i < 2; ++i) head = std::max(head, mesh.point(mesh.to_vertex_handle(mesh.halfedge_handle(e, i)))[0]);
    return head - (-1000.0 + 100.0);
  };
  const double crown = run("crown", "[model.canopy]\nbase_height = 1.0\nbulk_density = 0.2\n");
  const double surface = run("surface", "");
  MESSAGE(fmt::format("head advance in 1 h: {:.0f} m under the crowns (crown rate × t = {:.0f} m), {:.0f} m without",
                      crown, crown_rate * 3600, surface));
  CHECK(crown == doctest::Approx(crown_rate * 3600).epsilon(0.02));
  CHECK(crown > 3 * surface);
  // Every burnt cell of the crown run burnt as an active crown fire (NODATA where burning at t = 0).
  CHECK(fs::exists(dir / "crown" / "fire_type.tif"));
  CHECK_FALSE(fs::exists(dir / "surface" / "fire_type.tif"));
  // A canopy raster with a negative cell: refused, naming the cell.
  std::ofstream(dir / "cbd.asc") << "ncols 2\nnrows 1\nxllcorner -1500\nyllcorner -1500\ncellsize 1500\n"
                                    "NODATA_value -9999\n0.2 -0.1\n";
  std::ofstream(dir / "bad.toml") << test::read_file(dir / "crown.toml");
  const std::string bad = test::read_file(dir / "bad.toml");
  std::ofstream(dir / "bad.toml") << bad.substr(0, bad.find("bulk_density = 0.2")) << "bulk_density_map = 'cbd.asc'\n";
  const auto refused = test::run_bodyfit(fmt::format("run {} -o {}", (dir / "bad.toml").string(), (dir / "bad").string()));
  CHECK(refused.exit_code == 1);
  CHECK(refused.output.find("cbd.asc: the bulk_density of the cell at row 1, column 2 is negative (-0.1)") != std::string::npos);
}

TEST_CASE("sheltered wind adjustment: Albini & Baughman's factor under a canopy, unsheltered below 5 % fill") {
  // 50 % cover, 60 ft canopy, crown ratio 0.5: fill 0.5/3 · 0.5; 0.555 / (√(f H) ln((20 + 0.36 H)/(0.13 H))).
  const double f = 0.5 / 3 * 0.5, h = 60.0;
  const Sheltering shelter{.cover = 0.5, .canopy_height = 60 * 0.3048, .crown_ratio = 0.5};
  CHECK(wind_adjustment_factor(0.3048, shelter) ==
        doctest::Approx(0.555 / (std::sqrt(f * h) * std::log((20 + 0.36 * h) / (0.13 * h)))));
  // A thin canopy (fill 4 %): the bed's own, unsheltered factor.
  CHECK(wind_adjustment_factor(0.3048, {.cover = 0.24, .canopy_height = 18, .crown_ratio = 0.5}) ==
        wind_adjustment_factor(0.3048));
}

TEST_CASE("a FARSITE landscape (.lcp): its bands in SI units, and a run on its elevation, fuel and canopy") {
  const fs::path lcp = test::source_path("meshes/fixtures/landscape_20x20.lcp");
  // meshes/fixtures/README.md: canopy heights stored in m × 10, bulk density in kg/m³ × 100.
  const HeightGrid cbh = read_landscape_band(lcp, LandscapeBand::canopy_base_height);
  const HeightGrid cbd = read_landscape_band(lcp, LandscapeBand::canopy_bulk_density);
  const HeightGrid height = read_landscape_band(lcp, LandscapeBand::canopy_height);
  const HeightGrid cover = read_landscape_band(lcp, LandscapeBand::canopy_cover);
  const HeightGrid fuel = read_landscape_band(lcp, LandscapeBand::fuel);
  const HeightGrid elevation = read_dem(lcp);
  REQUIRE(cbh.cols == 20);
  CHECK(cbh.at(5, 5) == doctest::Approx(2.0));
  CHECK(cbd.at(5, 5) == doctest::Approx(0.2));
  CHECK(height.at(5, 5) == doctest::Approx(20.0));
  CHECK(cover.at(5, 5) == 60);
  CHECK(fuel.at(5, 0) == 102);
  CHECK(fuel.at(5, 19) == 165);
  CHECK(elevation.at(0, 1) - elevation.at(0, 0) == 3);
  CHECK(elevation.crs.find("UTM zone 32N") != std::string::npos);

  // A run: the landscape's elevation as the surface, its fuel band and canopy bands as the model's.
  test::TempDir dir("fire_landscape");
  std::ofstream(dir / "case.toml") << fmt::format(R"([surface]
generator = "terrain"
dem = "{0}"
h = 30.0
[region]
shape = "disks"
centers = [[500200.0, 5500300.0]]
radii = [60.0]
[model]
name = "fire"
spread = "rothermel"
landscape = "{0}"
[model.moisture]
scenario = "D1L1"
[model.wind]
type = "uniform"
speed = 6.7
direction_deg = 270.0
height = "20ft"
[time]
dt = 120.0
final_time = 600.0
[output]
vtu_every = 0
)",
                                                  lcp.string());
  const auto result = test::run_bodyfit(fmt::format("run {} -o {}", (dir / "case.toml").string(), (dir / "out").string()));
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  CHECK(fs::exists(dir / "out" / "fire_type.tif"));
  CHECK(fs::exists(dir / "out" / "fireline_intensity.tif"));
  // Both the fuel map and the landscape: refused.
  std::ofstream(dir / "both.toml") << test::read_file(dir / "case.toml") << "[model.fuel]\nmodel = \"GR2\"\n";
  const auto both = test::run_bodyfit(fmt::format("run {} -o {}", (dir / "both.toml").string(), (dir / "out2").string()));
  CHECK(both.exit_code == 1);
  CHECK(both.output.find("the fuel comes from [model] landscape") != std::string::npos);
}
