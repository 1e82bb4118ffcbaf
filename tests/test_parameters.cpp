// bodyfit::Parameters beyond what the plugins use (those are in test_plugins.cpp): optional
// tables, arrays of points, keys that do not apply, checks of several keys, located messages.
#include <bodyfit/error.hpp>
#include <bodyfit/parameters.hpp>

#include <doctest/doctest.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <string>

using namespace bodyfit;

namespace {

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

}  // namespace

TEST_CASE("parameters: an absent table reads as empty") {
  Parameters p(nullptr, "distance");
  CHECK(p.number("narrow_band", 3.0) == 3.0);
  CHECK(p.number_arrays("centers", 2).empty());
  CHECK_NOTHROW(p.reject_unknown());
  CHECK(error_of([&] { p.fail("give 'x'"); }) == "[distance] give 'x'");
}

TEST_CASE("parameters: arrays of points") {
  toml::table t = toml::parse(R"(
    centers = [[0, 1.5], [2, 3]]
    flat = [1, 2]
    short = [[1, 2], [3]]
    words = [[1, "a"]]
  )");
  Parameters p(t, "region");
  auto centers = p.number_arrays("centers", 2);
  REQUIRE(centers.size() == 2);
  CHECK(centers[0] == std::vector<double>{0, 1.5});
  CHECK(centers[1] == std::vector<double>{2, 3});
  CHECK(contains(error_of([&] { p.number_arrays("centers", 2, {.min = 1}); }),
                 "line 2: [region] centers: item 1: 0 is out of range [1, inf)"));
  CHECK(contains(error_of([&] { p.number_arrays("flat", 2); }),
                 "line 3: [region] flat: item 1: expected an array of 2 numbers, got an integer"));
  CHECK(contains(error_of([&] { p.number_arrays("short", 2); }), "[region] short: item 2: expected 2 numbers, got 1"));
  CHECK(contains(error_of([&] { p.number_arrays("words", 2); }),
                 "[region] words: item 1: expected 2 numbers, found a string in it"));
}

TEST_CASE("parameters: keys that do not apply, checks of several keys, located messages") {
  toml::table t = toml::parse(R"(
    generator = "sphere"
    extent = 5

    [time]
    dt = 1
  )");
  Parameters p(t, "surface");
  CHECK(p.choice("generator", "sphere", {"sphere", "plane"}) == "sphere");
  // A forbidden key is named with its line, and is not a known key for the suggestions.
  CHECK(error_of([&] { p.forbid({"faces", "extent"}, "to generator 'sphere'"); }) ==
        "line 3: [surface] extent: does not apply to generator 'sphere'");
  CHECK(error_of([&] { p.fail("extent", "must not exceed the radius"); }) ==
        "line 3: [surface] extent: must not exceed the radius");
  Parameters time(t["time"].as_table(), "time");
  CHECK(error_of([&] { time.fail("give 'final_time' or 'iterations'"); }) ==
        "line 5: [time] give 'final_time' or 'iterations'");
  // Integer ranges show the open ends as infinite.
  CHECK(error_of([&] { time.integer("dt", 0, 2); }) == "line 6: [time] dt: 1 is out of range [2, inf)");
  CHECK(error_of([&] { time.integer("dt", 0, std::numeric_limits<std::int64_t>::min(), 0); }) ==
        "line 6: [time] dt: 1 is out of range (-inf, 0]");
  // Values without a source (set in code, or by --set) have no location.
  toml::table set;
  set.insert("dt", -1.0);
  CHECK(error_of([&] { Parameters(set, "time").number("dt", 0, {.min = 0, .min_exclusive = true}); }) ==
        "[time] dt: -1 is out of range (0, inf)");
  CHECK(location_of(*t.get("extent")) == "line 3: ");
}
