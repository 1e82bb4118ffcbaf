// The plugin loader (search path, ABI check, each failure mode), the conormal plugin, the
// `bodyfit plugins` listing and the parameter reader models use.
#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/parameters.hpp>
#include <bodyfit/plugin_loader.hpp>
#include <bodyfit/projection.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>
#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
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
  CHECK(model->version() == "3.0");
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

TEST_CASE("bad parameters of a good plugin: an unknown key, a value out of the declared range") {
  LoadedModel model = load_model("testgood");
  std::string message = error_of([&] { configure_model(model, parse("valeu = 2.0")); });
  CHECK(contains(message, "unknown key 'valeu' in [model]; did you mean 'value'?"));
  message = error_of([&] { configure_model(model, parse("value = -1")); });
  CHECK(contains(message, "bodyfit_testgood.so: configure failed"));
  CHECK(contains(message, "value: -1 is out of range [0, inf)"));  // the declared range, not restated in configure
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
  CHECK(contains(message, "built against plugin ABI 1.0, this bodyfit needs 3.x"));
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
  CHECK(good->version == "3.0");
  CHECK(good->abi == kPluginAbi);
  REQUIRE(good->parameters.size() == 1);
  CHECK(good->parameters[0].key == "value");
  CHECK(good->parameters[0].default_text == "0.5");
  REQUIRE(good->outputs.size() == 1);
  CHECK(good->outputs[0].name == "state");
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

TEST_CASE("bodyfit plugins lists names, versions, ABI, files and failures") {
  auto result = test::run_bodyfit("plugins");
  CAPTURE(result.output);
  CHECK(result.exit_code == 0);
  CHECK(contains(result.output, "conormal 1.0  (ABI " + abi_string(kPluginAbi) + ")"));
  CHECK(contains(result.output, "bodyfit_conormal.so"));
  CHECK(contains(result.output, "testgood 3.0  (ABI " + abi_string(kPluginAbi) + ")"));
  CHECK(contains(result.output, "constant normal speed (test)"));
  CHECK(contains(result.output, "2 files failed to load"));
  CHECK(contains(result.output, "missing symbol 'bodyfit_destroy'"));
  CHECK(contains(result.output, BODYFIT_TEST_PLUGIN_DIR));
}

TEST_CASE("bodyfit plugins --describe: a model's parameters and outputs, as text or Markdown") {
  auto text = test::run_bodyfit("plugins --describe conormal");
  CAPTURE(text.output);
  REQUIRE(text.exit_code == 0);
  CHECK(contains(text.output, "conormal 1.0  (ABI " + abi_string(kPluginAbi) + ")"));
  CHECK(contains(text.output, "speed"));
  CHECK(contains(text.output, "default 1.0"));
  CHECK(contains(text.output, "period"));
  CHECK(contains(text.output, "[0, inf)"));  // the declared range
  CHECK(contains(text.output, "history column"));
  auto markdown = test::run_bodyfit("plugins --describe testgood --markdown");
  CAPTURE(markdown.output);
  REQUIRE(markdown.exit_code == 0);
  CHECK(contains(markdown.output, "## `testgood` 3.0"));
  CHECK(contains(markdown.output, "| `value` | number | length/time | 0.5 | [0, inf) | the normal speed |"));
  CHECK(contains(markdown.output, "| `state` | history column | 1 | the state's iteration |  |"));
  auto unknown = test::run_bodyfit("plugins --describe testgod");
  CHECK(unknown.exit_code == 1);
  CHECK(contains(unknown.output, "did you mean 'testgood'?"));
  CHECK(test::run_bodyfit("plugins --markdown").exit_code == 2);  // --markdown goes with --describe
}

TEST_CASE("conormal plugin: V = speed * conormal, tangential, unknown keys refused") {
  LoadedModel model = load_model("conormal");
  CHECK(model->name() == "conormal");
  auto params = model->parameters();
  REQUIRE(params.size() == 3);
  CHECK(params[0].key == "speed");
  CHECK(params[0].default_text == "1.0");
  CHECK(params[1].key == "period");  // the periodic mode: speed·cos(2πt/period + phase)
  CHECK(params[2].key == "phase");
  // A phase without a period takes no effect: refused, saying why.
  CHECK(contains(error_of([&] { configure_model(model, parse("phase = 90")); }),
                 "[model] phase is not used: it applies only with a period > 0"));
  CHECK_NOTHROW(configure_model(model, parse("phase = 90\nperiod = 2")));

  std::string message = error_of([&] { configure_model(model, parse("sped = 2")); });
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
  r.accept("speeed");
  CHECK_NOTHROW(r.reject_unknown());
}

// ---- declared parameters ---------------------------------------------------------------------------

namespace {
std::vector<ParameterDecl> declarations() {
  return {ParameterDecl::number("speed", "m/s", "a speed").fallback(2.0).at_least(0),
          ParameterDecl::number("length", "m", "a length").computed("twice the speed"),
          ParameterDecl::integer("count", "", "a count").fallback(3).within({.min = 1, .max = 10}),
          ParameterDecl::choice("mode", {"fast", "exact"}, "a mode").fallback("fast"),
          ParameterDecl::numbers("axis", 3, "", "an axis").fallback(std::vector<double>{0, 0, 1}),
          ParameterDecl::strings("names", "some names"),
          ParameterDecl::number("required", "", "needed").require(),
          ParameterDecl::choice("wind.type", {"none", "uniform"}, "the wind").fallback("none"),
          ParameterDecl::number("wind.speed", "m/s", "the wind's speed").fallback(0.0).at_least(0)};
}
std::string logic_error_of(auto&& action) {
  try {
    action();
  } catch (const std::logic_error& e) {
    return e.what();
  }
  return "(no logic_error thrown)";
}
}  // namespace

TEST_CASE("declared parameters: defaults, ranges and choices come from the declaration") {
  toml::table t = parse("required = 1\ncount = 7\nmode = \"exact\"\nnames = [\"a\", \"b\"]\n");
  Parameters p(t, declarations(), "model");
  CHECK(p.number("speed") == 2.0);            // declared default
  CHECK(p.number("length", 4.0) == 4.0);      // a default computed by the reader
  CHECK(p.integer("count") == 7);
  CHECK(p.choice("mode") == "exact");
  CHECK(p.numbers("axis") == std::vector<double>{0, 0, 1});
  CHECK(p.strings("names") == std::vector<std::string>{"a", "b"});
  CHECK(p.number("required") == 1);
  CHECK_NOTHROW(p.check_consumed());

  toml::table bad = parse("speed = -1\ncount = 11\nmode = \"exakt\"\naxis = [1, 2]\n");
  Parameters q(bad, declarations(), "model");
  CHECK(contains(error_of([&] { q.number("speed"); }), "[model] speed: -1 is out of range [0, inf)"));
  CHECK(contains(error_of([&] { q.integer("count"); }), "[model] count: 11 is out of range [1, 10]"));
  CHECK(contains(error_of([&] { q.choice("mode"); }), "'exakt' is not one of fast, exact; did you mean 'exact'?"));
  CHECK(contains(error_of([&] { q.numbers("axis"); }), "axis: expected 3 numbers, got 2"));
  CHECK(contains(error_of([&] { q.number("required"); }), "[model] required: required"));
  CHECK(contains(error_of([&] { q.number("length", 0.0); }), "(no InputError thrown)"));  // absent: the fallback
}

TEST_CASE("declared parameters: a key read but not declared, or as another type, is the model's error") {
  toml::table t = parse("speed = 1\n");
  Parameters p(t, declarations(), "model");
  CHECK(contains(logic_error_of([&] { p.number("sped"); }), "[model] sped: read, but not declared"));
  CHECK(contains(logic_error_of([&] { p.string("speed", ""); }), "read as another type than its declaration (number)"));
  CHECK(contains(logic_error_of([&] { p.section("speed"); }), "no parameter is declared in it"));
  CHECK(contains(logic_error_of([&] { p.not_used("sped", "why"); }), "not declared"));
}

TEST_CASE("declared parameters: every key set is read, or refused saying why") {
  // Read: nothing left.
  toml::table all = parse("required = 1\n[wind]\ntype = \"uniform\"\nspeed = 3\n");
  Parameters p(all, declarations(), "model");
  p.number("required");
  Parameters& wind = p.section("wind");
  CHECK(wind.section() == "model.wind");
  CHECK(wind.choice("type") == "uniform");
  CHECK(wind.number("speed") == 3);
  CHECK_NOTHROW(p.check_consumed());
  CHECK(p.consumed() == std::vector<std::string>{"required", "wind.type", "wind.speed"});

  // A declared key the settings do not use: refused, with the model's reason or a plain one.
  toml::table unused = parse("required = 1\nlength = 2\n[wind]\nspeed = 3\n");
  Parameters q(unused, declarations(), "model");
  q.number("required");
  q.not_used("length", "it is computed from the speed here");
  CHECK(contains(error_of([&] { q.check_consumed(); }), "line 2: [model] length is not used: it is computed from the speed here"));
  q.number("length", 0.0);
  Parameters& calm = q.section("wind");
  calm.choice("type");  // "none": the speed is not read
  CHECK(contains(error_of([&] { q.check_consumed(); }), "[model.wind] speed is set but not used with these settings"));

  // An unknown key, in a section too: a suggestion among the declared keys.
  toml::table typo = parse("required = 1\n[wind]\nsped = 3\n");
  Parameters r(typo, declarations(), "model");
  r.number("required");
  r.section("wind").choice("type");
  CHECK(contains(error_of([&] { r.check_consumed(); }), "unknown key 'sped' in [model.wind]; did you mean 'speed'?"));
}

TEST_CASE("plugin ABI: features by version, one compatibility rule") {
  CHECK(abi_compatible(kPluginAbi));
  CHECK(abi_compatible((kPluginAbiMajor << 16) | 0));
  CHECK_FALSE(abi_compatible(((kPluginAbiMajor + 1) << 16)));
  CHECK_FALSE(abi_compatible((kPluginAbiMajor << 16) | (kPluginAbiMinor + 1)));
  CHECK_FALSE(abi_compatible(2u << 16 | 5));
  CHECK(plugin_has(kPluginAbi, kAbiDeclaredParameters));
  CHECK_FALSE(plugin_has(2u << 16 | 5, kAbiDeclaredOutputs));
  constexpr AbiFeature later{kPluginAbiMajor, kPluginAbiMinor + 1, "a later feature"};
  CHECK_FALSE(plugin_has(kPluginAbi, later));
  CHECK(abi_string(kPluginAbi) == fmt::format("{}.{}", kPluginAbiMajor, kPluginAbiMinor));
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

TEST_CASE("plugin files are checked before they are loaded, and probed in a child: a truncated, foreign or "
          "crashing plugin is a failure named, never a signal death of bodyfit") {
  test::TempDir dir("plugins_unsafe");
  const std::string good = test::read_file(std::filesystem::path(BODYFIT_TEST_PLUGIN_DIR) / "bodyfit_testgood.so");
  REQUIRE(good.size() > 8192);
  auto write = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(dir / name, std::ios::binary) << bytes;
    return dir / name;
  };
  // Truncated at several places (a copy interrupted; the dynamic loader died of SIGBUS mapping
  // past the end), an ELF header alone, another word size, text.
  for (std::size_t keep : {std::size_t(64), std::size_t(4096), good.size() / 2, good.size() - 1}) {
    CAPTURE(keep);
    const auto file = write("bodyfit_cut.so", good.substr(0, keep));
    const std::string message = error_of([&] { load_plugin_file(file); });
    const bool named = contains(message, "bodyfit_cut.so: cannot load plugin: a ") && contains(message, "ELF file");
    CHECK_MESSAGE(named, message);
  }
  std::string elf32 = good;
  elf32[4] = 1;  // ELFCLASS32
  CHECK(contains(error_of([&] { load_plugin_file(write("bodyfit_elf32.so", elf32)); }), "another word size"));
  CHECK(contains(error_of([&] { load_plugin_file(write("bodyfit_text.so", "#!/bin/sh\n")); }), "not an ELF"));

  // `bodyfit plugins` over a directory of them, with a plugin whose constructor crashes or exits:
  // each is listed as a failure, the good ones as plugins, and the listing ends normally.
  for (const char* how : {"segv", "exit"}) {
    CAPTURE(how);
    ::setenv("BODYFIT_PLUGIN_PATH", (dir.path().string() + ":" + BODYFIT_TEST_PLUGIN_DIR).c_str(), 1);
    ::setenv("BODYFIT_TESTFAULT_CREATE", how, 1);
    auto listing = test::run_bodyfit("plugins");
    auto run = test::run_bodyfit("run " + test::source_path("meshes/cases/sphere_cap.toml").string() + " -o " +
                                 (dir / "out").string() + " --set model.name=\\\"testfault\\\"");
    ::unsetenv("BODYFIT_TESTFAULT_CREATE");
    ::setenv("BODYFIT_PLUGIN_PATH", BODYFIT_TEST_PLUGIN_DIR, 1);
    CHECK_MESSAGE(listing.exit_code == 0, listing.output);
    CHECK(contains(listing.output, "testgood 3.0"));
    CHECK(contains(listing.output, "bodyfit_cut.so: cannot load plugin: a truncated ELF file"));
    CHECK(contains(listing.output, "bodyfit_text.so: cannot load plugin: not an ELF"));
    CHECK(contains(listing.output, std::string(how) == "segv" ? "bodyfit_testfault.so: crashed while being loaded"
                                                              : "bodyfit_testfault.so: ended the process while being "
                                                                "loaded (exit status 4"));
    // A run of it: the crash or exit is named, with the plugin's file, and nothing is written.
    CHECK(run.exit_code == (std::string(how) == "segv" ? 128 + 11 : 4));
    CHECK_MESSAGE(contains(run.output, std::string("model 'bodyfit_testfault.so' ") +
                                           (std::string(how) == "segv" ? "crashed (SIGSEGV)" : "called exit()") +
                                           " in bodyfit_create"),
                  run.output);
    CHECK(contains(run.output, "before the run wrote anything"));
    CHECK_FALSE(std::filesystem::exists(dir / "out"));
  }
}
