// No drift (issue 14): a cap oscillating along its conormal comes back to its area every period,
// and the deformational flow of Nair & Lauritzen (2010) brings two caps back to where they started
// (docs/validation/drift.md, docs/validation/nair_lauritzen.md).
#include <bodyfit/case_config.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/plugin_loader.hpp>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

using namespace bodyfit;

namespace {

// Bounds from the measurements (docs/validation/drift.md, nair_lauritzen.md), with margin. Measured
// at h = 0.06 after the fix: largest |area/exact − 1| over the steps 1.24e-2 (the polygon's chord
// deficit when the cap is smallest), |G| against the exact cap after 1 and 2 periods −6.7e-4 and
// +2.3e-4; before it −1.2e-2 and −2.4e-2. Nair & Lauritzen (k = 1, h = 0.08): Hausdorff 0.194,
// area error +0.259.
constexpr double DRIFT_STEP_BOUND = 0.016, DRIFT_PERIOD_BOUND = 0.003, DRIFT_PER_PERIOD_BOUND = 0.0025;
constexpr double NL_HAUSDORFF_BOUND = 0.25, NL_AREA_BOUND = 0.35;

constexpr double kPi = std::numbers::pi;

struct Outcome {
  CaseSetup setup;
  EvolutionResult result;
  std::vector<IterationRecord> records;
};

Outcome run(const std::string& text) {
  CaseConfig config = parse_case(toml::parse(text));
  LoadedModel model = load_model(config.model);
  configure_model(model, config.model_parameters);
  Outcome out{setup_case(config), {}, {}};
  out.result = evolve(out.setup.mesh, model.model(), out.setup.options, {}, EvolutionHooks::quiet());
  return out;
}

}  // namespace

TEST_CASE("an oscillating cap keeps its area: h = 0.06, two periods of 200 steps") {
  // a(t) = π/4 + (1.5/π) sin(2πt/6): the cap goes from 0.31 to 1.26 rad and back each period.
  const Outcome o = run(R"(
[surface]
generator = "sphere"
h = 0.06
[region]
shape = "cap"
axis = [0, 0, 1]
angle = 45
[model]
name = "conormal"
speed = 0.5
period = 6.0
[time]
dt = 0.03
final_time = 12.0
[remesh]
hmax = 0.06
)");
  REQUIRE(o.result.reason == StopReason::FinalTime);
  const auto& records = o.result.records;
  REQUIRE(records.size() == 400);
  const double initial = 2 * kPi * (1 - std::cos(kPi / 4));
  double worst = 0;
  for (const auto& r : records) {
    // The exact cap at every step, within the polygon's own chord deficit and a margin.
    const double a = kPi / 4 + 1.5 / kPi * std::sin(2 * kPi * r.time / 6);
    worst = std::max(worst, std::abs(r.area / (2 * kPi * (1 - std::cos(a))) - 1));
  }
  MESSAGE("oscillating cap, h = 0.06: largest |area / exact - 1| over the steps " << worst);
  CHECK(worst < DRIFT_STEP_BOUND);
  const double period1 = records[199].area / initial - 1, period2 = records[399].area / initial - 1;
  MESSAGE("oscillating cap, h = 0.06: |G| after 1 and 2 periods against the exact cap: " << period1 << ", " << period2);
  CHECK(std::abs(period1) < DRIFT_PERIOD_BOUND);
  CHECK(std::abs(period2) < DRIFT_PERIOD_BOUND);
  CHECK(std::abs(period2 - period1) < DRIFT_PER_PERIOD_BOUND);
}

TEST_CASE("Nair & Lauritzen case 4 with k = 1 at h = 0.08: the two caps come back at T") {
  // The paper's k = 2.4 stretches the caps into filaments far thinner than this mesh resolves (the
  // area at T is then 2.6 times the initial one: docs/validation/nair_lauritzen.md); k = 1 keeps
  // them resolved from h = 0.08 on.
  const double radius = 0.4;
  const std::string text = R"(
[surface]
generator = "sphere"
h = 0.08
[region]
shape = "cap"
axes = [[-0.8660254037844387, 0.5, 0.0], [-0.8660254037844387, -0.5, 0.0]]
angles = [22.918311805232928, 22.918311805232928]
[model]
name = "prescribed"
flow = "nair_lauritzen"
case = 4
period = 5.0
k = 1.0
[time]
cfl = 0.5
final_time = 5.0
[remesh]
hmax = 0.08
)";
  Outcome o = run(text);
  REQUIRE(o.result.reason == StopReason::FinalTime);
  Segments exact;
  for (double lon : {5 * kPi / 6, 7 * kPi / 6}) {
    const Vec3 axis(std::cos(lon), std::sin(lon), 0), e1(0, 0, 1), e2 = cross(axis, e1);
    auto point = [&](int k) {
      const double s = 2 * kPi * k / 2000;
      return std::cos(radius) * axis + std::sin(radius) * (std::cos(s) * e1 + std::sin(s) * e2);
    };
    for (int k = 0; k < 2000; ++k) exact.emplace_back(point(k), point(k + 1));
  }
  const double hausdorff = hausdorff_distance(interface_segments(o.setup.mesh), exact);
  const double area_error = region_area(o.setup.mesh, kInside) / (4 * kPi * (1 - std::cos(radius))) - 1;
  MESSAGE("Nair & Lauritzen case 4, k = 1, h = 0.08: Hausdorff " << hausdorff << ", area error " << area_error);
  CHECK(o.result.records.back().components == 2);
  CHECK(hausdorff < NL_HAUSDORFF_BOUND);
  CHECK(std::abs(area_error) < NL_AREA_BOUND);
}
