// The front tracking of Rothermel's fire ellipse against its exact solution: a point ignition under
// a uniform wind on flat ground (the shipped case meshes/cases/fire_ellipse.toml, run as users run
// it), and the same with slope as the effective wind on an inclined plane.
#include "rothermel.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/plugin_loader.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

using namespace bodyfit;
namespace fs = std::filesystem;

namespace {

// Perimeter of the ellipse of semi-axes a and b (midpoint rule on the parametrisation, converged
// far below the tolerances here).
double ellipse_perimeter(double a, double b) {
  const int n = 20000;
  double length = 0;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * (i + 0.5) / n;
    length += std::hypot(a * std::sin(t), b * std::cos(t));
  }
  return length * 2 * M_PI / n;
}

// The exact burnt region at t from a disk of radius r0: the disk swept by the ellipse the fire
// traces in t (the Hopf–Lax formula for a convex ellipse of spread), so its extent grows by r0
// in every direction and its area is |tE| + r0·perimeter(tE) + π r0².
struct ExactFire {
  double head, back, flank, area;
};
ExactFire exact_fire(const fire::HeadSpread& s, double r0, double t) {
  const double a = 0.5 * (s.head + s.back) * t, b = s.flank * t;
  return {.head = s.head * t + r0,
          .back = s.back * t + r0,
          .flank = b + r0,
          .area = M_PI * a * b + r0 * ellipse_perimeter(a, b) + M_PI * r0 * r0};
}

struct FireExtent {
  double head = -1e300, back = 1e300, flank = 0;
};
FireExtent front_extent(const SurfaceMesh& mesh) {
  FireExtent e;
  for (auto edge : mesh.edges())
    if (mesh.interface(edge))
      for (int i = 0; i < 2; ++i) {
        const Vec3& p = mesh.point(mesh.to_vertex_handle(mesh.halfedge_handle(edge, i)));
        e.head = std::max(e.head, p[0]);
        e.back = std::min(e.back, p[0]);
        e.flank = std::max(e.flank, std::abs(p[1]));
      }
  return e;
}

// Area of the Minkowski sum of two centred ellipses (semi-axes (a1, b1) and (a2, b2) on the same
// axes) and a shift: its boundary point of outer normal n is the sum of the ellipses' (Gauss map).
double minkowski_area(double a1, double b1, double a2, double b2) {
  const int n = 20000;
  std::vector<std::pair<double, double>> boundary;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n, nx = std::cos(t), ny = std::sin(t);
    auto point = [&](double a, double b) {
      const double s = std::sqrt(a * a * nx * nx + b * b * ny * ny);
      return std::pair{a * a * nx / s, b * b * ny / s};
    };
    const auto [x1, y1] = point(a1, b1);
    const auto [x2, y2] = point(a2, b2);
    boundary.emplace_back(x1 + x2, y1 + y2);
  }
  double area = 0;
  for (int i = 0; i < n; ++i) {
    const auto& [x0, y0] = boundary[std::size_t(i)];
    const auto& [x1, y1] = boundary[std::size_t((i + 1) % n)];
    area += x0 * y1 - x1 * y0;
  }
  return 0.5 * area;
}

}  // namespace

TEST_CASE("fire_ellipse.toml: a point ignition under a uniform wind burns the exact ellipse, hour by hour") {
  // The case's fuel, moisture and wind (GR1, D1L1, 10 mi/h at 20 ft from the west).
  const fire::FuelModel gr1 = *fire::fuel_table("scott_burgan40").find("GR1");  // a copy: the table is a temporary
  fire::FuelMoisture moisture;
  REQUIRE(fire::moisture_scenario("D1L1", moisture));
  const double midflame = 4.4704 * fire::midflame_factor(fire::WindHeight::twenty_feet, gr1.depth);
  const fire::HeadSpread spread =
      fire::head_spread(fire::surface_fire(gr1, moisture), Vec3(midflame, 0, 0), Vec3(1, 0, 0), 0.0);
  REQUIRE(spread.length_to_width > 1.5);  // an ellipse, not a circle

  test::TempDir dir("fire_ellipse");
  const auto result = test::run_bodyfit(
      fmt::format("run {} -o {}", test::source_path("meshes/cases/fire_ellipse.toml").string(), dir.path().string()));
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  const double ignition_x = -800, r0 = 50;
  for (int hour = 1; hour <= 6; ++hour) {
    CAPTURE(hour);
    const SurfaceMesh mesh = read_vtu(dir / fmt::format("step_{:05d}.vtu", 12 * hour));
    const ExactFire exact = exact_fire(spread, r0, 3600.0 * hour);
    const FireExtent e = front_extent(mesh);
    const double area = region_area(mesh, kInside);
    const std::string figures = (fmt::format("head {:.1f} (exact {:.1f}), back {:.1f} ({:.1f}), flank {:.1f} ({:.1f}), area {:.0f} ({:.0f})",
                     e.head - ignition_x, exact.head, ignition_x - e.back, exact.back, e.flank, exact.flank, area,
                     exact.area));
    INFO(figures);
    MESSAGE(figures);
    CHECK(std::abs(area / exact.area - 1) < 0.005);
    CHECK(std::abs((e.head - ignition_x) / exact.head - 1) < 0.005);
    CHECK(std::abs((e.flank) / exact.flank - 1) < 0.005);
    CHECK(std::abs((ignition_x - e.back) / exact.back - 1) < 0.02);
  }
}

TEST_CASE("the fire model's settings: rothermel takes a fuel table, moistures and a wind height, Balbi's keys are refused") {
  LoadedModel model = load_plugin_file(fs::path(BODYFIT_PLUGIN_DIR) / "bodyfit_fire.so");
  auto configure = [&](const std::string& text) { configure_model(model, toml::parse(text)); };
  const std::string rothermel = "spread = 'rothermel'\n";
  const std::string fuel = "[fuel]\nmodel = 'GR2'\n";
  const std::string moisture = "[moisture]\nscenario = 'D1L1'\n";
  CHECK_NOTHROW(configure(rothermel + fuel + moisture));
  CHECK_NOTHROW(configure(rothermel + "limit_effective_wind = false\n" + fuel + "table = 'scott_burgan40'\n" + moisture +
                          "[wind]\ntype = 'uniform'\nspeed = 5.0\ndirection_deg = 270.0\nheight = '10m'\n"));
  // Balbi's parameters do not apply to Rothermel's spread, nor Rothermel's to Balbi's.
  CHECK_THROWS_WITH_AS(configure(rothermel + "R0 = 0.4\n" + fuel + moisture), doctest::Contains("[model] R0: does not apply to spread = \"rothermel\""), InputError);
  CHECK_THROWS_WITH_AS(configure("[moisture]\nscenario = 'D1L1'\n"), doctest::Contains("[model] moisture: does not apply to spread = \"balbi\""), InputError);
  CHECK_THROWS_WITH_AS(configure("[wind]\ntype = 'uniform'\nspeed = 5.0\ndirection_deg = 0.0\nheight = '20ft'\n"),
                       doctest::Contains("spread = \"balbi\" takes the wind at the flame"), InputError);
  // A fuel, a known model, moistures in percent.
  CHECK_THROWS_WITH_AS(configure(rothermel + moisture), doctest::Contains("expected either fuel.model"), InputError);
  CHECK_THROWS_WITH_AS(configure(rothermel + "[fuel]\nmodel = 'XX9'\n" + moisture),
                       doctest::Contains("'XX9' is not a model of the fuel table scott_burgan40"), InputError);
  CHECK_THROWS_WITH_AS(configure(rothermel + fuel), doctest::Contains("expected the fuel moistures"), InputError);
  CHECK_THROWS_WITH_AS(configure(rothermel + fuel + "[moisture]\ndead_1h = 0.06\ndead_10h = 0.07\ndead_100h = 0.08\nlive_herb = 0.6\nlive_woody = 0.9\n"),
                       doctest::Contains("[model.moisture] dead_1h: 0.06 looks like a fraction"), InputError);
  CHECK_THROWS_WITH_AS(configure(rothermel + fuel + moisture + "[wind]\ntype = 'uniform'\nspeed = 5.0\ndirection_deg = 0.0\nheight = '2m'\n"),
                       doctest::Contains("height"), InputError);

  // A fuel map holds the table's codes: one that is not in it names its cell.
  test::TempDir dir("fire_rothermel_settings");
  std::ofstream(dir / "fuel.asc") << "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 100\nNODATA_value -9999\n102 7\n";
  std::ofstream(dir / "fuels.csv") << "code,name,dynamic,load_1h[kg/m²],load_10h[kg/m²],load_100h[kg/m²],"
                                      "load_live_herb[kg/m²],load_live_woody[kg/m²],sav_1h[1/m],sav_live_herb[1/m],"
                                      "sav_live_woody[1/m],depth[m],extinction_moisture[%],heat_dead[kJ/kg],"
                                      "heat_live[kJ/kg]\n7,MINE,no,0.5,0,0,0,0,6000,0,0,0.3,25,18600,18600\n";
  const std::string map = fmt::format("map = '{}'\n", (dir / "fuel.asc").string());
  CHECK_THROWS_WITH_AS(configure(rothermel + "[fuel]\n" + map + moisture),
                       doctest::Contains("the fuel code 7 of the cell at row 1, column 2 is neither a code of the fuel table scott_burgan40"),
                       InputError);
  CHECK_NOTHROW(configure(rothermel + "[fuel]\n" + map + "non_burnable = [7]\n" + moisture));
  // A table of one's own in SI units: its code 7 burns, 102 is not in it.
  CHECK_THROWS_WITH_AS(configure(rothermel + "[fuel]\n" + map + fmt::format("table_file = '{}'\n", (dir / "fuels.csv").string()) + moisture),
                       doctest::Contains("the fuel code 102"), InputError);
  CHECK_THROWS_WITH_AS(configure(rothermel + "[fuel]\nmodel = 'MINE'\ntable = 'anderson13'\n" +
                                 fmt::format("table_file = '{}'\n", (dir / "fuels.csv").string()) + moisture),
                       doctest::Contains("give either fuel.table or fuel.table_file"), InputError);
  CHECK_NOTHROW(configure(rothermel + "[fuel]\nmodel = 'MINE'\n" + fmt::format("table_file = '{}'\n", (dir / "fuels.csv").string()) + moisture));
}

TEST_CASE("a point ignition on a uniform slope burns the exact ellipse of slope as effective wind") {
  // GR1 at D1L1 on a 30° plane, no wind: head upslope at R0 (1 + φ_s), the ellipse of the effective
  // wind. On the plane the surface's own coordinates (u upslope, y across) are those of flat ground,
  // in which the exact region is the ignition (a horizontal disk: an ellipse of semi-axes r0/cos α
  // upslope, r0 across) swept by the fire's ellipse.
  const double alpha = 30 * M_PI / 180, r0 = 50, ignition_x = -800;
  const fire::FuelModel gr1 = *fire::fuel_table("scott_burgan40").find("GR1");  // a copy: the table is a temporary
  fire::FuelMoisture moisture;
  REQUIRE(fire::moisture_scenario("D1L1", moisture));
  const fire::HeadSpread spread =
      fire::head_spread(fire::surface_fire(gr1, moisture), Vec3(0, 0, 0), Vec3(1, 0, 0), std::tan(alpha));
  REQUIRE(spread.length_to_width > 2);

  test::TempDir dir("fire_ellipse_slope");
  {
    std::ofstream dem(dir / "plane.asc");
    const int cells = 200;  // 12 m cells over [-1200, 1200]²
    dem << fmt::format("ncols {0}\nnrows {0}\nxllcorner -1200\nyllcorner -1200\ncellsize 12\nNODATA_value -9999\n", cells);
    for (int row = 0; row < cells; ++row) {
      for (int col = 0; col < cells; ++col) dem << fmt::format("{:.6f} ", (-1200 + 12 * (col + 0.5)) * std::tan(alpha));
      dem << "\n";
    }
  }
  std::ofstream(dir / "case.toml") << fmt::format(R"([surface]
generator = "terrain"
dem = "plane.asc"
h = 12.0
[region]
shape = "disks"
centers = [[{}, 0.0]]
radii = [{}]
[model]
name = "fire"
spread = "rothermel"
[model.fuel]
model = "GR1"
[model.moisture]
scenario = "D1L1"
[time]
dt = 300.0
max_cfl = 1.0
final_time = 10800.0
[discretize]
drop_detached = true
[remesh]
hmax = 12.0
hausd_interface = 0.5
[output]
vtu_every = 12
)",
                                                  ignition_x, r0);
  const auto result = test::run_bodyfit(fmt::format("run {} -o {}", (dir / "case.toml").string(), (dir / "out").string()));
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  const double a0 = r0 / std::cos(alpha);  // the ignition's semi-axis upslope, on the surface
  for (int hour = 1; hour <= 3; ++hour) {
    CAPTURE(hour);
    const double t = 3600.0 * hour;
    const SurfaceMesh mesh = read_vtu(dir / "out" / fmt::format("step_{:05d}.vtu", 12 * hour));
    const FireExtent e = front_extent(mesh);
    const double head = (e.head - ignition_x) / std::cos(alpha), back = (ignition_x - e.back) / std::cos(alpha);
    const double a = 0.5 * (spread.head + spread.back) * t, b = spread.flank * t;
    const double exact_area = minkowski_area(a0, r0, a, b);
    const double area = region_area(mesh, kInside);
    const std::string figures =
        fmt::format("head {:.1f} (exact {:.1f}), back {:.1f} ({:.1f}), flank {:.1f} ({:.1f}), area {:.0f} ({:.0f})", head,
                    a0 + spread.head * t, back, a0 + spread.back * t, e.flank, r0 + b, area, exact_area);
    INFO(figures);
    MESSAGE(figures);
    CHECK(std::abs(area / exact_area - 1) < 0.005);
    CHECK(std::abs(head / (a0 + spread.head * t) - 1) < 0.005);
    CHECK(std::abs(e.flank / (r0 + b) - 1) < 0.005);
    CHECK(std::abs(back / (a0 + spread.back * t) - 1) < 0.005);
  }
}
