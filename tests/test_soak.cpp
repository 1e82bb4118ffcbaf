// The soak of issue 14, short: two overlapping caps go in and out once per period (conormal model
// with a periodic speed, bench/soak_case.hpp), splitting and merging twice per period, for a few
// hundred iterations at a coarse size. |G| stays near the exact solution, the triangles stay good,
// the face count and the resident memory do not grow. bench_soak runs the long version
// (docs/validation/drift.md).
#include "../bench/soak_case.hpp"

#include <bodyfit/case_config.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/plugin_loader.hpp>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

using namespace bodyfit;

// Bounds from this test's figures (docs/validation/drift.md), with margin. Measured: largest
// |area/exact − 1| 0.196 (|G| grows from period to period where the caps merge: a known defect,
// see the docs), worst quality 0.404, no triangle below 0.3, faces 2816..3138, 17 splits/merges,
// RSS 38.7 MiB after the first period and at most 39.2 MiB after.
constexpr double SOAK_AREA_BOUND = 0.25, SOAK_QUALITY_FLOOR = 0.3, SOAK_SHARE_BOUND = 0.005, SOAK_FACES_RATIO = 1.25,
                 SOAK_RSS_MARGIN = 8;

TEST_CASE("soak (short): two caps split and merge for 400 iterations with bounded area error, quality, faces and memory") {
  soak::SoakCase c;
  c.h = 0.1;
  c.period = 4;  // Δt = 0.05: 80 steps per period, 5 periods
  c.iterations = 400;
  const soak::ExactArea exact(c);
  CaseConfig config = parse_case(toml::parse(c.toml()));
  LoadedModel model = load_model(config.model);
  configure_model(model, config.model_parameters);
  CaseSetup setup = setup_case(config);
  double worst_error = 0, worst_quality = 1, worst_share = 0, rss_after_first_period = 0, rss_max = 0;
  std::size_t faces_min = SIZE_MAX, faces_max = 0;
  int changes = 0, components = 0;
  const long first_period = std::lround(c.period / setup.options.dt);
  EvolutionHooks hooks = EvolutionHooks::quiet();
  hooks.on_iteration = [&](const SurfaceMesh& mesh, const IterationRecord& r, const RunState&) {
    const double error = r.area / exact.at(r.time) - 1;  // NaN on the way out (no exact value)
    if (std::isfinite(error)) worst_error = std::max(worst_error, std::abs(error));
    worst_quality = std::min(worst_quality, r.min_quality);
    worst_share = std::max(worst_share, soak::share_below(mesh, 0.3));
    faces_min = std::min(faces_min, r.faces), faces_max = std::max(faces_max, r.faces);
    if (components != 0 && r.components != components) ++changes;
    components = r.components;
    if (r.iteration == first_period) rss_after_first_period = soak::rss_mib();
    if (r.iteration > first_period) rss_max = std::max(rss_max, soak::rss_mib());
  };
  const EvolutionResult result = evolve(setup.mesh, model.model(), setup.options, {}, hooks);
  MESSAGE("soak h = 0.1, " << result.iteration << " iterations: max |area error| " << worst_error << ", worst quality "
                           << worst_quality << ", max share below 0.3 " << worst_share << ", faces " << faces_min
                           << ".." << faces_max << ", " << changes << " splits/merges, RSS " << rss_after_first_period
                           << " -> max " << rss_max << " MiB");
  CHECK(result.iteration == c.iterations);
  CHECK(changes >= 8);  // 2 per period, 5 periods (the last merge may fall after the end)
  CHECK(worst_error < SOAK_AREA_BOUND);
  CHECK(worst_quality > SOAK_QUALITY_FLOOR);
  CHECK(worst_share < SOAK_SHARE_BOUND);
  CHECK(double(faces_max) < SOAK_FACES_RATIO * double(faces_min));
  CHECK(rss_max < rss_after_first_period + SOAK_RSS_MARGIN);
}
