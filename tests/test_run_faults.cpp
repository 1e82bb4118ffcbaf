// Runs that fail, and what they leave: a run killed at every write point (--inject-fault) and
// resumed ends with the outputs of the uninterrupted run, byte for byte; a model failing at any
// stage exits with code 4 naming the model, the stage and the iteration, and the run resumes;
// output directories (a previous run is refused unless --overwrite or --resume; a failed set-up
// leaves nothing); --resume with another case is refused unless --force.
#include <bodyfit/app/case_identity.hpp>
#include <bodyfit/atomic_file.hpp>
#include <bodyfit/checkpoint.hpp>
#include <bodyfit/app/config.hpp>
#include <bodyfit/app/output_lock.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/app/run_directory.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>

using namespace bodyfit;
namespace fs = std::filesystem;

namespace {

// A fire on a small procedural terrain, 5 steps of which the last is shortened (200 s of 600),
// every output on: a VTU per state, a checkpoint per iteration, the arrival-time and rate rasters
// (ESRI grids) and the perimeters (GeoJSON; a resumed run's GeoTIFFs and GeoPackage are compared
// byte for byte in test_fire_wind.cpp).
const char* kFire = R"(
[surface]
generator = "terrain"
extent = 6000.0
h = 400.0
seed = 7
max_height = 600.0
feature_size = 2000.0
[region]
shape = "disks"
centers = [[3000.0, 3000.0]]
radii = [1000.0]
[model]
name = "fire"
preset = "balbi2009"
[model.arrival]
cell_size = 200.0
[model.perimeters]
file = "perimeters.geojson"
[time]
dt = 600.0
final_time = 2600.0
[remesh]
hmax = 400.0
[output]
vtu_every = 1
png_every = 0
checkpoint_every = 1
checkpoint_seconds = 0
grid_format = "asc"
)";

// A disk growing on a plane under the fault model (tests/plugins/testfault.cpp), 4 iterations,
// checkpoints only at the start and the end (and those a failure writes).
const char* kPlane = R"(
[surface]
generator = "plane"
size = 2.0
h = 0.1
[region]
shape = "disks"
centers = [[0.0, 0.0]]
radii = [0.3]
[model]
name = "testfault"
speed = 0.5
[time]
dt = 0.05
iterations = 4
[remesh]
hmax = 0.1
[output]
vtu_every = 0
png_every = 0
checkpoint_every = 0
checkpoint_seconds = 0
)";

struct Case {
  test::TempDir dir;
  fs::path file;
  Case(const std::string& name, const char* text) : dir(name), file(dir / "case.toml") {
    std::ofstream(file) << text;
    ::setenv("BODYFIT_PLUGIN_PATH", BODYFIT_TEST_PLUGIN_DIR, 1);
  }
  test::CommandResult run(const std::string& out, const std::string& arguments = "") const {
    return test::run_bodyfit("run " + file.string() + " -o " + (dir / out).string() + " " + arguments);
  }
  int checkpointed(const std::string& out) const { return load_checkpoint(dir / out / "checkpoint.bin").run.iteration; }
};

std::vector<std::string> names_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

/// Every file of `dir` as in `reference`, byte for byte (history.csv but for its ms_* columns).
void check_same_outputs(const fs::path& dir, const fs::path& reference) {
  REQUIRE(names_in(dir) == names_in(reference));
  for (const auto& name : names_in(reference)) {
    CAPTURE(name);
    if (name == "history.csv")
      CHECK(test::history_without_timings(dir / name) == test::history_without_timings(reference / name));
    else
      CHECK(test::read_file(dir / name) == test::read_file(reference / name));
  }
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("killed at every write point and resumed: every output byte-identical to the uninterrupted run") {
  Case fire("faults_kill", kFire);
  auto full = fire.run("full");
  REQUIRE_MESSAGE(full.exit_code == 0, full.output);
  REQUIRE(fire.checkpointed("full") == 5);
  // The driver's points (between two files), then every atomic write between its temporary and
  // the rename: the checkpoint (written in the background), the history, the .pvd, a VTU, the final
  // mesh and φ, the model's rasters and perimeters, the effective case.
  const std::vector<std::string> points = {
      "checkpoint:0",  // the first checkpoint on disk, history.csv not yet
      "row:2",         // a history row without its checkpoint
      "checkpoint:2",  "vtu:2",  // a VTU without its .pvd entry
      "pvd:2",         "final:5", "final-sol:5", "finish:5",  // before final.mesh, between it and
                                                             // final.sol, before the model's finish
      "rename:checkpoint.bin:0", "rename:checkpoint.bin:3", "rename:history.csv:1", "rename:history.csv:3",
      "rename:series.pvd:0",     "rename:series.pvd:4",     "rename:step_00003.vtu:3",
      "rename:final.mesh:5",     "rename:final.sol:5",      "rename:arrival_time.asc:5",
      "rename:rate_of_spread.asc:5", "rename:perimeters.geojson:3", "rename:perimeters.geojson:5",
      "rename:case.toml:0"};
  for (const std::string& point : points) {
    CAPTURE(point);
    std::string out = "kill-" + point;
    std::replace(out.begin(), out.end(), ':', '-');
    auto killed = fire.run(out, "--inject-fault " + point);
    REQUIRE_MESSAGE(killed.exit_code == 128 + 9, killed.output);  // the point was reached
    const auto left = names_in(fire.dir / out);
    if (point == "checkpoint:0")  // no history.csv yet; the lock names the killed run
      CHECK(left == std::vector<std::string>{OutputLock::kFileName, "checkpoint.bin"});
    if (point.starts_with("rename:"))
      CHECK(std::any_of(left.begin(), left.end(), [](const std::string& n) { return is_run_output(n) && n[0] == '.'; }));
    // Killed before its first checkpoint, a run left only a temporary: it starts again (and
    // removes it); from the first checkpoint on, it resumes.
    const bool started = fs::exists(fire.dir / out / "checkpoint.bin");
    CHECK(started == (point != "rename:checkpoint.bin:0"));
    auto resumed = fire.run(out, started ? "--resume" : "");
    REQUIRE_MESSAGE(resumed.exit_code == 0, resumed.output);
    check_same_outputs(fire.dir / out, fire.dir / "full");
  }
  // A finished run resumed (its last step shortened): nothing recomputed, nothing dropped.
  auto again = fire.run("full", "--resume");
  REQUIRE_MESSAGE(again.exit_code == 0, again.output);
  CHECK(contains(test::read_file(fire.dir / "full" / "series.pvd"), "timestep=\"2400\""));
  const auto names = names_in(fire.dir / "full");
  CHECK(std::count(names.begin(), names.end(), "step_00004.vtu") == 1);
}

TEST_CASE("an I/O error at a write point: exit 6 naming it, the last completed iteration saved, --resume completes") {
  Case fire("faults_io", kFire);
  auto full = fire.run("full");
  REQUIRE_MESSAGE(full.exit_code == 0, full.output);
  struct Point {
    std::string name;
    int saved;  ///< the checkpoint the failed run must leave (on_failure's, or the last one written)
  };
  // Iteration n is complete once its history row is written: a failure after that (its VTU, the
  // .pvd, the final files) leaves state n on disk — the driver's on_failure checkpoints it when the
  // cadence had not; a failure writing row n leaves checkpoint n − 1 (state n is recomputed). The
  // "checkpoint" point comes after the checkpoint's rename; a failed rename leaves the one before.
  const std::vector<Point> points = {{"row:2", 1},           {"vtu:2", 2},  {"pvd:2", 2},
                                     {"rename:history.csv:3", 2}, {"rename:step_00003.vtu:3", 3},
                                     {"final:5", 5},         {"checkpoint:2", 2}, {"rename:checkpoint.bin:3", 2}};
  for (const Point& point : points) {
    CAPTURE(point.name);
    std::string out = "io-" + point.name;
    std::replace(out.begin(), out.end(), ':', '-');
    auto failed = fire.run(out, "--inject-io-error " + point.name);
    CHECK_MESSAGE(failed.exit_code == 6, failed.output);
    CHECK_MESSAGE(contains(failed.output, "injected I/O error"), failed.output);
    CHECK(fire.checkpointed(out) == point.saved);
    auto resumed = fire.run(out, "--resume");
    REQUIRE_MESSAGE(resumed.exit_code == 0, resumed.output);
    check_same_outputs(fire.dir / out, fire.dir / "full");
  }
}

TEST_CASE("a model failing at any stage: exit 4 naming the model, the stage and the iteration, and the run resumes") {
  Case plane("faults_plugin", kPlane);
  auto reference = plane.run("reference");
  REQUIRE_MESSAGE(reference.exit_code == 0, reference.output);
  struct Fault {
    std::string settings, message;
    int exit_code, checkpoint;  ///< the checkpoint the failed run leaves
  };
  const std::vector<Fault> faults = {
      {"stage=compute at=2 how=runtime_error", "failed in compute at iteration 2: a runtime error from compute", 4, 2},
      {"stage=compute at=2 how=int", "failed in compute at iteration 2: an exception that is not a std::exception", 4, 2},
      // An InputError is the model telling the user's input is wrong: exit 1, named the same.
      {"stage=compute at=2 how=input_error", "failed in compute at iteration 2: an input error from compute", 1, 2},
      {"stage=compute at=2 how=not_finite", "failed in compute at iteration 2: non-finite velocity at vertex", 4, 2},
      {"stage=compute at=2 how=size", "failed in compute at iteration 2: ", 4, 2},
      {"stage=end_step at=2", "failed in end_step at iteration 2: a runtime error from end_step", 4, 2},
      // The candidate T^3 is in memory, not T^2: the last checkpoint written stands.
      {"stage=review at=3", "failed in review at iteration 3: a runtime error from review", 4, 0},
      {"stage=save_state at=2", "failed in save_state at iteration 2: a runtime error from save_state", 4, 0},
      {"stage=finish at=4", "failed in finish at iteration 4: a runtime error from finish", 4, 4},
      {"stage=compute at=2 how=segv", "model 'testfault' crashed (SIGSEGV) in compute at iteration 2", 128 + 11, 0},
      {"stage=compute at=2 how=fpe", "model 'testfault' crashed (SIGFPE) in compute at iteration 2", 128 + 8, 0},
      // exit() in the model is its failure, not the run's end with status 0 and no final state.
      {"stage=compute at=2 how=exit", "model 'testfault' called exit() in compute at iteration 2: a model failure", 4, 0},
      {"stage=review at=3 how=exit", "model 'testfault' called exit() in review at iteration 3: a model failure", 4, 0},
  };
  for (const Fault& fault : faults) {
    CAPTURE(fault.settings);
    std::string sets, out = "fault";
    std::stringstream words(fault.settings);
    for (std::string word; words >> word;) sets += " --set model." + word, out += "-" + word;
    std::replace(out.begin(), out.end(), '=', '-');
    auto failed = plane.run(out, sets);
    CHECK_MESSAGE(failed.exit_code == fault.exit_code, failed.output);
    CHECK_MESSAGE(contains(failed.output, fault.message), failed.output);
    if (fault.exit_code <= 4 && !contains(fault.settings, "how=exit")) CHECK(contains(failed.output, "model 'testfault' failed in "));
    CHECK(plane.checkpointed(out) == fault.checkpoint);
    if (fault.settings.starts_with("stage=finish")) {  // the completed run's final mesh is on disk
      CHECK(test::read_file(plane.dir / out / "final.mesh") == test::read_file(plane.dir / "reference" / "final.mesh"));
    }
    auto resumed = plane.run(out, sets + " --set model.stage=none --resume --force");
    REQUIRE_MESSAGE(resumed.exit_code == 0, resumed.output);
    CHECK(test::read_file(plane.dir / out / "final.mesh") == test::read_file(plane.dir / "reference" / "final.mesh"));
    CHECK(test::history_without_timings(plane.dir / out / "history.csv") ==
          test::history_without_timings(plane.dir / "reference" / "history.csv"));
  }

  // load_state on --resume: nothing of the directory is touched.
  auto part = plane.run("load", "--inject-signal 2:INT");
  REQUIRE_MESSAGE(part.exit_code == 130, part.output);
  const std::string history = test::read_file(plane.dir / "load" / "history.csv");
  auto load = plane.run("load", "--set model.stage=load_state --set model.at=2 --resume --force");
  CHECK_MESSAGE(load.exit_code == 4, load.output);
  CHECK(contains(load.output, "model 'testfault' failed in load_state at iteration 2: a runtime error from load_state"));
  CHECK(test::read_file(plane.dir / "load" / "history.csv") == history);

  // configure: an InputError is the user's (exit 1), anything else the plugin's (exit 4).
  auto input = plane.run("configure-input", "--set model.stage=configure --set model.how=input_error");
  CHECK_MESSAGE(input.exit_code == 1, input.output);
  CHECK(contains(input.output, "configure failed: an input error from configure"));
  auto thrown = plane.run("configure-int", "--set model.stage=configure --set model.how=int");
  CHECK_MESSAGE(thrown.exit_code == 4, thrown.output);
  CHECK(contains(thrown.output, "model 'testfault' failed in configure: an exception that is not a std::exception"));
  CHECK_FALSE(fs::exists(plane.dir / "configure-input"));
  CHECK_FALSE(fs::exists(plane.dir / "configure-int"));
  // A crash or exit() in configure: nothing was written, and the report says so (no checkpoint).
  for (const char* how : {"segv", "exit"}) {
    CAPTURE(how);
    auto crashed = plane.run(std::string("configure-") + how, std::string("--set model.stage=configure --set model.how=") + how);
    CHECK(crashed.exit_code == (std::string(how) == "exit" ? 4 : 128 + 11));
    CHECK_MESSAGE(contains(crashed.output, "in configure"), crashed.output);
    CHECK_MESSAGE(contains(crashed.output, "before the run wrote anything"), crashed.output);
    CHECK_FALSE(contains(crashed.output, "checkpoint on disk is intact"));
    CHECK_FALSE(fs::exists(plane.dir / (std::string("configure-") + how)));
  }
}

TEST_CASE("output directories: a previous run is refused unless --overwrite or --resume, a failed set-up leaves nothing") {
  Case plane("faults_dirs", kPlane);
  auto first = plane.run("out", "--set time.iterations=1");
  REQUIRE_MESSAGE(first.exit_code == 0, first.output);
  auto again = plane.run("out", "--set time.iterations=1");
  CHECK(again.exit_code == 1);
  CHECK(contains(again.output, "holds a previous run"));
  CHECK(contains(again.output, "--overwrite"));

  // --overwrite removes the run's files, and only those.
  std::ofstream(plane.dir / "out" / "notes.txt") << "mine";
  std::ofstream(plane.dir / "out" / "step_00099.vtu") << "an older run's";
  std::ofstream(plane.dir / "out" / ".history.csv.tmp999-3") << "a killed write";
  auto overwritten = plane.run("out", "--set time.iterations=2 --overwrite");
  REQUIRE_MESSAGE(overwritten.exit_code == 0, overwritten.output);
  CHECK(test::read_file(plane.dir / "out" / "notes.txt") == "mine");
  CHECK_FALSE(fs::exists(plane.dir / "out" / "step_00099.vtu"));
  CHECK_FALSE(fs::exists(plane.dir / "out" / ".history.csv.tmp999-3"));
  CHECK(plane.checkpointed("out") == 2);
  CHECK(plane.run("out", "--overwrite --resume").exit_code == 2);  // one or the other

  // The model's files too (VelocityModel::output_files): a fire run writing ESRI grids and GeoJSON
  // perimeters (kFire) replaced by one writing GeoTIFFs and a GeoPackage leaves none of them.
  if constexpr (config::have_gdal) {
    Case fire("faults_dirs_fire", kFire);
    REQUIRE(fire.run("out").exit_code == 0);
    REQUIRE(fs::exists(fire.dir / "out" / "arrival_time.asc"));
    REQUIRE(fs::exists(fire.dir / "out" / "perimeters.geojson"));
    auto replaced = fire.run("out", "--overwrite --set output.grid_format='\"tif\"' "
                                    "--set model.perimeters.file='\"perimeters.gpkg\"'");
    REQUIRE_MESSAGE(replaced.exit_code == 0, replaced.output);
    CHECK(fs::exists(fire.dir / "out" / "arrival_time.tif"));
    CHECK(fs::exists(fire.dir / "out" / "perimeters.gpkg"));
    for (const char* gone : {"arrival_time.asc", "arrival_time.prj", "rate_of_spread.asc", "perimeters.geojson"}) {
      CAPTURE(gone);
      CHECK_FALSE(fs::exists(fire.dir / "out" / gone));
    }
  }

  // A failed set-up writes nothing: a bad key, an unknown model, a bad mesh, a failing configure.
  std::ofstream(plane.dir / "bad.mesh") << "not a mesh at all\n";
  std::ofstream(plane.dir / "bad_mesh.toml") << "[surface]\nfile = \"bad.mesh\"\n[region]\nshape = \"refs\"\n"
                                                "[model]\nname = \"testfault\"\n[time]\ndt = 0.1\niterations = 1\n";
  const std::vector<std::pair<std::string, std::string>> failures = {
      {"run " + plane.file.string(), "--set time.tiem=3"},
      {"run " + plane.file.string(), "--set model.name=nosuchmodel"},
      {"run " + (plane.dir / "bad_mesh.toml").string(), ""},
      {"run " + plane.file.string(), "--set model.stage=configure"}};
  for (std::size_t i = 0; i < failures.size(); ++i) {
    CAPTURE(failures[i].second);
    const fs::path out = plane.dir / ("failed" + std::to_string(i));
    auto failed = test::run_bodyfit(failures[i].first + " -o " + out.string() + " " + failures[i].second);
    CHECK_MESSAGE(failed.exit_code != 0, failed.output);
    CHECK_FALSE(fs::exists(out));
  }
}

TEST_CASE("--resume with another case is refused, naming the keys, unless --force (the end of the run may change)") {
  Case plane("faults_case", kPlane);
  auto first = plane.run("out", "--set time.iterations=2");
  REQUIRE_MESSAGE(first.exit_code == 0, first.output);

  auto other_dt = plane.run("out", "--set time.iterations=2 --set time.dt=0.025 --resume");
  CHECK(other_dt.exit_code == 1);
  CHECK_MESSAGE(contains(other_dt.output, "the case differs"), other_dt.output);
  CHECK(contains(other_dt.output, "time.dt: 0.05 -> 0.025"));
  CHECK(contains(other_dt.output, "--force"));
  // Another case file: the same text but for the model's speed.
  std::string text = kPlane;
  text.replace(text.find("speed = 0.5"), 11, "speed = 0.7");
  std::ofstream(plane.dir / "other.toml") << text;
  auto other_file = test::run_bodyfit("run " + (plane.dir / "other.toml").string() + " -o " +
                                      (plane.dir / "out").string() + " --set time.iterations=2 --resume");
  CHECK(other_file.exit_code == 1);
  CHECK_MESSAGE(contains(other_file.output, "model.speed: 0.5 -> 0.7"), other_file.output);

  // Extending the run (more iterations) is not another case; --force accepts another one.
  auto extended = plane.run("out", "--set time.iterations=3 --resume");
  REQUIRE_MESSAGE(extended.exit_code == 0, extended.output);
  CHECK(contains(extended.output, "resuming with time.iterations: 2 -> 3"));
  auto forced = plane.run("out", "--set time.iterations=4 --set time.dt=0.025 --resume --force");
  REQUIRE_MESSAGE(forced.exit_code == 0, forced.output);
  CHECK(contains(forced.output, "--force"));

  // A checkpoint that records no case (format 3, or written by a program): resumed, with a warning.
  const Checkpoint c = load_checkpoint(plane.dir / "out" / "checkpoint.bin");
  save_checkpoint(plane.dir / "out" / "checkpoint.bin", c.mesh, c.run, c.model ? &*c.model : nullptr);
  auto unrecorded = plane.run("out", "--set time.iterations=5 --resume");
  REQUIRE_MESSAGE(unrecorded.exit_code == 0, unrecorded.output);
  CHECK(contains(unrecorded.output, "the case is not compared"));
}

TEST_CASE("--resume refuses a data file edited in between (the checkpoint records a digest of each)") {
  // A case whose surface is a mesh file: the plane of kPlane, written by a first run.
  Case plane("faults_inputs", kPlane);
  REQUIRE(plane.run("mesh", "--set time.iterations=0").exit_code == 0);
  fs::copy_file(plane.dir / "mesh" / "final.mesh", plane.dir / "surface.mesh");
  std::string text = kPlane;
  const std::string generated = "generator = \"plane\"\nsize = 2.0\nh = 0.1";
  text.replace(text.find(generated), generated.size(), "file = \"surface.mesh\"");
  std::ofstream(plane.file) << text;
  auto first = plane.run("out", "--set time.iterations=2");
  REQUIRE_MESSAGE(first.exit_code == 0, first.output);
  const Checkpoint c = load_checkpoint(plane.dir / "out" / "checkpoint.bin");
  CHECK(contains(c.case_text, "surface.file"));
  // Rewritten with the same bytes (a new modification time): the same file, resumed.
  std::string mesh = test::read_file(plane.dir / "surface.mesh");
  std::ofstream(plane.dir / "surface.mesh") << mesh;
  REQUIRE(plane.run("out", "--set time.iterations=4 --resume").exit_code == 0);
  mesh += "\n";  // a byte more: another file for the digest (and the same mesh for the reader)
  std::ofstream(plane.dir / "surface.mesh") << mesh;
  auto edited = plane.run("out", "--set time.iterations=5 --resume");
  CHECK(edited.exit_code == 1);
  CHECK_MESSAGE(contains(edited.output, "input_files.surface.file"), edited.output);
  CHECK(contains(edited.output, "--force"));
  auto forced = plane.run("out", "--set time.iterations=5 --resume --force");
  CHECK_MESSAGE(forced.exit_code == 0, forced.output);
  // A checkpoint from before the digests (its case without [input_files]) is resumed.
  const Checkpoint d = load_checkpoint(plane.dir / "out" / "checkpoint.bin");
  toml::table old_case = toml::parse(d.case_text);
  old_case.erase("input_files");
  CheckpointSnapshot snapshot;
  take_snapshot(snapshot, d.mesh, d.run, d.model ? &*d.model : nullptr, canonical_case(old_case));
  save_checkpoint(plane.dir / "out" / "checkpoint.bin", snapshot);
  auto older = plane.run("out", "--set time.iterations=6 --resume");
  CHECK_MESSAGE(older.exit_code == 0, older.output);
  CHECK(contains(older.output, "records no digest of surface.file"));
}

TEST_CASE("case identity: canonical text, and the keys that differ") {
  const std::string a = canonical_case(toml::parse("[time]\ndt = 0.5 # a comment\nfinal_time = 2.0\n[model]\nname = 'x'\n"));
  const std::string b = canonical_case(toml::parse("[model]\nname = \"x\"\n\n[time]\nfinal_time = 2.0\ndt = 0.5\n"));
  CHECK(a == b);
  CHECK(case_changes(a, b).empty());
  const std::string c = canonical_case(toml::parse("[model]\nname = 'y'\nspeed = 2\n[time]\nfinal_time = 2.0\n"));
  const auto changes = case_changes(a, c);
  REQUIRE(changes.size() == 3);
  CHECK(changes[0].key == "model.name");
  CHECK(changes[0].before == "'x'");
  CHECK(changes[0].after == "'y'");
  CHECK(changes[1].key == "model.speed");
  CHECK(changes[1].before.empty());
  CHECK(changes[2].key == "time.dt");
  CHECK(changes[2].after.empty());
  CHECK(resume_may_change("time.iterations"));
  CHECK(resume_may_change("output.vtu_every"));
  CHECK_FALSE(resume_may_change("time.dt"));
  CHECK_FALSE(resume_may_change("model.speed"));
}

TEST_CASE("the run's own files: names, temporaries, per-state files past a checkpoint") {
  CHECK(is_run_output("history.csv"));
  CHECK(is_run_output("step_00012.vtu"));
  CHECK(is_run_output("snap_00003.png"));
  CHECK(is_run_output(".checkpoint.bin.tmp1234-0"));
  CHECK_FALSE(is_run_output("notes.txt"));
  CHECK_FALSE(is_run_output("arrival_time.asc"));  // the model's
  CHECK_FALSE(is_run_output("step_final.vtu"));
  test::TempDir dir("run_directory");
  for (const char* name : {"step_00001.vtu", "step_00002.vtu", "snap_00002.png", "step_00003.vtu", "history.csv",
                           ".series.pvd.tmp1-2", "mine.vtu"})
    std::ofstream(dir / name) << "x";
  CHECK(remove_stale_temporaries(dir.path()) == 1);
  CHECK(remove_states_from(dir.path(), 2) == 3);
  CHECK(names_in(dir.path()) == std::vector<std::string>{"history.csv", "mine.vtu", "step_00001.vtu"});
  remove_run_outputs(dir.path());
  CHECK(names_in(dir.path()) == std::vector<std::string>{"mine.vtu"});
}

TEST_CASE("a model stuck in compute: the first signal waits for it, a second one ends the run at once, the "
          "checkpoint intact and resumable") {
  test::TempDir dir("faults_stuck");
  const fs::path hang = dir / "hang";
  std::ofstream(hang) << "stuck while this file exists\n";
  const fs::path file = dir / "case.toml";
  std::ofstream(file) << fmt::format(R"(
[surface]
generator = "plane"
size = 2.0
h = 0.1
[region]
shape = "disks"
centers = [[0.0, 0.0]]
radii = [0.3]
[model]
name = "testlifecycle"
speed = 0.5
hang_file = "{}"
[time]
dt = 0.05
iterations = 4
[remesh]
hmax = 0.1
[output]
vtu_every = 0
png_every = 0
)", hang.string());
  ::setenv("BODYFIT_PLUGIN_PATH", BODYFIT_TEST_PLUGIN_DIR, 1);
  const fs::path out = dir / "out", status = dir / "status";
  // The run stalls in the compute of iteration 1 (after T^0's row is written); SIGTERM there is
  // honoured only after the iteration, which never ends; a second SIGTERM ends the process.
  const std::string script = fmt::format(
      "'{}' run '{}' -o '{}' > '{}log' 2>&1 & pid=$!; "
      "for i in $(seq 600); do [ -s '{}/history.csv' ] && break; sleep 0.1; done; sleep 0.5; "
      "kill -TERM $pid; sleep 0.5; kill -TERM $pid; wait $pid; echo $? > '{}'",
      BODYFIT_EXE, file.string(), out.string(), (dir / "").string(), out.string(), status.string());
  std::ofstream(dir / "signal.sh") << script << "\n";
  REQUIRE(std::system(("bash '" + (dir / "signal.sh").string() + "'").c_str()) == 0);
  CHECK(test::read_file(status) == "130\n");
  CHECK(load_checkpoint(out / "checkpoint.bin").run.iteration == 0);
  // Unstuck (the hang file, one of the case's inputs, is gone: --force), the resume continues from
  // T^0 and finishes.
  fs::remove(hang);
  auto rest = test::run_bodyfit("run " + file.string() + " -o " + out.string() + " --resume --force");
  REQUIRE_MESSAGE(rest.exit_code == 0, rest.output);
  CHECK(fs::exists(out / "final.mesh"));
}

TEST_CASE("an output directory is one run's at a time: a second run (or --overwrite, or --resume) is refused "
          "naming the owner, and a lock left by a killed run is taken over") {
  test::TempDir dir("faults_lock");
  const fs::path hang = dir / "hang";
  std::ofstream(hang) << "stuck while this file exists\n";
  const fs::path file = dir / "case.toml";
  std::ofstream(file) << fmt::format(R"(
[surface]
generator = "plane"
size = 2.0
h = 0.1
[region]
shape = "disks"
centers = [[0.0, 0.0]]
radii = [0.3]
[model]
name = "testlifecycle"
speed = 0.5
hang_file = "{}"
[time]
dt = 0.05
iterations = 4
[remesh]
hmax = 0.1
[output]
vtu_every = 0
png_every = 0
)", hang.string());
  ::setenv("BODYFIT_PLUGIN_PATH", BODYFIT_TEST_PLUGIN_DIR, 1);
  const fs::path out = dir / "out", status = dir / "status";
  // The first run stalls in its first compute, holding the directory; the others try it meanwhile;
  // then the first is killed outright (SIGKILL: no chance to release anything).
  const std::string script = fmt::format(
      "exe='{}'; case='{}'; out='{}'; d='{}'; "
      "$exe run $case -o $out > $d/first.log 2>&1 & pid=$!; "
      "for i in $(seq 600); do [ -s $out/history.csv ] && break; sleep 0.1; done; "
      "$exe run $case -o $out > $d/second.log 2>&1; echo $? > $d/second.status; "
      "$exe run $case -o $out --overwrite > $d/overwrite.log 2>&1; echo $? > $d/overwrite.status; "
      "$exe run $case -o $out --resume --force > $d/resume.log 2>&1; echo $? > $d/resume.status; "
      "kill -KILL $pid; wait $pid; echo $? > '{}'",
      BODYFIT_EXE, file.string(), out.string(), dir.path().string(), status.string());
  std::ofstream(dir / "lock.sh") << script << "\n";
  REQUIRE(std::system(("bash '" + (dir / "lock.sh").string() + "'").c_str()) == 0);
  CHECK(test::read_file(status) == "137\n");
  for (const char* attempt : {"second", "overwrite", "resume"}) {
    CAPTURE(attempt);
    const std::string log = test::read_file(dir / (std::string(attempt) + ".log"));
    CHECK(test::read_file(dir / (std::string(attempt) + ".status")) == "1\n");
    CHECK_MESSAGE(log.find("is in use by another run (pid ") != std::string::npos, log);
    CHECK_MESSAGE(log.find(" on host ") != std::string::npos, log);
  }
  // The first run's files are its own, untouched by the refused runs.
  CHECK(test::read_file(out / "case.toml").find("hang_file") != std::string::npos);
  CHECK(load_checkpoint(out / "checkpoint.bin").run.iteration == 0);
  // The killed run's lock names it still: the next run takes it over, says so, and finishes.
  fs::remove(hang);
  auto rest = test::run_bodyfit("run " + file.string() + " -o " + out.string() + " --resume --force");
  REQUIRE_MESSAGE(rest.exit_code == 0, rest.output);
  CHECK_MESSAGE(rest.output.find("ended without releasing it (killed?): taken over") != std::string::npos, rest.output);
  CHECK(fs::exists(out / "final.mesh"));
  CHECK(test::read_file(out / ".bodyfit.lock").empty());  // released at the end
}

TEST_CASE("OutputLock (run and ensemble): a second holder is refused, and the directory is free once released") {
  test::TempDir dir("faults_lock_unit");
  const fs::path out = dir / "new" / "out";  // created by the lock
  {
    const OutputLock first(out);
    CHECK(test::read_file(out / OutputLock::kFileName).find(fmt::format("pid {} on host ", ::getpid())) == 0);
    CHECK_THROWS_WITH_AS(OutputLock{out}, doctest::Contains("is in use by another run (pid"), InputError);
    CHECK_THROWS_WITH_AS(OutputLock::check_free(out), doctest::Contains("is in use by another run"), InputError);
  }
  CHECK(test::read_file(out / OutputLock::kFileName).empty());
  CHECK_NOTHROW(OutputLock::check_free(out));
  CHECK_NOTHROW(OutputLock::check_free(dir / "absent"));  // makes nothing
  CHECK_FALSE(fs::exists(dir / "absent"));
  const OutputLock again(out);
}

TEST_CASE("resume against damaged files: garbage after history.csv's rows, a checkpoint recording a case that is "
          "not TOML, a model metric that cannot be a column; each a named outcome, never an internal error") {
  Case plane("faults_resume_files", kPlane);
  auto reference = plane.run("reference");
  REQUIRE_MESSAGE(reference.exit_code == 0, reference.output);

  // Lines appended to history.csv (by hand, a disk that wrote garbage): dropped with a warning
  // naming the line; the resumed run writes the rows again.
  auto part = plane.run("garbage", "--inject-signal 2:INT");
  REQUIRE(part.exit_code == 130);
  std::ofstream(plane.dir / "garbage" / "history.csv", std::ios::app) << "not,a,row\n7e,1,2\n\x01\x02\n";
  auto rest = plane.run("garbage", "--resume");
  REQUIRE_MESSAGE(rest.exit_code == 0, rest.output);
  CHECK(contains(rest.output, "history.csv:5: not a history row (not,a,row)"));
  CHECK(test::history_without_timings(plane.dir / "garbage" / "history.csv") ==
        test::history_without_timings(plane.dir / "reference" / "history.csv"));

  // A checkpoint (intact checksum) whose recorded case is not TOML: refused naming the file and the
  // line, unless --force.
  auto part2 = plane.run("case", "--inject-signal 2:INT");
  REQUIRE(part2.exit_code == 130);
  {
    Checkpoint c = load_checkpoint(plane.dir / "case" / "checkpoint.bin");
    c.case_text = "[model\nname = ";
    CheckpointSnapshot snapshot;
    take_snapshot(snapshot, c.mesh, c.run, c.model ? &*c.model : nullptr, c.case_text);
    save_checkpoint(plane.dir / "case" / "checkpoint.bin", snapshot);
  }
  auto refused = plane.run("case", "--resume");
  CHECK_MESSAGE(refused.exit_code == 1, refused.output);
  CHECK(contains(refused.output, "checkpoint.bin: the recorded case is not valid TOML (line 1"));
  auto forced = plane.run("case", "--resume --force");
  CHECK_MESSAGE(forced.exit_code == 0, forced.output);
  CHECK(contains(forced.output, "--force: resuming without comparing the cases"));

  // A metric whose name would break history.csv's columns: the model's failure (exit 4).
  auto metric = plane.run("metric", "--set model.stage=compute --set model.at=1 --set model.how=metric_name");
  CHECK_MESSAGE(metric.exit_code == 4, metric.output);
  CHECK(contains(metric.output, "cannot be a column of history.csv"));
}

TEST_CASE("a file-size limit (ulimit -f): an I/O error naming it, exit 6, and no temporary left behind") {
  Case plane("faults_fsize", kPlane);
  const fs::path out = plane.dir / "out", log = plane.dir / "log";
  // SIGXFSZ killed the run (status 153) with its .checkpoint.bin.tmp… left in the directory.
  const std::string script = fmt::format("ulimit -f 64; '{}' run '{}' -o '{}' > '{}' 2>&1; echo $? >> '{}'", BODYFIT_EXE,
                                         plane.file.string(), out.string(), log.string(), log.string());
  std::ofstream(plane.dir / "fsize.sh") << script << "\n";
  REQUIRE(std::system(("bash '" + (plane.dir / "fsize.sh").string() + "'").c_str()) == 0);
  const std::string output = test::read_file(log);
  CHECK_MESSAGE(output.ends_with("\n6\n"), output);
  CHECK_MESSAGE(contains(output, "write failed (File too large)"), output);
  for (const auto& name : names_in(out)) CHECK_FALSE(is_atomic_temporary(name));
}

TEST_CASE("a model stuck in compute under a --model-timeout ends the run on its own, exit 4, the checkpoint intact") {
  test::TempDir dir("faults_timeout");
  const fs::path hang = dir / "hang";
  std::ofstream(hang) << "stuck while this file exists\n";
  const fs::path file = dir / "case.toml";
  std::ofstream(file) << fmt::format(R"(
[surface]
generator = "plane"
size = 2.0
h = 0.1
[region]
shape = "disks"
centers = [[0.0, 0.0]]
radii = [0.3]
[model]
name = "testlifecycle"
speed = 0.5
hang_file = "{}"
[time]
dt = 0.05
iterations = 4
[output]
vtu_every = 0
png_every = 0
)", hang.string());
  ::setenv("BODYFIT_PLUGIN_PATH", BODYFIT_TEST_PLUGIN_DIR, 1);
  const fs::path out = dir / "out";
  const auto started = std::chrono::steady_clock::now();
  auto stuck = test::run_bodyfit("run " + file.string() + " -o " + out.string() + " --model-timeout 1");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  CHECK_MESSAGE(stuck.exit_code == 4, stuck.output);
  CHECK(contains(stuck.output, "model 'testlifecycle' did not return from compute at iteration"));
  CHECK(contains(stuck.output, "within the limit (--model-timeout 1 s)"));
  CHECK(seconds < 30);
  CHECK(load_checkpoint(out / "checkpoint.bin").run.iteration == 0);
  fs::remove(hang);
  auto rest = test::run_bodyfit("run " + file.string() + " -o " + out.string() + " --resume --force --model-timeout 60");
  REQUIRE_MESSAGE(rest.exit_code == 0, rest.output);
  CHECK(fs::exists(out / "final.mesh"));
}
