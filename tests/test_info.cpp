// `bodyfit info`: the figures it prints for meshes whose answers are known exactly.
#include "test_support.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>

using bodyfit::test::run_bodyfit;
using bodyfit::test::TempDir;

namespace {

// The number after `"key": ` (the first occurrence after `from`, if given; for a list, its first).
double json_value(const std::string& json, const std::string& key, const std::string& from = "") {
  std::size_t start = from.empty() ? 0 : json.find("\"" + from + "\"");
  REQUIRE(start != std::string::npos);
  auto at = json.find("\"" + key + "\": ", start);
  REQUIRE_MESSAGE(at != std::string::npos, key);
  at += key.size() + 4;
  if (json[at] == '[') ++at;
  return std::strtod(json.c_str() + at, nullptr);
}

std::string info_json(const std::filesystem::path& mesh) {
  auto r = run_bodyfit("info --json '" + mesh.string() + "'");
  REQUIRE(r.exit_code == 0);
  return r.output;
}

}  // namespace

TEST_CASE("info: a sphere is one closed component of Euler characteristic 2 and area about 4 pi R^2") {
  TempDir dir("info_sphere");
  auto file = dir / "s.mesh";
  REQUIRE(run_bodyfit("mesh sphere --faces 2420 --radius 2 -o '" + file.string() + "'").exit_code == 0);
  auto json = info_json(file);
  CHECK(json_value(json, "faces") == 2420);
  CHECK(json_value(json, "vertices") == 1212);
  CHECK(json_value(json, "edges") == 3630);
  CHECK(json_value(json, "euler_characteristic") == 2);
  CHECK(json_value(json, "components") == 1);
  CHECK(json_value(json, "count", "boundary_loops") == 0);
  const double area = json_value(json, "area");
  CHECK(area < 16 * M_PI);
  CHECK(area > 0.99 * 16 * M_PI);
  CHECK(json_value(json, "min", "quality") >= 0.7);
  // The box's corners are not on the sphere: its diagonal is at most 2R√3, and close to it.
  CHECK(json_value(json, "diagonal") <= 4 * std::sqrt(3.0));
  CHECK(json_value(json, "diagonal") > 0.99 * 4 * std::sqrt(3.0));
  CHECK(json_value(json, "edges", "interface") == 0);
}

TEST_CASE("info: a flat terrain is a disc bounded by one loop of length 4 extent") {
  TempDir dir("info_terrain");
  auto file = dir / "t.mesh";
  REQUIRE(run_bodyfit("mesh terrain --extent 10000 --h 500 --seed 3 --max-height 0 -o '" + file.string() + "'")
              .exit_code == 0);
  auto json = info_json(file);
  CHECK(json_value(json, "euler_characteristic") == 1);
  CHECK(json_value(json, "components") == 1);
  CHECK(json_value(json, "count", "boundary_loops") == 1);
  CHECK(json_value(json, "lengths", "boundary_loops") == doctest::Approx(40000).epsilon(1e-12));
  CHECK(json_value(json, "area") == doctest::Approx(1e8).epsilon(1e-12));
  CHECK(json_value(json, "corners") == 4);

  // With relief the boundary is longer than the square's perimeter but there is still one loop.
  auto hilly = dir / "h.mesh";
  REQUIRE(run_bodyfit("mesh terrain --extent 10000 --h 500 --seed 3 -o '" + hilly.string() + "'").exit_code == 0);
  auto hj = info_json(hilly);
  CHECK(json_value(hj, "count", "boundary_loops") == 1);
  CHECK(json_value(hj, "lengths", "boundary_loops") > 40000);
  CHECK(json_value(hj, "euler_characteristic") == 1);
}

TEST_CASE("info: regions, interface and boundary of a hand-made strip") {
  TempDir dir("info_strip");
  // [0, 2] × [0, 1]: left unit square inside G (ref 3), right one outside (ref 2), the segment
  // x = 1 between them is the interface (ref 10).
  auto file = dir / "strip.mesh";
  std::ofstream(file) << "MeshVersionFormatted 2\nDimension 3\n"
                         "Vertices\n6\n0 0 0 0\n1 0 0 0\n2 0 0 0\n0 1 0 0\n1 1 0 0\n2 1 0 0\n"
                         "Triangles\n4\n1 2 5 3\n1 5 4 3\n2 3 6 2\n2 6 5 2\n"
                         "Edges\n1\n2 5 10\nEnd\n";
  auto json = info_json(file);
  CHECK(json_value(json, "vertices") == 6);
  CHECK(json_value(json, "faces") == 4);
  CHECK(json_value(json, "edges") == 9);
  CHECK(json_value(json, "euler_characteristic") == 1);
  CHECK(json_value(json, "count", "boundary_loops") == 1);
  CHECK(json_value(json, "lengths", "boundary_loops") == doctest::Approx(6));
  CHECK(json_value(json, "length", "interface") == doctest::Approx(1));
  CHECK(json_value(json, "open_curves", "interface") == 1);
  CHECK(json_value(json, "closed_curves", "interface") == 0);
  const auto regions = json.substr(json.find("\"regions\""));
  CHECK(regions.find("{\"ref\": 2, \"faces\": 2, \"area\": 1}") != std::string::npos);
  CHECK(regions.find("{\"ref\": 3, \"faces\": 2, \"area\": 1}") != std::string::npos);

  auto text = run_bodyfit("info '" + file.string() + "'");
  CHECK(text.exit_code == 0);
  CHECK(text.output.find("region 3") != std::string::npos);
  CHECK(text.output.find("Euler characteristic 1") != std::string::npos);
}

TEST_CASE("info: unreadable input is a one-line error with exit code 1") {
  TempDir dir("info_bad");
  auto missing = run_bodyfit("info '" + (dir / "missing.mesh").string() + "'");
  CHECK(missing.exit_code == 1);
  CHECK(missing.output.find("missing.mesh") != std::string::npos);
  auto bad = dir / "bad.mesh";
  std::ofstream(bad) << "MeshVersionFormatted 2\nDimension 3\nVertices\n3\n0 0 0 0\n1 0 0\n";
  auto r = run_bodyfit("info '" + bad.string() + "'");
  CHECK(r.exit_code == 1);
  CHECK(r.output.find("bad.mesh") != std::string::npos);
  CHECK(std::count(r.output.begin(), r.output.end(), '\n') <= 1);
}

TEST_CASE("info: a terrain from the DEM fixture covers the raster's extent with one boundary loop") {
  TempDir dir("info_dem");
  auto file = dir / "hill.mesh";
  const auto dem = bodyfit::test::source_path("meshes/dem/hill.asc");
  auto made = run_bodyfit("mesh terrain --dem '" + dem.string() + "' -o '" + file.string() + "'");
  REQUIRE(made.exit_code == 0);
  auto json = info_json(file);
  CHECK(json_value(json, "euler_characteristic") == 1);
  CHECK(json_value(json, "components") == 1);
  CHECK(json_value(json, "count", "boundary_loops") == 1);
  CHECK(json_value(json, "corners") == 4);
  // x ∈ [500000, 503000], y ∈ [4000000, 4002000] (30 × 20 cells of 100 m); heights within the raster's.
  const auto box = json.substr(json.find("\"bounding_box\""));
  CHECK(box.find("\"min\": [500000, 4000000, ") != std::string::npos);
  CHECK(box.find("\"max\": [503000, 4002000, ") != std::string::npos);
  CHECK(json_value(json, "mean", "edge_length") == doctest::Approx(100).epsilon(0.1));

  auto missing = run_bodyfit("mesh terrain --dem '" + (dir / "none.asc").string() + "' -o '" + file.string() + "'");
  CHECK(missing.exit_code == 1);
  CHECK(missing.output.find("none.asc") != std::string::npos);
}

TEST_CASE("command line: MMG's -hmax spellings work as in mmgs, usage errors exit 2") {
  bodyfit::test::TempDir dir("cli_mmg");
  const std::string sphere = (dir / "s.mesh").string();
  REQUIRE(bodyfit::test::run_bodyfit("mesh sphere --faces 320 -o " + sphere).exit_code == 0);
  // Read by CLI11 as -h -m -a -x, this used to print the help and exit 0 without writing anything.
  auto mmg = bodyfit::test::run_bodyfit("remesh " + sphere + " -hmax 0.3 -hausd 0.01 -o " + (dir / "r.mesh").string());
  CHECK_MESSAGE(mmg.exit_code == 0, mmg.output);
  CHECK(std::filesystem::exists(dir / "r.mesh"));
  auto unknown = bodyfit::test::run_bodyfit("remesh " + sphere + " --hmaxx 0.3 -o " + (dir / "x.mesh").string());
  CHECK(unknown.exit_code == 2);
  CHECK_FALSE(std::filesystem::exists(dir / "x.mesh"));
  CHECK(bodyfit::test::run_bodyfit("remesh --help").exit_code == 0);
}

TEST_CASE("--threads: the same final mesh, byte for byte, with 1 and 2 worker threads") {
  bodyfit::test::TempDir dir("threads");
  const std::string run = "run " + bodyfit::test::source_path("meshes/cases/sphere_cap.toml").string() +
                          " --set surface.h=0.03 --set remesh.hmax=0.03 --set time.iterations=4 "
                          "--set output.vtu_every=0 --set output.png_every=0 -o ";
  auto one = bodyfit::test::run_bodyfit("--threads 1 " + run + (dir / "one").string());
  REQUIRE_MESSAGE(one.exit_code == 0, one.output);
  auto two = bodyfit::test::run_bodyfit("--threads 2 " + run + (dir / "two").string());
  REQUIRE_MESSAGE(two.exit_code == 0, two.output);
  CHECK(bodyfit::test::read_file(dir / "one" / "final.mesh") == bodyfit::test::read_file(dir / "two" / "final.mesh"));
  CHECK(bodyfit::test::read_file(dir / "one" / "final.sol") == bodyfit::test::read_file(dir / "two" / "final.sol"));
  CHECK(bodyfit::test::run_bodyfit("--threads -1 mesh sphere --faces 320 -o " + (dir / "x.mesh").string()).exit_code == 2);
}

TEST_CASE("one-shot commands restart on huge pages unless GLIBC_TUNABLES names the choice, with the same bytes out") {
  TempDir dir("huge_pages");
  std::string mode;
  std::getline(std::ifstream("/sys/kernel/mm/transparent_hugepage/enabled"), mode);
  const bool available = !mode.empty() && mode.find("[never]") == std::string::npos;
  const auto sphere = dir / "s.mesh";
  REQUIRE(run_bodyfit("-q mesh sphere --faces 2000 -o '" + sphere.string() + "'").exit_code == 0);
  const char* before = std::getenv("GLIBC_TUNABLES");
  const std::string saved = before ? before : "";
  auto remesh = [&](const char* tunables, const std::string& out) {
    if (tunables) ::setenv("GLIBC_TUNABLES", tunables, 1);
    else ::unsetenv("GLIBC_TUNABLES");
    auto r = run_bodyfit("-v remesh '" + sphere.string() + "' --hmax 0.15 -o '" + (dir / out).string() + "'");
    CHECK(r.exit_code == 0);
    return r.output.find("heap on transparent huge pages") != std::string::npos;
  };
  CHECK(remesh(nullptr, "default.mesh") == available);
  CHECK(remesh("glibc.malloc.arena_max=4", "other.mesh") == available);  // the user's tunables kept, ours added
  CHECK_FALSE(remesh("glibc.malloc.hugetlb=0", "off.mesh"));
  if (before) ::setenv("GLIBC_TUNABLES", saved.c_str(), 1);
  else ::unsetenv("GLIBC_TUNABLES");
  const std::string reference = bodyfit::test::read_file(dir / "off.mesh");
  CHECK_FALSE(reference.empty());
  CHECK(bodyfit::test::read_file(dir / "default.mesh") == reference);
  CHECK(bodyfit::test::read_file(dir / "other.mesh") == reference);
}
