// The step lifecycle of the evolution: a model that rejects candidates (T^n restored exactly, Δt
// halved, the run still ends at its final time), stops the run, drives Δt and keeps state across a
// resume; and a fire run interrupted (SIGINT, kill -9) and resumed ends byte-identical to the
// uninterrupted one.
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/checkpoint.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/plugin_loader.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

using namespace bodyfit;

namespace {

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
name = "testlifecycle"
[time]
dt = 0.025
final_time = 0.3
[remesh]
hmax = 0.05
[output]
vtu_every = 0
)";

std::filesystem::path test_plugin() { return std::filesystem::path(BODYFIT_TEST_PLUGIN_DIR) / "bodyfit_testlifecycle.so"; }

struct Run {
  CaseSetup setup;
  EvolutionResult result;
};

Run run(const std::string& model_table, const std::vector<std::string>& overrides = {}) {
  toml::table table = toml::parse(kPlane);
  for (const auto& o : overrides) apply_override(table, o);
  CaseConfig config = parse_case(table);
  LoadedModel model = load_plugin_file(test_plugin());
  configure_model(model, toml::parse(model_table));
  Run out{setup_case(config), {}};
  out.result = evolve(out.setup.mesh, model.model(), out.setup.options, {}, EvolutionHooks::quiet());
  return out;
}

double metric(const IterationRecord& r, const std::string& name) {
  for (const auto& [n, v] : r.metrics)
    if (n == name) return v;
  FAIL("no metric " << name);
  return 0;
}

/// A format-4 checkpoint rewritten as format 2 (before model states): what older runs left.
void downgrade_checkpoint(const std::filesystem::path& file) {
  std::string v3 = test::read_file(file);
  REQUIRE(v3.rfind("BFCKPT04", 0) == 0);  // the same header and arrays as format 3
  std::uint64_t nv, ne, nf;
  std::memcpy(&nv, v3.data() + 32, 8), std::memcpy(&ne, v3.data() + 40, 8), std::memcpy(&nf, v3.data() + 48, 8);
  const std::size_t arrays_end = 56 + 42 * nv + 31 * ne + 8 * nf;
  std::string v2 = "BFCKPT02" + v3.substr(8, 16) + v3.substr(32, arrays_end - 32);
  std::ofstream(file, std::ios::binary) << v2;
}

}  // namespace

TEST_CASE("a model rejecting the first candidate of every third step: T^n restored exactly, Δt/2, same final time") {
  const Run plain = run("");
  const Run rejecting = run("reject_every = 3");
  CHECK(rejecting.result.reason == StopReason::FinalTime);
  CHECK(rejecting.result.time == doctest::Approx(0.3).epsilon(1e-12));
  // Each rejected step is retried at half the step: more steps to reach the same time.
  int rejected = 0;
  for (const auto& r : rejecting.result.records) {
    CAPTURE(r.iteration);
    const bool every_third = r.iteration % 3 == 0;
    CHECK(r.rejections == (every_third ? 1 : 0));
    CHECK(r.dt == doctest::Approx(every_third ? 0.0125 : 0.025));
    CHECK(metric(r, "restore_mismatches") == 0);  // arrays seen on the retry == those of attempt 0
    rejected += r.rejections;
  }
  CHECK(rejected >= 3);
  CHECK(rejecting.result.records.size() > plain.result.records.size());
  // V^n is not recomputed on the retry: one compute() per state.
  for (const auto& r : rejecting.result.records) CHECK(metric(r, "computes") == r.iteration);
  // The disk grows at unit speed whatever the steps were.
  const auto& last = rejecting.result.records.back();
  CHECK(std::abs(std::sqrt(last.area / M_PI) - 0.6) < 0.01);
  CHECK(std::abs(last.area - plain.result.records.back().area) < 0.01 * last.area);
}

TEST_CASE("rejections run out: the run stops naming the iteration") {
  const Run r = run("reject_every = 1", {"time.max_rejections=0"});  // every first attempt rejected, no retry
  CHECK(r.result.reason == StopReason::Rejected);
  CHECK(r.result.message.find("step 1 ") != std::string::npos);
  CHECK(r.result.records.empty());
  CHECK(r.result.iteration == 0);
}

TEST_CASE("a model stopping at iteration 5: the run ends there, exit 0, outputs and checkpoint complete") {
  test::TempDir dir("lifecycle_stop");
  ::setenv("BODYFIT_PLUGIN_PATH", BODYFIT_TEST_PLUGIN_DIR, 1);
  std::ofstream(dir / "case.toml") << kPlane << "\n";
  auto out = test::run_bodyfit("run " + (dir / "case.toml").string() + " -o " + (dir / "out").string() +
                               " --set model.stop_at=5 --set output.vtu_every=1");
  REQUIRE_MESSAGE(out.exit_code == 0, out.output);
  CHECK(out.output.find("asked to stop at iteration 5") != std::string::npos);
  const Checkpoint c = load_checkpoint(dir / "out" / "checkpoint.bin");
  CHECK(c.run.iteration == 5);
  REQUIRE(c.model);
  CHECK(c.model->integers("accepted").at(0) == 5);
  for (const char* f : {"final.mesh", "final.sol", "history.csv", "series.pvd", "step_00005.vtu"})
    CHECK_MESSAGE(std::filesystem::exists(dir / "out" / f), f);
  CHECK_FALSE(std::filesystem::exists(dir / "out" / "step_00006.vtu"));
  // history.csv: the same columns in every row (row 0 included), 6 rows.
  std::stringstream history(test::read_file(dir / "out" / "history.csv"));
  std::string line;
  std::getline(history, line);
  const auto columns = std::count(line.begin(), line.end(), ',');
  CHECK(line.find("rejections") != std::string::npos);
  int rows = 0;
  while (std::getline(history, line)) {
    CHECK(std::count(line.begin(), line.end(), ',') == columns);
    ++rows;
  }
  CHECK(rows == 6);
  // The final state's VTU carries V and the model's fields.
  const std::string vtu = test::read_file(dir / "out" / "step_00005.vtu");
  CHECK(vtu.find("Name=\"velocity\" NumberOfComponents=\"3\"") != std::string::npos);
}

TEST_CASE("model-driven Δt and model state survive a resume: the same steps as the uninterrupted run") {
  test::TempDir dir("lifecycle_dt");
  ::setenv("BODYFIT_PLUGIN_PATH", BODYFIT_TEST_PLUGIN_DIR, 1);
  std::ofstream(dir / "case.toml") << kPlane << "\n";
  const std::string common = " --set model.grow_dt=1.25 --set model.reject_every=4 --set time.final_time=0.4";
  auto full = test::run_bodyfit("run " + (dir / "case.toml").string() + " -o " + (dir / "full").string() + common);
  REQUIRE_MESSAGE(full.exit_code == 0, full.output);
  auto part = test::run_bodyfit("run " + (dir / "case.toml").string() + " -o " + (dir / "part").string() + common +
                                " --inject-signal 3:INT");
  CHECK_MESSAGE(part.exit_code == 130, part.output);
  auto rest = test::run_bodyfit("run " + (dir / "case.toml").string() + " -o " + (dir / "part").string() + common +
                                " --resume");
  REQUIRE_MESSAGE(rest.exit_code == 0, rest.output);
  CHECK(rest.output.find("resuming from iteration 3") != std::string::npos);
  const std::string a = test::history_without_timings(dir / "full" / "history.csv");
  CHECK(a.find(",0.03125,") != std::string::npos);  // 0.025 · 1.25: the model grew Δt
  CHECK(test::history_without_timings(dir / "part" / "history.csv") == a);
  CHECK(test::read_file(dir / "part" / "final.mesh") == test::read_file(dir / "full" / "final.mesh"));

  // A checkpoint written before model states (format 2) still loads, with a warning.
  auto again = test::run_bodyfit("run " + (dir / "case.toml").string() + " -o " + (dir / "old").string() + common +
                                 " --inject-signal 2:INT");
  CHECK(again.exit_code == 130);
  downgrade_checkpoint(dir / "old" / "checkpoint.bin");
  auto old = test::run_bodyfit("run " + (dir / "case.toml").string() + " -o " + (dir / "old").string() + common +
                               " --resume");
  REQUIRE_MESSAGE(old.exit_code == 0, old.output);
  CHECK(old.output.find("without model state") != std::string::npos);
}

TEST_CASE("a fire run interrupted by SIGINT or kill -9 and resumed ends byte-identical to the uninterrupted run") {
  test::TempDir dir("fire_resume");
  const std::string run_case = "run " + test::source_path("meshes/cases/fire_luxembourg.toml").string() +
                               " --set time.final_time=7200 --set output.png_every=0 -o ";
  auto full = test::run_bodyfit(run_case + (dir / "full").string());
  REQUIRE_MESSAGE(full.exit_code == 0, full.output);
  for (const std::string signal : {"INT", "KILL"}) {
    CAPTURE(signal);
    const auto out = dir / signal;
    auto first = test::run_bodyfit(run_case + out.string() + " --inject-signal 7:" + signal);
    CHECK(first.exit_code == (signal == "INT" ? 130 : 128 + 9));  // the shell's status of a SIGKILL
    CHECK(load_checkpoint(out / "checkpoint.bin").run.iteration == 7);
    auto rest = test::run_bodyfit(run_case + out.string() + " --resume");
    REQUIRE_MESSAGE(rest.exit_code == 0, rest.output);
    CHECK(test::read_file(out / "arrival_time.asc") == test::read_file(dir / "full" / "arrival_time.asc"));
    CHECK(test::read_file(out / "final.mesh") == test::read_file(dir / "full" / "final.mesh"));
    CHECK(test::history_without_timings(out / "history.csv") == test::history_without_timings(dir / "full" / "history.csv"));
  }
}

TEST_CASE("SIGTERM and SIGHUP stop a run like Ctrl-C: the iteration is checkpointed, exit 130, and the resume ends "
          "as the uninterrupted run") {
  test::TempDir dir("signals");
  const std::string run_case = "run " + test::source_path("meshes/cases/fire_luxembourg.toml").string() +
                               " --set time.final_time=3600 --set output.png_every=0 -o ";
  auto full = test::run_bodyfit(run_case + (dir / "full").string());
  REQUIRE_MESSAGE(full.exit_code == 0, full.output);
  for (const std::string signal : {"TERM", "HUP"}) {
    CAPTURE(signal);
    const auto out = dir / signal;
    auto first = test::run_bodyfit(run_case + out.string() + " --inject-signal 3:" + signal);
    CHECK(first.exit_code == 130);
    CHECK(load_checkpoint(out / "checkpoint.bin").run.iteration == 3);
    auto rest = test::run_bodyfit(run_case + out.string() + " --resume");
    REQUIRE_MESSAGE(rest.exit_code == 0, rest.output);
    CHECK(test::read_file(out / "final.mesh") == test::read_file(dir / "full" / "final.mesh"));
  }
}

TEST_CASE("a model returning NaN velocities is an error naming the model and the iteration, not a wrong region") {
  CHECK_THROWS_WITH_AS(run("nan_at_vertex = 17"),
                       doctest::Contains("model 'testlifecycle' failed in compute at iteration 0: non-finite velocity "
                                         "at vertex 17"),
                       PluginError);
}
