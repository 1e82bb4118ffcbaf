// Checkpoints: bit-exact round trips of the mesh, the run state and a model's state; corrupt and
// truncated files refused; formats 1 and 2 still read; canonicalize() gives the mesh a checkpoint
// reads back; the cadence of `bodyfit run` (every N iterations, every S seconds, always at the end
// and on SIGINT) and a resume after a crash between two checkpoints.
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/checkpoint.hpp>
#include <bodyfit/checkpoint_writer.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/plugin_loader.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>

#include <cstring>
#include <limits>
#include <fstream>
#include <regex>
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
name = "conormal"
[time]
cfl = 0.5
iterations = 1
[remesh]
hmax = 0.05
)";

/// T^1 of a disk growing on a plane: a remeshed mesh with regions and an interface.
SurfaceMesh evolved_plane() {
  CaseConfig config = parse_case(toml::parse(kPlane));
  LoadedModel model = load_model(config.model);
  configure_model(model, config.model_parameters);
  CaseSetup setup = setup_case(config);
  evolve(setup.mesh, model.model(), setup.options, {}, EvolutionHooks::quiet());
  return std::move(setup.mesh);
}

std::string bytes_of(const SurfaceMesh& mesh, const RunState& run, const ModelState* model) {
  std::stringstream buffer;
  write_checkpoint(buffer, mesh, run, model);
  return buffer.str();
}

Checkpoint parse(const std::string& bytes) {
  std::stringstream in(bytes);
  return read_checkpoint(in);
}

std::string error_of(const std::string& bytes) {
  try {
    parse(bytes);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// The same checkpoint as format 2 wrote it (no Δt, no model state, no case, no checksum): what
/// runs made before the step lifecycle left on disk.
std::string as_format_2(const std::string& v4, bool had_model_state) {
  REQUIRE(!had_model_state);
  std::string v2 = "BFCKPT02";
  v2 += v4.substr(8, 16);     // iteration, time
  v2 += v4.substr(32);        // counts and arrays (the Δt at 24..32 dropped)
  v2.resize(v2.size() - 17);  // model-state flag, empty case record, checksum
  return v2;
}

void check_same_arrays(const SurfaceMesh& a, const SurfaceMesh& b) {
  REQUIRE(a.n_vertices() == b.n_vertices());
  REQUIRE(a.n_edges() == b.n_edges());
  REQUIRE(a.n_faces() == b.n_faces());
  for (auto v : a.vertices()) {
    CHECK(a.point(v) == b.point(v));
    CHECK(a.phi(v) == b.phi(v));
    CHECK(a.halfedge_handle(v) == b.halfedge_handle(v));
    CHECK(a.status(v).bits() == b.status(v).bits());
  }
  for (auto h : a.halfedges()) {
    CHECK(a.to_vertex_handle(h) == b.to_vertex_handle(h));
    CHECK(a.next_halfedge_handle(h) == b.next_halfedge_handle(h));
    CHECK(a.prev_halfedge_handle(h) == b.prev_halfedge_handle(h));
    CHECK(a.face_handle(h) == b.face_handle(h));
  }
  for (auto e : a.edges()) {
    CHECK(a.interface(e) == b.interface(e));
    CHECK(a.status(e).bits() == b.status(e).bits());
  }
  for (auto f : a.faces()) {
    CHECK(a.halfedge_handle(f) == b.halfedge_handle(f));
    CHECK(a.region(f) == b.region(f));
    CHECK(a.status(f).bits() == b.status(f).bits());
  }
}

}  // namespace

TEST_CASE("checkpoints round-trip the mesh, the run state and the model state bit-exactly") {
  const SurfaceMesh mesh = evolved_plane();
  ModelState state;
  state.version = 7;
  state.set("dt", 0.1 + 0.2);  // not representable exactly in decimal: bits must survive
  state.set("history", std::vector<double>{1.5, -2.25, 1e-300, std::numeric_limits<double>::infinity()});
  state.set("counts", std::vector<std::int64_t>{-1, 0, std::int64_t(1) << 40});
  state.set("raster", std::string("\0binary\xff", 8));
  state.set("empty", std::vector<double>{});
  const Checkpoint c = parse(bytes_of(mesh, {.iteration = 7, .time = 0.125, .dt = 0.0375}, &state));
  CHECK(c.format == 4);
  CHECK(c.case_text.empty());  // none given
  CHECK(c.run.iteration == 7);
  CHECK(c.run.time == 0.125);
  CHECK(c.run.dt == 0.0375);
  REQUIRE(c.model);
  CHECK(*c.model == state);
  CHECK(c.model->number("dt") == 0.1 + 0.2);
  CHECK(c.model->string("raster").size() == 8);
  check_same_arrays(c.mesh, mesh);
  CHECK(region_area(c.mesh, kInside) == region_area(mesh, kInside));

  // The effective case a run records (format 4).
  CheckpointSnapshot with_case;
  take_snapshot(with_case, mesh, {.iteration = 2}, &state, "[time]\ndt = 0.5\n");
  with_case.seal();
  CHECK(parse(std::string(with_case.bytes())).case_text == "[time]\ndt = 0.5\n");

  // Without a model state, and the accessors' errors.
  CHECK_FALSE(parse(bytes_of(mesh, {}, nullptr)).model);
  CHECK_THROWS_WITH_AS(state.number("nothing"), doctest::Contains("no entry 'nothing'"), InputError);
  CHECK_THROWS_WITH_AS(state.number("history"), doctest::Contains("holds 4 numbers"), InputError);
  CHECK_THROWS_WITH_AS(state.string("dt"), doctest::Contains("is not a string"), InputError);
}

TEST_CASE("damaged, truncated and altered checkpoints are refused before anything is allocated") {
  const SurfaceMesh mesh = evolved_plane();
  const std::string bytes = bytes_of(mesh, {.iteration = 1, .time = 0.5}, nullptr);
  CHECK(error_of("not a checkpoint").find("not a bodyfit checkpoint") != std::string::npos);
  // One flipped bit anywhere: the checksum.
  for (std::size_t at : {std::size_t(9), std::size_t(60), bytes.size() / 2, bytes.size() - 3}) {
    std::string damaged = bytes;
    damaged[at] ^= 0x10;
    CAPTURE(at);
    CHECK(error_of(damaged).find("checksum mismatch") != std::string::npos);
  }
  CHECK(error_of(bytes.substr(0, bytes.size() / 2)).find("checksum mismatch") != std::string::npos);
  CHECK(error_of(bytes.substr(0, 12)).find("checkpoint") != std::string::npos);

  // Format 2 has no checksum: an altered vertex count is caught against the file length (it used
  // to allocate gigabytes), a wrong "next" index by the connectivity checks.
  std::string v2 = as_format_2(bytes, false);
  std::string huge = v2;
  const std::uint64_t count = std::uint64_t(1) << 30;
  std::memcpy(huge.data() + 24, &count, 8);
  CHECK(error_of(huge).find("corrupt checkpoint sizes") != std::string::npos);
  std::string wrong_next = v2;
  const std::size_t next_at = 48 + 42 * mesh.n_vertices() + 4;  // first edge record, first "next"
  std::int32_t next = 0;
  std::memcpy(&next, wrong_next.data() + next_at, 4);
  next = (next + 7) % std::int32_t(mesh.n_halfedges());
  std::memcpy(wrong_next.data() + next_at, &next, 4);
  CHECK(error_of(wrong_next).find("corrupt checkpoint") != std::string::npos);

  // Intact checksums over impossible content: refused as corrupt, not met later as an overflow or a
  // NaN time.
  CHECK(error_of(bytes_of(mesh, {.iteration = std::numeric_limits<int>::max(), .time = 0.5}, nullptr))
            .find("corrupt checkpoint: iteration 2147483647") != std::string::npos);
  CHECK(error_of(bytes_of(mesh, {.iteration = -3, .time = 0.5}, nullptr)).find("iteration -3") != std::string::npos);
  CHECK(error_of(bytes_of(mesh, {.iteration = 2, .time = std::nan("")}, nullptr)).find("time nan") != std::string::npos);
  CHECK(error_of(bytes_of(mesh, {.iteration = 2, .time = 1, .dt = -1}, nullptr)).find("step -1") != std::string::npos);
}

TEST_CASE("format 2 checkpoints (before the model state) and format 1 still load") {
  const SurfaceMesh mesh = evolved_plane();
  const Checkpoint c2 = parse(as_format_2(bytes_of(mesh, {.iteration = 4, .time = 0.2, .dt = 0.05}, nullptr), false));
  CHECK(c2.format == 2);
  CHECK(c2.run.iteration == 4);
  CHECK(c2.run.time == 0.2);
  CHECK(c2.run.dt == 0);  // not stored: the case's Δt applies
  CHECK_FALSE(c2.model);
  check_same_arrays(c2.mesh, mesh);

  // Format 1 (faces by corners), as the first bodyfit wrote them: one triangle, one tagged edge.
  std::string v1 = "BFCKPT01";
  auto put = [&](const auto& value) { v1.append(reinterpret_cast<const char*>(&value), sizeof value); };
  put(std::int64_t(3)), put(0.25), put(std::uint64_t(3)), put(std::uint64_t(1));
  const double corners[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (const auto& p : corners) {
    put(p[0]), put(p[1]), put(p[2]);
    put(std::int32_t(0)), put(char(0)), put(char(0)), put(-1.0);
  }
  put(std::int32_t(0)), put(std::int32_t(1)), put(std::int32_t(2)), put(std::int32_t(kInside));
  put(std::uint64_t(1));
  put(std::int32_t(0)), put(std::int32_t(1)), put(std::int32_t(10)), put(char(1)), put(char(0)), put(char(0));
  const Checkpoint c1 = parse(v1);
  CHECK(c1.format == 1);
  CHECK(c1.run.iteration == 3);
  CHECK(c1.mesh.n_faces() == 1);
  CHECK(c1.mesh.region(FaceHandle(0)) == kInside);
  std::size_t interface = 0;
  for (auto e : c1.mesh.edges()) interface += c1.mesh.interface(e);
  CHECK(interface == 1);
}

TEST_CASE("canonicalize gives the arrays a checkpoint reads back, without the round trip") {
  // A remeshed mesh straight out of the remesher (deleted elements, status bits set), not yet
  // canonical: canonicalize() must give exactly what decoding its checkpoint gives.
  CaseConfig config = parse_case(toml::parse(kPlane));
  CaseSetup setup = setup_case(config);
  SurfaceMesh mesh = setup.mesh;
  RemeshOptions options = setup.options.remesh;
  options.hmax *= 0.7;  // real work: splits, collapses, flips
  remesh(mesh, options);
  for (auto v : mesh.vertices()) mesh.status(v).set_tagged(true);  // a stage leaving flags behind
  canonicalize(mesh);
  const Checkpoint read = parse(bytes_of(mesh, {}, nullptr));
  check_same_arrays(mesh, read.mesh);
  CHECK_FALSE(mesh.status(*mesh.vertices().begin()).tagged());
}

// ---- the cadence of `bodyfit run` ------------------------------------------------------------

namespace {

/// The iterations `bodyfit -v run` took a checkpoint of, from its debug lines.
std::vector<int> checkpointed(const std::string& output) {
  static const std::regex line("checkpoint of iteration ([0-9]+):");
  std::vector<int> iterations;
  for (std::sregex_iterator it(output.begin(), output.end(), line), end; it != end; ++it)
    iterations.push_back(std::stoi((*it)[1]));
  return iterations;
}

/// history.csv without its wall-clock columns (ms_*), after checking that it has one row per
/// iteration 0..last, each exactly once and in order.
std::string history_rows(const std::filesystem::path& file, int last) {
  std::stringstream in(test::read_file(file)), out;
  std::vector<bool> keep;
  int expected = -1;
  for (std::string line; std::getline(in, line);) {
    std::stringstream cells(line);
    std::size_t c = 0;
    for (std::string cell; std::getline(cells, cell, ','); ++c) {
      if (keep.size() <= c) keep.push_back(cell.rfind("ms_", 0) != 0);  // from the header
      if (c == 0 && expected >= 0) CHECK(cell == std::to_string(expected));
      if (keep[c]) out << cell << ',';
    }
    out << '\n';
    ++expected;
  }
  CHECK(expected == last + 1);
  return out.str();
}

struct PlaneRun {
  test::TempDir dir{"checkpoint_cadence"};
  std::filesystem::path case_file = dir / "case.toml";
  PlaneRun() { std::ofstream(case_file) << kPlane << "\n[output]\nvtu_every = 0\n"; }
  test::CommandResult run(const std::string& out, const std::string& arguments) const {
    return test::run_bodyfit("-v run " + case_file.string() + " -o " + (dir / out).string() + " " + arguments);
  }
};

}  // namespace

TEST_CASE("checkpoint cadence: due every N iterations, every S seconds, both off") {
  test::TempDir dir("checkpoint_due");
  CheckpointWriter every3(dir / "a.bin", {.every = 3, .seconds = 0});
  std::vector<int> due;
  for (int n = 1; n <= 10; ++n)
    if (every3.due(n)) due.push_back(n);
  CHECK(due == std::vector<int>{3, 6, 9});
  CHECK(CheckpointWriter(dir / "b.bin", {.every = 0, .seconds = 1e-9}).due(1));
  CHECK_FALSE(CheckpointWriter(dir / "c.bin", {.every = 0, .seconds = 1e9}).due(1));
  CHECK_FALSE(CheckpointWriter(dir / "d.bin", {.every = 0, .seconds = 0}).due(1));
}

TEST_CASE("checkpoint writer: the snapshot is written in the background, one write at a time, bit-exactly") {
  test::TempDir dir("checkpoint_writer");
  const SurfaceMesh mesh = evolved_plane();
  ModelState state;
  state.version = 2;
  state.set("x", 0.1 + 0.2);
  CheckpointWriter writer(dir / "checkpoint.bin", {});
  CHECK(writer.last_iteration() == -1);
  CHECK(writer.snapshot(mesh, {.iteration = 4, .time = 0.5, .dt = 0.125}, &state) >= 0);
  writer.start();
  // The next snapshot waits for the write in flight, then reuses the buffer.
  writer.snapshot(mesh, {.iteration = 5, .time = 0.625, .dt = 0.125}, &state);
  CHECK(load_checkpoint(dir / "checkpoint.bin").run.iteration == 4);
  writer.start();
  writer.wait();
  CHECK(writer.last_iteration() == 5);
  const Checkpoint c = load_checkpoint(dir / "checkpoint.bin");
  CHECK(c.run.iteration == 5);
  CHECK(c.run.time == 0.625);
  REQUIRE(c.model);
  CHECK(*c.model == state);
  check_same_arrays(c.mesh, mesh);
  // The same bytes as the synchronous writer.
  CHECK(test::read_file(dir / "checkpoint.bin") == bytes_of(mesh, c.run, &state));
  // A failed write surfaces on the loop's next call.
  CheckpointWriter nowhere(dir / "missing" / "checkpoint.bin", {});
  nowhere.snapshot(mesh, {}, nullptr);
  nowhere.start();
  CHECK_THROWS_AS(nowhere.wait(), IoError);  // an output that cannot be written: exit code 6
}

TEST_CASE("bodyfit run: checkpoints at iterations N, 2N... and at the end, by seconds, only at the end") {
  PlaneRun plane;
  auto by_iterations = plane.run("every3", "--set time.iterations=7 --set output.checkpoint_every=3 "
                                           "--set output.checkpoint_seconds=0");
  REQUIRE_MESSAGE(by_iterations.exit_code == 0, by_iterations.output);
  CHECK(checkpointed(by_iterations.output) == std::vector<int>{0, 3, 6, 7});
  CHECK(load_checkpoint(plane.dir / "every3" / "checkpoint.bin").run.iteration == 7);

  auto every_iteration = plane.run("tiny", "--set time.iterations=4 --set output.checkpoint_seconds=1e-9");
  REQUIRE_MESSAGE(every_iteration.exit_code == 0, every_iteration.output);
  CHECK(checkpointed(every_iteration.output) == std::vector<int>{0, 1, 2, 3, 4});

  auto at_end = plane.run("huge", "--set time.iterations=4 --set output.checkpoint_seconds=1e9");
  REQUIRE_MESSAGE(at_end.exit_code == 0, at_end.output);
  CHECK(checkpointed(at_end.output) == std::vector<int>{0, 4});
  CHECK(load_checkpoint(plane.dir / "huge" / "checkpoint.bin").run.iteration == 4);

  // SIGINT between two checkpoints: the last completed iteration is checkpointed on the way out.
  auto interrupted = plane.run("int", "--set time.iterations=6 --set output.checkpoint_seconds=1e9 "
                                      "--inject-signal 3:INT:scheduled");
  CHECK_MESSAGE(interrupted.exit_code == 130, interrupted.output);
  CHECK(checkpointed(interrupted.output) == std::vector<int>{0, 3});
  CHECK(load_checkpoint(plane.dir / "int" / "checkpoint.bin").run.iteration == 3);

  auto bad = plane.run("bad", "--set output.checkpoint_every=-1");
  CHECK(bad.exit_code != 0);
  CHECK(bad.output.find("checkpoint_every") != std::string::npos);
}

TEST_CASE("a kill between two checkpoints, then --resume: the same final mesh, every history row once") {
  PlaneRun plane;
  const std::string common =
      "--set time.iterations=8 --set output.checkpoint_every=3 --set output.checkpoint_seconds=0";
  auto full = plane.run("full", common);
  REQUIRE_MESSAGE(full.exit_code == 0, full.output);

  auto killed = plane.run("part", common + " --inject-signal 5:KILL:scheduled");
  CHECK_MESSAGE(killed.exit_code == 128 + 9, killed.output);
  CHECK(load_checkpoint(plane.dir / "part" / "checkpoint.bin").run.iteration == 3);
  history_rows(plane.dir / "part" / "history.csv", 5);  // rows 4 and 5 are past the checkpoint

  auto resumed = plane.run("part", common + " --resume");
  REQUIRE_MESSAGE(resumed.exit_code == 0, resumed.output);
  CHECK(resumed.output.find("resuming from iteration 3") != std::string::npos);
  CHECK(checkpointed(resumed.output) == std::vector<int>{6, 8});
  CHECK(test::read_file(plane.dir / "part" / "final.mesh") == test::read_file(plane.dir / "full" / "final.mesh"));
  CHECK(test::read_file(plane.dir / "part" / "final.sol") == test::read_file(plane.dir / "full" / "final.sol"));
  CHECK(history_rows(plane.dir / "part" / "history.csv", 8) == history_rows(plane.dir / "full" / "history.csv", 8));
}
