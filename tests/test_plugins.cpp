// The plugin loader (search path, ABI check, each failure mode), the conormal plugin, the
// `bodyfit plugins` listing and the parameter reader models use.
#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/parameters.hpp>
#include <bodyfit/plugin_loader.hpp>
#include <bodyfit/projection.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <string>

using namespace bodyfit;

namespace {

/// Search the test plugins first (set once for the whole executable, children inherit it).
const bool plugin_path_set = [] {
  ::setenv("BODYFIT_PLUGIN_PATH", BODYFIT_TEST_PLUGIN_DIR, 1);
  return true;
}();

std::string error_of(auto&& action) {
  try {
    action();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError thrown)";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

toml::table parse(std::string_view text) { return toml::parse(text); }

}  // namespace

TEST_CASE("search path: BODYFIT_PLUGIN_PATH entries first, then the build and install directories") {
  REQUIRE(plugin_path_set);
  ::setenv("BODYFIT_PLUGIN_PATH", (std::string("/nonexistent/a::") + BODYFIT_TEST_PLUGIN_DIR).c_str(), 1);
  auto dirs = plugin_search_path();
  ::setenv("BODYFIT_PLUGIN_PATH", BODYFIT_TEST_PLUGIN_DIR, 1);
  REQUIRE(dirs.size() >= 3);
  CHECK(dirs[0] == "/nonexistent/a");
  CHECK(dirs[1] == BODYFIT_TEST_PLUGIN_DIR);  // the empty entry is skipped
  CHECK(dirs[2] == BODYFIT_PLUGIN_DIR);
}

TEST_CASE("a good plugin loads, configures and computes") {
  LoadedModel model = load_model("testgood");
  CHECK(model->name() == "testgood");
  CHECK(model->version() == "2.5");
  CHECK(model.abi() == kPluginAbi);
  CHECK(model.file().filename() == "bodyfit_testgood.so");
  configure_model(model, parse("value = 2.0"));

  SurfaceMesh sphere = make_sphere({.faces = 320});
  ScalarField d(sphere.n_vertices(), 0.0);
  StandaloneStep where;
  where.iteration = 4;
  StepContext context = StepContext::standalone(sphere, d, where);
  VelocityField v = model->compute(context);
  CHECK(v.kind == VelocityField::Kind::NormalSpeed);
  REQUIRE(v.normal_speed.size() == sphere.n_vertices());
  for (double s : v.normal_speed) CHECK(s == 2.0);
  REQUIRE(v.metrics.size() == 1);
  CHECK(v.metrics[0].second == 4.0);

  // Moving keeps the model alive; the moved-from object owns nothing.
  LoadedModel moved = std::move(model);
  CHECK(moved->name() == "testgood");
  CHECK(model.file().empty());
}

TEST_CASE("a plugin given by its path loads the same") {
  LoadedModel model = load_model(std::string(BODYFIT_TEST_PLUGIN_DIR) + "/bodyfit_testgood.so");
  CHECK(model->name() == "testgood");
}

TEST_CASE("bad parameters of a good plugin: configure failed, naming the file and the key") {
  LoadedModel model = load_model("testgood");
  std::string message = error_of([&] { configure_model(model, parse("valeu = 2.0")); });
  CHECK(contains(message, "bodyfit_testgood.so: configure failed: "));
  CHECK(contains(message, "unknown key 'valeu' in [model]; did you mean 'value'?"));
  message = error_of([&] { configure_model(model, parse("value = -1")); });
  CHECK(contains(message, "configure failed"));
  CHECK(contains(message, "value: -1 is out of range [0, inf)"));
}

TEST_CASE("a plugin missing a symbol is refused, naming the file and the symbol") {
  std::string message = error_of([] { load_model("testnosymbol"); });
  CHECK(contains(message, "bodyfit_testnosymbol.so: "));
  CHECK(contains(message, "missing symbol 'bodyfit_destroy'"));
}

TEST_CASE("a plugin of another ABI is refused before anything else is called") {
  // Its bodyfit_create would abort the process.
  std::string message = error_of([] { load_model("testwrongabi"); });
  CHECK(contains(message, "bodyfit_testwrongabi.so: "));
  CHECK(contains(message, "built against plugin ABI 1.0, this bodyfit needs 2.x"));
  CHECK(contains(message, "rebuild it"));
}

TEST_CASE("a plugin whose configure throws gives 'configure failed' with its reason") {
  LoadedModel model = load_model("testthrowing");
  std::string message = error_of([&] { configure_model(model, toml::table{}); });
  CHECK(contains(message, "bodyfit_testthrowing.so: configure failed: the answer must be 42"));
}

TEST_CASE("unknown model names and missing files") {
  std::string message = error_of([] { load_model("testgod"); });
  CHECK(contains(message, "unknown velocity model 'testgod'"));
  CHECK(contains(message, "no bodyfit_testgod.so in " + std::string(BODYFIT_TEST_PLUGIN_DIR)));
  CHECK(contains(message, "did you mean 'testgood'?"));
  CHECK(contains(message, "available: "));
  CHECK(contains(message, "conormal"));

  message = error_of([] { load_model("/nonexistent/bodyfit_x.so"); });
  CHECK(message == "/nonexistent/bodyfit_x.so: no such plugin file");

  test::TempDir dir("plugins_not_elf");
  {
    std::FILE* f = std::fopen((dir / "bodyfit_junk.so").c_str(), "w");
    REQUIRE(f);
    std::fputs("not a shared object", f);
    std::fclose(f);
  }
  message = error_of([&] { load_plugin_file(dir / "bodyfit_junk.so"); });
  CHECK(contains(message, "bodyfit_junk.so: cannot load plugin: "));
}

TEST_CASE("discover_plugins lists the loadable plugins and reports the others") {
  std::vector<std::string> failures;
  auto plugins = discover_plugins(&failures);
  auto find = [&](const std::string& name) -> const PluginInfo* {
    for (const auto& p : plugins)
      if (p.name == name) return &p;
    return nullptr;
  };
  const PluginInfo* good = find("testgood");
  REQUIRE(good);
  CHECK(good->version == "2.5");
  CHECK(good->abi == kPluginAbi);
  REQUIRE(good->parameters.size() == 1);
  CHECK(good->parameters[0].name == "value");
  CHECK(good->parameters[0].default_value == "0.5");
  CHECK(find("testthrowing"));  // it loads; only its configure fails
  const PluginInfo* conormal = find("conormal");
  REQUIRE(conormal);
  CHECK(conormal->file.parent_path() == BODYFIT_PLUGIN_DIR);
  CHECK_FALSE(find("testnosymbol"));
  CHECK_FALSE(find("testwrongabi"));
  REQUIRE(failures.size() == 2);
  CHECK(contains(failures[0] + failures[1], "bodyfit_testnosymbol.so: not a bodyfit plugin: missing symbol"));
  CHECK(contains(failures[0] + failures[1], "bodyfit_testwrongabi.so: built against plugin ABI 1.0"));
}

TEST_CASE("bodyfit plugins lists names, versions, ABI, files, parameters and failures") {
  auto result = test::run_bodyfit("plugins");
  CAPTURE(result.output);
  CHECK(result.exit_code == 0);
  CHECK(contains(result.output, "conormal 1.0  (ABI 2.5)"));
  CHECK(contains(result.output, "bodyfit_conormal.so"));
  CHECK(contains(result.output, "speed = 1"));
  CHECK(contains(result.output, "testgood 2.5  (ABI 2.5)"));
  CHECK(contains(result.output, "value = 0.5"));
  CHECK(contains(result.output, "constant normal speed (test)"));
  CHECK(contains(result.output, "2 files failed to load"));
  CHECK(contains(result.output, "missing symbol 'bodyfit_destroy'"));
  CHECK(contains(result.output, BODYFIT_TEST_PLUGIN_DIR));
}

TEST_CASE("conormal plugin: V = speed * conormal, tangential, unknown keys refused") {
  LoadedModel model = load_model("conormal");
  CHECK(model->name() == "conormal");
  auto params = model->parameters();
  REQUIRE(params.size() == 3);
  CHECK(params[0].name == "speed");
  CHECK(params[0].default_value == "1");
  CHECK(params[1].name == "period");  // the periodic mode (issue 14): speed·cos(2πt/period + phase)
  CHECK(params[2].name == "phase");
  CHECK(contains(error_of([&] { configure_model(model, parse("phase = 90")); }), "applies only with a period > 0"));

  std::string message = error_of([&] { configure_model(model, parse("sped = 2")); });
  CHECK(contains(message, "bodyfit_conormal.so: configure failed: "));
  CHECK(contains(message, "unknown key 'sped' in [model]; did you mean 'speed'?"));
  message = error_of([&] { configure_model(model, parse("speed = 'fast'")); });
  CHECK(contains(message, "speed: expected a number, got a string"));

  configure_model(model, parse("speed = 2.5"));
  SurfaceMesh sphere = make_sphere({.faces = 1280});
  ScalarField d(sphere.n_vertices());
  for (auto v : sphere.vertices()) d[v.idx()] = std::acos(std::clamp(sphere.point(v)[2], -1.0, 1.0)) - 1.0;
  StepContext context = StepContext::standalone(sphere, d);
  VelocityField v = model->compute(context);
  CHECK(v.kind == VelocityField::Kind::Tangential);
  REQUIRE(v.vector.size() == sphere.n_vertices());
  const VectorField& n = context.conormal();
  for (std::size_t i = 0; i < n.size(); ++i) CHECK((v.vector[i] - 2.5 * n[i]).norm() < 1e-15);
  // |V| = speed where the conormal is defined (everywhere but at the poles of this cap).
  std::size_t unit = 0;
  for (const auto& x : v.vector) unit += std::abs(x.norm() - 2.5) < 1e-12;
  CHECK(unit + 2 >= v.vector.size());
}

// ---- parameters.hpp --------------------------------------------------------------------------------

TEST_CASE("parameters: typed getters with defaults") {
  toml::table t = parse(R"(
    a = 1.5
    n = 3
    i = 7
    flag = true
    mode = "exact"
    xs = [1, 2.5, 3]
    [sub]
    k = 1
  )");
  Parameters p(t, "model");
  CHECK(p.number("a", 0.0) == 1.5);
  CHECK(p.number("n", 0.0) == 3.0);  // an integer is a number
  CHECK(p.number("absent", 4.25) == 4.25);
  CHECK(p.integer("i", 0, 0, 10) == 7);
  CHECK(p.boolean("flag", false));
  CHECK(p.choice("mode", "fast", {"fast", "exact"}) == "exact");
  CHECK(p.numbers("xs", {}, 3) == std::vector<double>{1, 2.5, 3});
  REQUIRE(p.table("sub"));
  CHECK(p.string("name", "none") == "none");
  CHECK_NOTHROW(p.reject_unknown());
}

TEST_CASE("parameters: unknown key with a suggestion, or the list of known keys") {
  toml::table t = parse("speeed = 2\n");
  Parameters p(t, "model");
  p.number("speed", 1.0);
  p.number("length", 1.0);
  CHECK(contains(error_of([&] { p.reject_unknown(); }), "unknown key 'speeed' in [model]; did you mean 'speed'?"));

  toml::table far = parse("zzz = 2\n");
  Parameters q(far, "fire");
  q.number("speed", 1.0);
  std::string message = error_of([&] { q.reject_unknown(); });
  CHECK(contains(message, "unknown key 'zzz' in [fire]"));
  CHECK_FALSE(contains(message, "did you mean"));
  CHECK(contains(message, "known keys: speed"));

  Parameters r(t, "model");
  r.accept(std::vector<ParameterInfo>{{"speeed", "1", ""}});
  CHECK_NOTHROW(r.reject_unknown());
}

TEST_CASE("parameters: wrong types, out of range, required, bad choices") {
  toml::table t = parse(R"(
    s = "fast"
    x = -0.5
    i = 2.5
    b = 1
    xs = [1, 2]
    mode = "exakt"
  )");
  Parameters p(t, "model");
  CHECK(contains(error_of([&] { p.number("s", 0.0); }), "[model] s: expected a number, got a string"));
  CHECK(contains(error_of([&] { p.number("x", 0.0, {.min = 0}); }), "[model] x: -0.5 is out of range [0, inf)"));
  CHECK(contains(error_of([&] { p.number("x", 0.0, {.min = -0.5, .min_exclusive = true}); }),
                 "is out of range (-0.5, inf)"));
  CHECK(p.number("x", 0.0, {.min = -0.5, .max = 1}) == -0.5);
  CHECK(contains(error_of([&] { p.integer("i", 0); }), "i: expected an integer, got a float"));
  CHECK(contains(error_of([&] { p.boolean("b", false); }), "b: expected true or false, got an integer"));
  CHECK(contains(error_of([&] { p.numbers("xs", {}, 3); }), "xs: expected 3 numbers, got 2"));
  CHECK(contains(error_of([&] { p.required_number("missing"); }), "[model] missing: required"));
  CHECK(contains(error_of([&] { p.choice("mode", "fast", {"fast", "exact"}); }),
                 "'exakt' is not one of fast, exact; did you mean 'exact'?"));
  // Errors carry the line of the offending value in the TOML text.
  CHECK(contains(error_of([&] { p.number("s", 0.0); }), "2: [model] s"));
}

TEST_CASE("edit distance and closest match") {
  CHECK(edit_distance("kitten", "sitting") == 3);
  CHECK(edit_distance("", "abc") == 3);
  CHECK(edit_distance("same", "same") == 0);
  CHECK(closest_match("sped", {"speed", "length"}) == "speed");
  CHECK(closest_match("qqqqqq", {"speed", "length"}).empty());
}

TEST_CASE("StepContext::surface_normals: S's smooth normal at the vertices, the vertex normals without S or on S") {
  const SurfaceMesh coarse = make_sphere({.faces = 320});
  const ReferenceSurface surface(coarse);
  const SurfaceMesh fine = make_sphere({.faces = 1280});  // its vertices on the exact sphere, not on S
  const ScalarField d_fine(fine.n_vertices(), 0.0), d_coarse(coarse.n_vertices(), 0.0);
  StandaloneStep where;
  where.surface = &surface;
  const StepContext on_fine = StepContext::standalone(fine, d_fine, where);
  const VectorField& normals = on_fine.surface_normals();
  REQUIRE(normals.size() == fine.n_vertices());
  double farthest = 0;
  for (auto v : fine.vertices()) {
    CHECK((normals[v.idx()] - surface.smooth_normal(fine.point(v))).norm() < 1e-12);
    farthest = std::max(farthest, (normals[v.idx()] - on_fine.vertex_normals()[v.idx()]).norm());
  }
  CHECK(farthest > 1e-3);  // S's field, not the fine mesh's own normals
  // On S itself: S's vertex normals. Without S: the mesh's.
  const StepContext on_coarse = StepContext::standalone(coarse, d_coarse, where);
  for (auto v : coarse.vertices())
    CHECK((on_coarse.surface_normals()[v.idx()] - on_coarse.vertex_normals()[v.idx()]).norm() < 1e-12);
  const StepContext without = StepContext::standalone(fine, d_fine);
  CHECK(without.surface_normals() == without.vertex_normals());
}
