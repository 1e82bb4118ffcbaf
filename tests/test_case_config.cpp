// The TOML case: validation messages (unknown keys with suggestions, missing keys, wrong types),
// --set overrides, and the analytic initial regions.
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/parameters.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <string>

using namespace bodyfit;

namespace {

const char* kValidCase = R"(
[surface]
generator = "sphere"
faces = 320

[region]
shape = "cap"
axis = [0, 0, 1]
angle = 45

[model]
name = "conormal"
speed = 2.0

[time]
cfl = 0.5
final_time = 0.78

[remesh]
hmax = 0.2
)";

CaseConfig parse(const std::string& text, const std::vector<std::string>& overrides = {}) {
  toml::table table = toml::parse(text);
  for (const auto& o : overrides) apply_override(table, o);
  return parse_case(table);
}

std::string error_of(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    parse(text, overrides);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

}  // namespace

TEST_CASE("a valid case is read into its options") {
  CaseConfig c = parse(kValidCase);
  CHECK(c.surface.kind == SurfaceSpec::Kind::Sphere);
  CHECK(c.surface.sphere.faces == 320);
  CHECK(c.region.kind == RegionSpec::Kind::Cap);
  CHECK(c.region.angle == 45);
  CHECK(c.model == "conormal");
  CHECK(c.model_parameters["speed"].value<double>() == 2.0);
  CHECK(!c.model_parameters.contains("name"));
  CHECK(c.time.cfl == 0.5);
  CHECK(c.time.dt == 0);
  CHECK(c.time.final_time == 0.78);
  CHECK(c.time.iterations == -1);
  CHECK(c.time.max_cfl == 0);  // no sub-steps unless asked for
  CHECK(parse(kValidCase, {"time.max_cfl=4"}).time.max_cfl == 4);
  CHECK(c.remesh.hmax == 0.2);
  CHECK(c.remesh.hausd_interface == 0);  // the interface's tolerance is hausd unless given
  CHECK(parse(kValidCase, {"remesh.hausd_interface=0.001"}).remesh.hausd_interface == 0.001);
  CHECK_FALSE(c.discretize.drop_detached);  // new parts are kept unless asked
  CHECK(parse(kValidCase, {"discretize.drop_detached=true"}).discretize.drop_detached);
  CHECK(c.output.vtu_every == 1);
}

TEST_CASE("unknown keys and tables are errors with a suggestion") {
  std::string text = kValidCase;
  text.replace(text.find("final_time"), 10, "final_tiem");
  std::string e = error_of(text);
  CHECK_MESSAGE(contains(e, "unknown key 'final_tiem' in [time]"), e);
  CHECK_MESSAGE(contains(e, "did you mean 'final_time'?"), e);

  e = error_of(std::string(kValidCase) + "\n[remsh]\nhmin = 1\n");
  CHECK_MESSAGE(contains(e, "unknown table [remsh]"), e);
  CHECK_MESSAGE(contains(e, "did you mean 'remesh'?"), e);

  e = error_of(kValidCase, {"remesh.hgard=1.5"});
  CHECK_MESSAGE(contains(e, "unknown key 'hgard' in [remesh]; did you mean 'hgrad'?"), e);

  // Nothing close: no suggestion.
  e = error_of(kValidCase, {"output.zzzzzzzzzz=1"});
  CHECK_MESSAGE(contains(e, "unknown key 'zzzzzzzzzz' in [output]"), e);
  CHECK_MESSAGE(!contains(e, "did you mean"), e);

  // A bad choice suggests the closest valid value.
  e = error_of(kValidCase, {"region.shape=cpa"});
  CHECK_MESSAGE(contains(e, "did you mean 'cap'"), e);
}

TEST_CASE("missing required keys are named") {
  std::string text = kValidCase;
  text.replace(text.find("name = \"conormal\""), 17, "");
  std::string e = error_of(text);
  CHECK_MESSAGE(contains(e, "[model] missing key 'name'"), e);

  text = kValidCase;
  text.replace(text.find("cfl = 0.5"), 9, "");
  e = error_of(text);
  CHECK_MESSAGE(contains(e, "[time] give exactly one of 'dt' and 'cfl'"), e);

  text = kValidCase;
  text.replace(text.find("final_time = 0.78"), 17, "");
  e = error_of(text);
  CHECK_MESSAGE(contains(e, "'final_time' or 'iterations'"), e);

  text = kValidCase;
  text.replace(text.find("angle = 45"), 10, "");
  e = error_of(text);
  CHECK_MESSAGE(contains(e, "missing key 'angle'"), e);

  e = error_of("[model]\nname = \"x\"\n");
  CHECK_MESSAGE(contains(e, "missing table [surface]"), e);
}

TEST_CASE("wrong types and values are errors naming the key") {
  std::string e = error_of(kValidCase, {"time.final_time=\"soon\""});
  CHECK_MESSAGE(contains(e, "[time] final_time: expected a number"), e);
  e = error_of(kValidCase, {"output.vtu_every=1.5"});
  CHECK_MESSAGE(contains(e, "[output] vtu_every: expected an integer"), e);
  e = error_of(kValidCase, {"remesh.hmax=-1"});
  CHECK_MESSAGE(contains(e, "[remesh] hmax: -1 is out of range (0, inf)"), e);
  e = error_of(kValidCase, {"remesh.hausd_interface=0"});
  CHECK_MESSAGE(contains(e, "[remesh] hausd_interface: 0 is out of range (0, inf)"), e);
  e = error_of(kValidCase, {"discretize.drop_detached=1"});
  CHECK_MESSAGE(contains(e, "[discretize] drop_detached: expected"), e);
  e = error_of(kValidCase, {"region.axis=[1, 2]"});
  CHECK_MESSAGE(contains(e, "[region] axis: expected 3 numbers, got 2"), e);
  e = error_of(kValidCase, {"surface.extent=5"});
  CHECK_MESSAGE(contains(e, "extent: does not apply to generator 'sphere'"), e);
  e = error_of(kValidCase, {"time.dt=0.1"});
  CHECK_MESSAGE(contains(e, "exactly one of 'dt' and 'cfl'"), e);
  e = error_of(kValidCase, {"time.max_cfl=0"});
  CHECK_MESSAGE(contains(e, "[time] max_cfl: 0 is out of range (0, inf)"), e);
  e = error_of(kValidCase, {"time.max_cf=2"});
  CHECK_MESSAGE(contains(e, "unknown key 'max_cf' in [time]; did you mean 'max_cfl'?"), e);
  e = error_of(kValidCase, {"region.angle=180"});
  CHECK_MESSAGE(contains(e, "[region] angle: must be in (0, 180) degrees (got 180)"), e);
  e = error_of(kValidCase, {"advection.rk_order=3"});
  CHECK_MESSAGE(contains(e, "[advection] rk_order: must be 2 or 4 (got 3)"), e);
  e = error_of(kValidCase, {"remesh.hmin=0.5"});
  CHECK_MESSAGE(contains(e, "[remesh] hmin: 0.5 must not exceed hmax = 0.2"), e);
  // A value written in the text is located by its line.
  std::string text = kValidCase;
  text.replace(text.find("hmax = 0.2"), 10, "hmax = \"big\"");
  e = error_of(text);
  CHECK_MESSAGE(contains(e, "line 20: [remesh] hmax: expected a number, got a string"), e);
}

TEST_CASE("[surface] nodata and reproject: with a dem only, hole and none by default") {
  // A procedural terrain has no NODATA and nothing to reproject.
  std::string e = error_of(kValidCase, {"surface.nodata=\"fill\""});
  CHECK_MESSAGE(contains(e, "nodata: does not apply to generator 'sphere'"), e);
  toml::table table = toml::parse(kValidCase);
  table.insert_or_assign("surface", toml::table{{"generator", "terrain"}, {"h", 100.0}, {"nodata", "fill"}});
  e = "no error";
  try {
    parse_case(table);
  } catch (const InputError& error) {
    e = error.what();
  }
  CHECK_MESSAGE(contains(e, "nodata: does not apply to a procedural terrain (no 'dem')"), e);
  // With a dem: the defaults, the alternatives, and a choice outside them.
  table.insert_or_assign("surface", toml::table{{"generator", "terrain"}, {"dem", "d.asc"}});
  CaseConfig c = parse_case(table);
  CHECK(c.surface.nodata == NodataMode::hole);
  CHECK(c.surface.reproject == Reprojection::none);
  table.insert_or_assign("surface", toml::table{{"generator", "terrain"}, {"dem", "d.asc"}, {"nodata", "fill"}, {"reproject", "utm"}});
  c = parse_case(table);
  CHECK(c.surface.nodata == NodataMode::fill);
  CHECK(c.surface.reproject == Reprojection::utm);
  table.insert_or_assign("surface", toml::table{{"generator", "terrain"}, {"dem", "d.asc"}, {"nodata", "zero"}});
  CHECK_THROWS_WITH_AS(parse_case(table), doctest::Contains("nodata"), InputError);
}

TEST_CASE("[time] max_rejections: an integer >= 0, default 5") {
  CHECK(parse(kValidCase).time.max_rejections == 5);
  CHECK(parse(kValidCase, {"time.max_rejections=2"}).time.max_rejections == 2);
  CHECK(parse(kValidCase, {"time.max_rejections=0"}).time.max_rejections == 0);
  std::string e = error_of(kValidCase, {"time.max_rejections=-1"});
  CHECK_MESSAGE(contains(e, "[time] max_rejections: -1 is out of range [0, inf)"), e);
  e = error_of(kValidCase, {"time.max_rejections=2.5"});
  CHECK_MESSAGE(contains(e, "[time] max_rejections: expected an integer, got a float"), e);
  e = error_of(kValidCase, {"time.max_rejection=3"});
  CHECK_MESSAGE(contains(e, "unknown key 'max_rejection' in [time]; did you mean 'max_rejections'?"), e);
  // The sub-steps' composition: off unless asked (EvolutionOptions::compose_substeps).
  CHECK_FALSE(parse(kValidCase).time.compose_substeps);
  CHECK(parse(kValidCase, {"time.compose_substeps=true"}).time.compose_substeps);
}

TEST_CASE("--set overrides any key with a dotted path, typed as TOML") {
  CaseConfig c = parse(kValidCase, {"time.cfl=0.25", "model.speed=3", "output.view=top", "time.iterations=7",
                                    "output.size=[320, 200]", "distance.narrow_band=0.5"});
  CHECK(c.time.cfl == 0.25);
  CHECK(c.model_parameters["speed"].value<double>() == 3.0);
  CHECK(c.output.view == "top");  // a bare word is a string
  CHECK(c.time.iterations == 7);
  CHECK(c.output.width == 320);
  CHECK(c.output.height == 200);
  CHECK(c.distance.narrow_band == 0.5);  // a table absent from the file is created
  // The effective table carries the overrides (it becomes outdir/case.toml).
  CHECK(c.effective["time"]["cfl"].value<double>() == 0.25);
  CHECK(contains(error_of(kValidCase, {"time.cfl"}), "expected key=value"));
  CHECK(contains(error_of(kValidCase, {"model.name.x=1"}), "'name' is not a table"));
}

TEST_CASE("every example case of meshes/cases is valid") {
  for (const char* name : {"sphere_cap", "plane_disk", "plane_boundary", "two_caps_merge"}) {
    CAPTURE(name);
    CaseConfig c = read_case(test::source_path(std::string("meshes/cases/") + name + ".toml"));
    CHECK(c.model == "conormal");
  }
  // An error in a file names the file.
  test::TempDir dir("case-config");
  {
    std::ofstream out(dir / "bad.toml");
    out << kValidCase << "\n[time]\n";  // duplicate table: a TOML syntax error
  }
  try {
    read_case(dir / "bad.toml");
    FAIL("expected an error");
  } catch (const InputError& e) {
    CHECK(contains(e.what(), "bad.toml:"));
  }
  // A bad value names the file and its line, once; a bad --set value names the file.
  {
    std::string text = kValidCase;
    text.replace(text.find("final_time = 0.78"), 17, "final_time = -1.0");
    std::ofstream out(dir / "negative.toml");
    out << text;
  }
  const std::string file = (dir / "negative.toml").string();
  try {
    read_case(dir / "negative.toml");
    FAIL("expected an error");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) == file + ":17: [time] final_time: -1 is out of range (0, inf)");
  }
  try {
    read_case(dir / "negative.toml", {"time.final_time=1.0", "time.iterations=-2"});
    FAIL("expected an error");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) == file + ": [time] iterations: -2 is out of range [0, inf)");
  }
}

TEST_CASE("the plane generator covers the square with good triangles") {
  CaseConfig c = parse(R"(
[surface]
generator = "plane"
size = 2.0
h = 0.1
[region]
shape = "disks"
centers = [[0.0, 0.0], [0.5, 0.5]]
radii = [0.3, 0.1]
[model]
name = "conormal"
[time]
dt = 0.1
iterations = 1
)");
  SurfaceMesh plane = make_case_surface(c);
  CHECK(total_area(plane) == doctest::Approx(4.0).epsilon(1e-12));
  // Near-equilateral rows; the half cells at the row ends are the worst triangles.
  CHECK(quality_stats(plane).min > 0.5);
  CHECK(quality_stats(plane).mean > 0.9);
  CHECK(boundary_loops(plane).size() == 1);
  CHECK(euler_characteristic(plane) == 1);
  CHECK(edge_length_stats(plane).mean == doctest::Approx(0.1).epsilon(0.1));
  // Disks: horizontal distance to the nearest circle.
  ScalarField phi = initial_level_set(c, plane);
  for (auto v : plane.vertices()) {
    const Vec3& p = plane.point(v);
    double expected = std::min(std::hypot(p[0], p[1]) - 0.3, std::hypot(p[0] - 0.5, p[1] - 0.5) - 0.1);
    CHECK(phi[v.idx()] == doctest::Approx(expected).epsilon(1e-12));
  }
}

TEST_CASE("a cap's level set is the exact geodesic distance on the sphere") {
  CaseConfig c = parse(kValidCase, {"surface.radius=2.0", "region.angle=30"});
  SurfaceMesh sphere = make_case_surface(c);
  ScalarField phi = initial_level_set(c, sphere);
  for (auto v : sphere.vertices()) {
    const Vec3& p = sphere.point(v);
    double beta = std::acos(std::clamp(p[2] / p.norm(), -1.0, 1.0));
    CHECK(phi[v.idx()] == doctest::Approx(2.0 * (beta - std::numbers::pi / 6)).epsilon(1e-9));
  }
  // A union of caps: the min of the two distances.
  CaseConfig two = parse(R"(
[surface]
generator = "sphere"
faces = 320
[region]
shape = "cap"
axes = [[0, 0, 1], [0, 0, -1]]
angles = [30, 60]
[model]
name = "conormal"
[time]
dt = 0.1
iterations = 1
)");
  phi = initial_level_set(two, sphere);
  for (auto v : sphere.vertices()) {
    const Vec3& p = sphere.point(v);
    double beta = std::acos(std::clamp(p[2] / p.norm(), -1.0, 1.0));
    // (the sphere has radius 2)
    double expected = 2.0 * std::min(beta - std::numbers::pi / 6, (std::numbers::pi - beta) - std::numbers::pi / 3);
    CHECK(phi[v.idx()] == doctest::Approx(expected).epsilon(1e-9));
  }
}

TEST_CASE("file names resolve against the case file, --set values against the working directory (Parameters::path, "
          "[surface], [region])") {
  namespace fs = std::filesystem;
  test::TempDir dir("case_paths");
  fs::create_directories(dir / "cases");
  {
    std::ofstream out(dir / "cases" / "c.toml");
    std::string text = kValidCase;
    const std::string speed = "speed = 2.0\n";
    text.replace(text.find(speed), speed.size(),
                 speed + "grid = \"maps/fuel.asc\"\nup = \"../dem.asc\"\nabsolute = \"/data/x.asc\"\n"
                         "wind = { u_file = \"u.asc\" }\n");
    out << text;
  }
  const fs::path cases = fs::absolute(dir / "cases");
  // Read from another working directory, through a relative name of the case file.
  const auto previous = fs::current_path();
  fs::current_path(dir.path());
  CaseConfig c = read_case(fs::path("cases") / "c.toml", {"model.override=\"o.asc\""});
  Parameters p(c.model_parameters, "model");
  CHECK(p.path("grid") == cases / "maps" / "fuel.asc");
  CHECK(p.path("up") == dir.path() / "dem.asc");
  CHECK(p.path("absolute") == fs::path("/data/x.asc"));
  CHECK(p.path("override") == fs::absolute(dir.path()) / "o.asc");  // --set: the working directory
  CHECK(p.path("absent", "default.asc") == fs::path("default.asc"));
  CHECK(p.path("absent").empty());
  Parameters wind(*p.table("wind"), "model.wind");
  CHECK(wind.path("u_file") == cases / "u.asc");  // nested tables keep their source too
  // A table parsed from a string has no file: its names are relative to the working directory.
  toml::table text = toml::parse("f = \"a/b.asc\"");
  CHECK(Parameters(text).path("f") == fs::absolute(dir.path()) / "a" / "b.asc");
  // The engine's own file names ([surface] file and dem, [region] sol and file) follow the same
  // rule: the case file's directory, or the working directory for a --set value. (A --set
  // surface.dem was resolved against the case file's directory: another DEM was used silently.)
  {
    std::string text = kValidCase;
    const std::string generator = "generator = \"sphere\"\nfaces = 320\n";
    REQUIRE(text.find(generator) != std::string::npos);
    text.replace(text.find(generator), generator.size(), "file = \"part.mesh\"\n");
    std::ofstream(dir / "cases" / "f.toml") << text;
  }
  CaseConfig own = read_case(fs::path("cases") / "f.toml", {});
  CaseConfig set = read_case(fs::path("cases") / "f.toml", {"surface.file=\"here.mesh\""});
  CHECK(own.surface.file == cases / "part.mesh");
  CHECK(set.surface.file == fs::absolute(dir.path()) / "here.mesh");
  fs::current_path(previous);
  // Not a string: the usual typed error.
  toml::table wrong = toml::parse("f = 3");
  CHECK_THROWS_AS(Parameters(wrong).path("f"), InputError);
}

TEST_CASE("terrains: ridge detection is off unless [remesh] angle is given, and the remesher then keeps quality") {
  const std::string terrain = R"(
[surface]
generator = "terrain"
extent = 20000.0
h = 400.0
seed = 7
max_height = 3000.0
feature_size = 3000.0

[region]
shape = "disks"
centers = [[10000.0, 10000.0]]
radii = [2000.0]

[model]
name = "conormal"

[time]
dt = 60.0
iterations = 1

[remesh]
hmax = 400.0
)";
  const CaseSetup off = setup_case(parse(terrain));
  CHECK(off.options.remesh.feature_angle == 0);
  const CaseSetup given = setup_case(parse(terrain, {"remesh.angle=45.0"}));
  CHECK(given.options.remesh.feature_angle == 45);
  // On this steep landscape the 45° ridges freeze the remesh: worse triangles with them (since the
  // sliver repair none falls below 0.3 either way, so compare the worst and the mean).
  auto share_good = [](const SurfaceMesh& mesh) {
    std::size_t good = 0;
    for (auto f : mesh.faces()) good += face_quality(mesh, f) >= 0.3;
    return double(good) / double(mesh.n_faces());
  };
  const auto q_off = quality_stats(off.mesh), q_given = quality_stats(given.mesh);
  MESSAGE("quality min / mean: ridges off " << q_off.min << " / " << q_off.mean << ", 45° ridges " << q_given.min << " / " << q_given.mean);
  CHECK(q_off.min > q_given.min);
  CHECK(q_off.mean > q_given.mean);
  CHECK(share_good(off.mesh) > 0.99);
  // Spheres keep the default.
  CHECK(setup_case(parse(kValidCase)).options.remesh.feature_angle == 45);
}

TEST_CASE("balls: the Euclidean distance to the nearest sphere, bad balls are errors") {
  const char* text = R"(
[surface]
generator = "sphere"
faces = 320
[region]
shape = "balls"
centers = [[0, 0, 1], [1, 0, 0]]
radii = [0.5, 0.25]
[model]
name = "conormal"
[time]
dt = 0.1
iterations = 1
)";
  CaseConfig c = parse(text);
  CHECK(c.region.kind == RegionSpec::Kind::Balls);
  SurfaceMesh sphere = make_case_surface(c);
  ScalarField phi = initial_level_set(c, sphere);
  for (auto v : sphere.vertices()) {
    const Vec3& p = sphere.point(v);
    const double expected = std::min((p - Vec3(0, 0, 1)).norm() - 0.5, (p - Vec3(1, 0, 0)).norm() - 0.25);
    CHECK(phi[v.idx()] == doctest::Approx(expected).epsilon(1e-12));
  }
  CHECK_THROWS_WITH_AS(parse(text, {"region.radii=[0.5]"}), doctest::Contains("2 centres but 1 radii"), InputError);
  CHECK_THROWS_WITH_AS(parse(text, {"region.centers=[[0, 0], [1, 0]]"}), doctest::Contains("centers"), InputError);
  CHECK_THROWS_WITH_AS(parse(text, {"region.radii=[0.5, -1]"}), doctest::Contains("radii"), InputError);
}
