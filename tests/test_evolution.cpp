// The evolution loop against exact solutions: the paper's growing cap on the unit sphere (§4.2),
// a disk growing on a plane, an interface meeting the boundary, the merge of two caps, and
// `bodyfit run` (outputs, --resume gives the same final mesh as an uninterrupted run).
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/plugin_loader.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <sstream>

using namespace bodyfit;

namespace {

constexpr double kPi = std::numbers::pi;

struct Outcome {
  CaseSetup setup;
  EvolutionResult result;
};

Outcome run(const std::string& case_text, const std::vector<std::string>& overrides = {}) {
  toml::table table = toml::parse(case_text);
  for (const auto& o : overrides) apply_override(table, o);
  CaseConfig config = parse_case(table);
  LoadedModel model = load_model(config.model);
  configure_model(model, config.model_parameters);
  Outcome out{setup_case(config), {}};
  out.result = evolve(out.setup.mesh, model.model(), out.setup.options, {}, EvolutionHooks::quiet());
  return out;
}

/// E of (4.5): the L² norm over the mesh of d_h − (β − T − a), with the edge-midpoint rule (exact
/// for quadratics on each flat triangle; β evaluated at the midpoint's direction).
double cap_error(const SurfaceMesh& mesh, const ScalarField& d, double final_angle) {
  return l2_difference(mesh, d, [&](const Vec3& m) {
    return std::acos(std::clamp(m[2] / m.norm(), -1.0, 1.0)) - final_angle;
  });
}

const char* kCap = R"(
[surface]
generator = "sphere"
h = 0.1
[region]
shape = "cap"
axis = [0, 0, 1]
angle = 45
[model]
name = "conormal"
[time]
cfl = 0.5
final_time = 0.7853981633974483
[remesh]
hmax = 0.1
)";

const char* kPlane = R"(
[surface]
generator = "plane"
size = 2.0
h = 0.05
[region]
shape = "disks"
centers = [[0.0, 0.0]]
radii = [0.3]
[model]
name = "conormal"
[time]
cfl = 0.5
final_time = 0.3
[remesh]
hmax = 0.05
)";

}  // namespace

TEST_CASE("sphere cap under the conormal flow (paper §4.2): error bound and final angle π/2") {
  Outcome o = run(kCap);
  const auto& r = o.result;
  CHECK(r.reason == StopReason::FinalTime);
  CHECK(r.time == doctest::Approx(kPi / 4).epsilon(1e-12));
  // Δt = 0.5·0.1 = 0.05 → ⌈(π/4)/0.05⌉ = 16 steps, the last one shortened.
  CHECK(r.iteration == 16);
  // G(T) is the upper half-sphere: area 2π (cap angle θ with 2π(1 − cos θ) = |G|).
  const double area = region_area(o.setup.mesh, kInside);
  const double angle = std::acos(1 - area / (2 * kPi));
  CHECK(std::abs(angle - kPi / 2) < 0.02);
  // The paper's pipeline reaches E = 2.6e-2 at h = 0.1, c = 0.5; bodyfit's stages give 5.2e-2 at
  // the time of writing (an interface lag of ≈ 0.15 h, see docs/validation/conormal.md): this
  // bound guards against regressions, it is not the goal.
  const double error = cap_error(o.setup.mesh, r.final_distance, kPi / 2);
  MESSAGE("h = 0.1, c = 0.5: E = " << error << ", final cap angle " << angle);
  CHECK(error < 6e-2);
  CHECK(r.records.back().components == 1);
  CHECK(r.records.back().min_quality > 0.3);
}

TEST_CASE("a disk on a plane grows at unit speed: radius r0 + t") {
  Outcome o = run(kPlane);
  CHECK(o.result.reason == StopReason::FinalTime);
  for (const auto& rec : o.result.records) {
    const double radius = std::sqrt(rec.area / kPi);
    CAPTURE(rec.iteration);
    // The front may lag by at most 0.3 h (h = 0.05) over the run.
    CHECK(std::abs(radius - (0.3 + rec.time)) < 0.3 * 0.05);
    CHECK(std::abs(rec.interface_length - 2 * kPi * (0.3 + rec.time)) < 2 * kPi * 0.3 * 0.05);
    CHECK(rec.components == 1);
  }
  CHECK(o.result.records.back().time == doctest::Approx(0.3));
  // The surface stays the flat square.
  CHECK(total_area(o.setup.mesh) == doctest::Approx(4.0).epsilon(1e-9));
}

TEST_CASE("an interface that meets the boundary of an open surface: a half-disk of radius r0 + t") {
  Outcome o = run(kPlane, {"region.centers=[[-1.0, 0.0]]", "region.radii=[0.4]", "time.final_time=0.3"});
  CHECK(o.result.reason == StopReason::FinalTime);
  const auto& last = o.result.records.back();
  const double radius = std::sqrt(2 * last.area / kPi);
  CHECK(std::abs(radius - 0.7) < 0.3 * 0.05);
  CHECK(std::abs(last.interface_length - kPi * 0.7) < kPi * 0.3 * 0.05);  // the arc only, not the boundary
  auto curves = interface_curves(o.setup.mesh);
  CHECK(curves.open == 1);
  CHECK(curves.closed == 0);
  CHECK(total_area(o.setup.mesh) == doctest::Approx(4.0).epsilon(1e-9));
}

TEST_CASE("two caps grow and merge: components 2 → 1") {
  Outcome o = run(test::read_file(test::source_path("meshes/cases/two_caps_merge.toml")), {"surface.h=0.08", "remesh.hmax=0.08"});
  REQUIRE(!o.result.records.empty());
  CHECK(o.result.records.front().components == 2);
  CHECK(o.result.records.back().components == 1);
  // Before touching (each grows by 10° ≈ 0.1745): two components.
  for (const auto& rec : o.result.records)
    if (rec.time < 0.15) CHECK(rec.components == 2);
}

TEST_CASE("a shrinking cap vanishes and the run stops with a clear reason") {
  Outcome o = run(kCap, {"model.speed=-1.0", "region.angle=10", "time.final_time=1.0"});
  CHECK(o.result.reason == StopReason::Vanished);
  CHECK(o.result.message.find("vanished") != std::string::npos);
  CHECK(o.result.time < 0.25);
}

TEST_CASE("bodyfit run writes its outputs, and --resume gives the same final mesh") {
  test::TempDir dir("run");
  const std::string case_file = test::source_path("meshes/cases/plane_disk.toml").string();
  const std::string common = " --set surface.h=0.08 --set remesh.hmax=0.08 --set output.png_every=2 "
                             "--set output.size=[200,150]";
  auto full = test::run_bodyfit("run " + case_file + " -o " + (dir / "full").string() + common +
                                " --set time.iterations=4");
  REQUIRE_MESSAGE(full.exit_code == 0, full.output);
  for (const char* f : {"series.pvd", "history.csv", "final.mesh", "final.sol", "case.toml", "step_00000.vtu",
                        "step_00004.vtu", "snap_00000.png", "snap_00004.png"})
    CHECK_MESSAGE(std::filesystem::exists(dir / "full" / f), f);
  // history.csv: header + the initial state + 4 iterations.
  std::stringstream history(test::read_file(dir / "full" / "history.csv"));
  std::string line;
  int rows = 0;
  std::getline(history, line);
  CHECK(line.rfind("iteration,time,dt,area,interface_length,components", 0) == 0);
  while (std::getline(history, line)) ++rows;
  CHECK(rows == 5);
  // The effective case carries the overrides.
  CHECK(test::read_file(dir / "full" / "case.toml").find("iterations = 4") != std::string::npos);

  // Interrupted after 2 iterations, then resumed up to 4.
  auto part = test::run_bodyfit("run " + case_file + " -o " + (dir / "resumed").string() + common +
                                " --set time.iterations=2");
  REQUIRE_MESSAGE(part.exit_code == 0, part.output);
  auto rest = test::run_bodyfit("run " + case_file + " -o " + (dir / "resumed").string() + common +
                                " --set time.iterations=4 --resume");
  REQUIRE_MESSAGE(rest.exit_code == 0, rest.output);
  CHECK(rest.output.find("resuming from iteration 2") != std::string::npos);
  CHECK(test::read_file(dir / "resumed" / "final.mesh") == test::read_file(dir / "full" / "final.mesh"));
  CHECK(test::read_file(dir / "resumed" / "final.sol") == test::read_file(dir / "full" / "final.sol"));
  std::stringstream resumed_history(test::read_file(dir / "resumed" / "history.csv"));
  rows = -1;
  while (std::getline(resumed_history, line)) ++rows;
  CHECK(rows == 5);

  auto bad = test::run_bodyfit("run " + case_file + " -o " + (dir / "bad").string() + " --set time.tiem=3");
  CHECK(bad.exit_code == 1);
  CHECK(bad.output.find("unknown key 'tiem' in [time]") != std::string::npos);
  auto no_checkpoint = test::run_bodyfit("run " + case_file + " -o " + (dir / "none").string() + " --resume");
  CHECK(no_checkpoint.exit_code == 1);
  CHECK(no_checkpoint.output.find("no checkpoint") != std::string::npos);
}

TEST_CASE("[time] max_cfl: a long step is made of sub-steps on the same mesh, and the disk still grows at unit speed") {
  // Δt = 0.15 = 3h; with max_cfl = 1 each step is made of 3 sub-steps of 0.05 (|V| = 1).
  Outcome o = run(kPlane, {"time.cfl=3.0", "time.max_cfl=1.0"});
  CHECK(o.result.reason == StopReason::FinalTime);
  REQUIRE(o.result.records.size() == 2);
  for (const auto& rec : o.result.records) {
    CAPTURE(rec.iteration);
    CHECK(rec.substeps == 3);
    CHECK(rec.dt == doctest::Approx(0.15));
    const double radius = std::sqrt(rec.area / kPi);
    CHECK(std::abs(radius - (0.3 + rec.time)) < 0.3 * 0.05);
    CHECK(rec.components == 1);
  }
  CHECK(o.result.records.back().time == doctest::Approx(0.3));
  // Without the cap, one pass per step.
  Outcome plain = run(kPlane, {"time.cfl=3.0"});
  CHECK(plain.result.records.front().substeps == 1);
}
