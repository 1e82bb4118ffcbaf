// Every case shipped in meshes/cases is taken whole: its model reads every key of [model] with the
// case's settings (nothing set is silently ignored), and an ensemble case's members too.
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/app/ensemble.hpp>
#include <bodyfit/app/run.hpp>
#include <bodyfit/error.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

using namespace bodyfit;
namespace fs = std::filesystem;

TEST_CASE("every shipped case's model reads all its keys") {
  std::vector<fs::path> cases;
  for (const auto& entry : fs::directory_iterator(fs::path(BODYFIT_SOURCE_DIR) / "meshes" / "cases"))
    if (entry.path().extension() == ".toml") cases.push_back(entry.path());
  std::sort(cases.begin(), cases.end());
  REQUIRE(cases.size() >= 10);
  for (const fs::path& file : cases) {
    CAPTURE(file.string());
    const CaseConfig config = read_case(file);
    if (config.model == "thermal" && !fs::exists(fs::path(BODYFIT_PLUGIN_DIR) / "bodyfit_thermal.so")) continue;
    CHECK_NOTHROW(load_case_model(config));
  }
}

TEST_CASE("the shipped ensemble's members sample only keys their model reads") {
  const fs::path file = fs::path(BODYFIT_SOURCE_DIR) / "meshes" / "cases" / "fire_luxembourg_ensemble.toml";
  EnsembleRun run;
  run.case_file = file;
  run.spec = read_ensemble_spec(file, {});
  REQUIRE_FALSE(run.spec.parameters.empty());
  run.domain = make_placement_domain(file, {}, run.spec);
  CHECK_NOTHROW(check_member_case(run));
  CHECK(run.model == "fire");
  REQUIRE(run.combined.size() == 2);  // the arrival time and the rate of spread
  CHECK(run.combined[0].name == "arrival_time");
  CHECK(run.combined[1].name == "rate_of_spread");
  // A key the model does not read with these settings (R0 comes from the fuel classes here) is refused.
  test::TempDir dir("shipped_ensemble_r0");
  // The case with its data files named absolutely, and R0 sampled.
  const std::string dem = fmt::format("\"{}/", (fs::path(BODYFIT_SOURCE_DIR) / "meshes" / "dem").string());
  std::string text = test::read_file(file);
  for (std::size_t at = text.find("\"../dem/"); at != std::string::npos; at = text.find("\"../dem/", at))
    text.replace(at, 8, dem);
  text += "\"model.R0\" = {dist = \"uniform\", min = 0.3, max = 0.5}\n";  // [ensemble.sample] is the last table
  std::ofstream(dir / "case.toml") << text;
  run = EnsembleRun{};
  run.case_file = dir / "case.toml";
  run.spec = read_ensemble_spec(run.case_file, {});
  run.domain = make_placement_domain(run.case_file, {}, run.spec);
  CHECK_THROWS_WITH_AS(check_member_case(run),
                       doctest::Contains("R0 is not used: R0 is set per fuel class by [model.fuel] presets"), InputError);
}
