// bodyfit ensemble: members sampled from their index alone, the reduction's rasters, the same
// bytes for any scheduling (sequential, threads, MPI ranks), restarts and failing members.
#include <bodyfit/app/config.hpp>
#include <bodyfit/app/ensemble.hpp>
#include <bodyfit/error.hpp>

#include "test_support.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <doctest/doctest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

using namespace bodyfit;
using bodyfit::test::read_file;
using bodyfit::test::run_bodyfit;
using bodyfit::test::TempDir;
namespace fs = std::filesystem;

namespace {

// A small procedural terrain (about 400 faces), a uniform wind, 4 steps of 2 minutes.
constexpr const char* kCase = R"(
[surface]
generator = "terrain"
extent = 1200.0
h = 100.0
seed = 3
max_height = 100.0
feature_size = 600.0

[region]
shape = "disks"
centers = [[600.0, 600.0]]
radii = [150.0]

[model]
name = "fire"
[model.wind]
type = "uniform"
speed = 3.0
direction_deg = 250.0
[model.arrival]
cell_size = 50.0

[time]
dt = 120.0
final_time = 480.0

[remesh]
hmax = 100.0

[output]
vtu_every = 0

[ensemble]
members = 5
seed = 11
[ensemble.region]
polygon = [[250.0, 250.0], [950.0, 250.0], [950.0, 950.0], [250.0, 950.0]]
radius = 150.0
[ensemble.sample]
"model.wind.speed" = {dist = "normal", mean = 3, sd = 1, min = 0}
"model.wind.direction_deg" = {dist = "uniform", min = 200, max = 250}
"model.R0" = {dist = "lognormal", mu = -0.92, sigma = 0.2}
)";

fs::path write_case(const TempDir& dir, const std::string& text = kCase) {
  const fs::path file = dir / "case.toml";
  std::ofstream(file) << text;
  return file;
}

/// The files an ensemble's outputs are compared by: the reduced rasters, the table, the members'.
std::vector<std::string> output_files(const fs::path& outdir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::recursive_directory_iterator(outdir))
    if (entry.is_regular_file()) names.push_back(fs::relative(entry.path(), outdir).string());
  std::sort(names.begin(), names.end());
  return names;
}

void require_identical(const fs::path& a, const fs::path& b) {
  const std::vector<std::string> files = output_files(a);
  REQUIRE(files == output_files(b));
  CHECK(std::find(files.begin(), files.end(), "burn_probability.asc") != files.end());
  for (const std::string& name : files) {
    INFO(name);
    CHECK(read_file(a / name) == read_file(b / name));
  }
}

struct Grid {
  std::size_t cols = 0, rows = 0;
  double nodata = -9999;
  std::vector<double> values;
};
Grid read_grid(const fs::path& file) {
  std::ifstream in(file);
  Grid g;
  std::string key;
  double x0, y0, cell;
  in >> key >> g.cols >> key >> g.rows >> key >> x0 >> key >> y0 >> key >> cell >> key >> g.nodata;
  g.values.resize(g.cols * g.rows);
  for (double& v : g.values) in >> v;
  REQUIRE(in);
  return g;
}

std::string ensemble(const fs::path& case_file, const fs::path& outdir, const std::string& extra = "") {
  const auto result = run_bodyfit(fmt::format("--threads 1 ensemble {} -o {} {}", case_file.string(), outdir.string(), extra));
  INFO(result.output);
  REQUIRE(result.exit_code == 0);
  return result.output;
}

}  // namespace

TEST_CASE("a member's scenario is a function of its index alone") {
  EnsembleSpec spec;
  spec.seed = 11;
  spec.parameters.push_back({.key = "model.R0", .distribution = SampledParameter::Distribution::LogNormal, .a = -0.9, .b = 0.2});
  spec.parameters.push_back({.key = "model.wind.speed", .distribution = SampledParameter::Distribution::Normal, .a = 3, .b = 1, .min = 0});
  PlacementDomain domain;
  domain.polygon = {{0, 0}, {100, 0}, {0, 100}};  // a triangle: some draws are rejected
  domain.xmax = domain.ymax = 100;
  domain.radius = 5;
  std::vector<MemberScenario> forward;
  for (std::size_t i = 0; i < 20; ++i) forward.push_back(sample_member(spec, domain, i));
  for (std::size_t i = 20; i-- > 0;) {  // backwards, and with more members in the spec
    spec.members = 1000;
    const MemberScenario again = sample_member(spec, domain, i);
    CHECK(again.overrides == forward[i].overrides);
    CHECK(again.x == forward[i].x);
    CHECK(again.y == forward[i].y);
  }
  for (const MemberScenario& s : forward) {
    REQUIRE(s.placed);
    CHECK(s.x + s.y <= 100);  // inside the triangle
    CHECK(s.values[0] > 0);   // lognormal
    CHECK(s.values[1] >= 0);  // truncated normal
  }
  CHECK(forward[0].x != forward[1].x);
  // Adding a parameter leaves the others' draws (each key has its own stream).
  spec.parameters.insert(spec.parameters.begin(), SampledParameter{.key = "model.A", .distribution = SampledParameter::Distribution::Uniform, .a = 1, .b = 2});
  const MemberScenario more = sample_member(spec, domain, 3);
  CHECK(more.values[1] == forward[3].values[0]);
  CHECK(more.values[2] == forward[3].values[1]);
  CHECK(more.x == forward[3].x);
  // Another seed, other draws.
  spec.seed = 12;
  CHECK(sample_member(spec, domain, 3).x != forward[3].x);
}

TEST_CASE("ensemble: probabilities are multiples of 1/N and the rasters reduce the members' arrival times") {
  TempDir dir("ensemble_reduce");
  const fs::path case_file = write_case(dir);
  ensemble(case_file, dir / "out");
  const Grid probability = read_grid(dir / "out/burn_probability.asc");
  const Grid mean = read_grid(dir / "out/arrival_mean.asc");
  const Grid p50 = read_grid(dir / "out/arrival_p50.asc");
  const Grid p90 = read_grid(dir / "out/arrival_p90.asc");
  std::vector<Grid> members;
  for (int i = 0; i < 5; ++i) members.push_back(read_grid(dir / fmt::format("out/members/m{:06d}.arrival_time.asc", i)));
  const std::size_t n = 5;
  std::size_t some = 0;
  for (std::size_t c = 0; c < probability.values.size(); ++c) {
    const double p = probability.values[c];
    REQUIRE(p >= 0);
    REQUIRE(p <= 1);
    const double k = std::round(p * double(n));
    REQUIRE(p == k / double(n));
    // The reduction of this cell, again from the members' rasters.
    std::vector<double> times;
    for (const Grid& m : members)
      if (m.values[c] != m.nodata) times.push_back(m.values[c]);
    REQUIRE(double(times.size()) == k);
    if (times.empty()) {
      CHECK(mean.values[c] == mean.nodata);
      continue;
    }
    ++some;
    double sum = 0;
    for (double t : times) sum += t;
    CHECK(mean.values[c] == sum / double(times.size()));
    std::sort(times.begin(), times.end());
    const double at = 0.5 * double(times.size() - 1);
    const std::size_t lo = std::size_t(at);
    const double median = times[lo] + (at - double(lo)) * (times[std::min(lo + 1, times.size() - 1)] - times[lo]);
    CHECK(p50.values[c] == median);
    CHECK(p90.values[c] >= p50.values[c]);
    CHECK(p90.values[c] <= times.back());
  }
  CHECK(some > 0);
  // The table: a row per member, all complete, with their sampled values.
  std::ifstream table(dir / "out/members.csv");
  std::string header;
  std::getline(table, header);
  CHECK(header ==
        "index,status,region_x,region_y,model.R0,model.wind.direction_deg,model.wind.speed,burnt_area_m2,"
        "final_time_s,iterations,stop,error");
  int rows = 0;
  for (std::string row; std::getline(table, row); ++rows) CHECK(row.starts_with(fmt::format("{},ok,", rows)));
  CHECK(rows == 5);
  // ros_mean: the mean of the members' rates of spread where they burnt a cell, so nothing above
  // the fastest rate any member burnt at (none at the ignition disks, burning at t = 0).
  const Grid ros = read_grid(dir / "out/ros_mean.asc");
  std::vector<Grid> rates;
  double fastest = 0;
  for (int i = 0; i < 5; ++i) {
    rates.push_back(read_grid(dir / fmt::format("out/members/m{:06d}.rate_of_spread.asc", i)));
    for (double r : rates.back().values)
      if (r != rates.back().nodata) fastest = std::max(fastest, r);
  }
  REQUIRE(fastest > 0);
  std::size_t with_rate = 0;
  for (std::size_t c = 0; c < ros.values.size(); ++c) {
    double sum = 0;
    int count = 0;
    for (const Grid& r : rates)
      if (r.values[c] != r.nodata) sum += r.values[c], ++count;
    if (count == 0) {
      CHECK(ros.values[c] == ros.nodata);
      continue;
    }
    ++with_rate;
    CHECK(ros.values[c] == doctest::Approx(sum / count).epsilon(1e-9));
    CHECK(ros.values[c] <= fastest);
  }
  CHECK(with_rate > 0);
}

TEST_CASE("ensemble on a DEM with NODATA: no combined value off the terrain, 0 where no member burnt") {
  // The shipped Luxembourg ensemble, 3 members of 20 minutes: the DEM's NODATA cells (outside the
  // country) are no terrain, so burn_probability has no value there, and 0 or more on the terrain.
  TempDir dir("ensemble_nodata");
  const fs::path case_file = test::source_path("meshes/cases/fire_luxembourg_ensemble.toml");
  ensemble(case_file, dir / "out", "--members 3 --set time.final_time=1200");
  const Grid probability = read_grid(dir / "out/burn_probability.asc");
  const Grid dem = read_grid(test::source_path("meshes/dem/luxembourg_elev_200m.asc"));
  REQUIRE(probability.cols == dem.cols);
  REQUIRE(probability.rows == dem.rows);
  // Away from the border: the terrain's mesh (edges of 400 m, two cells) covers the valid cells up
  // to an edge from it. A cell whose 3 × 3 block is all NODATA has no value; one whose 5 × 5 block
  // is all valid is on the terrain and has a probability.
  auto block = [&](std::size_t r, std::size_t c, std::size_t k, bool valid) {
    for (std::size_t i = r - k; i <= r + k; ++i)
      for (std::size_t j = c - k; j <= c + k; ++j)
        if ((dem.values[i * dem.cols + j] != dem.nodata) != valid) return false;
    return true;
  };
  std::size_t off = 0, on = 0, burnt = 0;
  for (std::size_t r = 2; r + 2 < dem.rows; ++r)
    for (std::size_t c = 2; c + 2 < dem.cols; ++c) {
      const double p = probability.values[r * dem.cols + c];
      if (block(r, c, 1, false)) {
        ++off;
        CHECK(p == probability.nodata);
      } else if (block(r, c, 2, true)) {
        ++on;
        CHECK(p >= 0);
        CHECK(p <= 1);
        burnt += p > 0;
      }
    }
  CHECK(off > 1000);
  CHECK(on > 1000);
  CHECK(burnt > 0);
}

TEST_CASE("ensemble: the same bytes sequentially, on 2 threads, and from the index alone") {
  TempDir dir("ensemble_schedules");
  const fs::path case_file = write_case(dir);
  ensemble(case_file, dir / "sequential");
  ensemble(case_file, dir / "threads", "--jobs 2");
  require_identical(dir / "sequential", dir / "threads");
  // Members 0-2 of a 3-member ensemble are those of the 5-member one.
  ensemble(case_file, dir / "three", "--members 3");
  for (int i = 0; i < 3; ++i)
    for (const char* ext : {".arrival_time.asc", ".rate_of_spread.asc", ".toml"}) {
      const std::string name = fmt::format("members/m{:06d}{}", i, ext);
      INFO(name);
      CHECK(read_file(dir / "three" / name) == read_file(dir / "sequential" / name));
    }
}

TEST_CASE("ensemble: a restart recomputes only the members whose results are missing") {
  TempDir dir("ensemble_restart");
  const fs::path case_file = write_case(dir);
  ensemble(case_file, dir / "full");
  fs::copy(dir / "full", dir / "restart", fs::copy_options::recursive);
  for (int i : {1, 3}) {
    REQUIRE(fs::remove(dir / fmt::format("restart/members/m{:06d}.toml", i)));
    REQUIRE(fs::remove(dir / fmt::format("restart/members/m{:06d}.arrival_time.asc", i)));
  }
  fs::remove(dir / "restart/members/m000004.toml");  // a member killed before its record: it runs again
  fs::remove(dir / "restart/burn_probability.asc");
  const std::string log = ensemble(case_file, dir / "restart");
  CHECK(log.find("2 members already complete, 3 to run") != std::string::npos);
  CHECK(log.find("member 0:") == std::string::npos);
  CHECK(log.find("member 1:") != std::string::npos);
  require_identical(dir / "full", dir / "restart");
  // Another case in that directory is refused.
  const auto other = run_bodyfit(fmt::format("ensemble {} -o {} --seed 12", case_file.string(), (dir / "full").string()));
  CHECK(other.exit_code == 1);
  CHECK(other.output.find("holds an ensemble of another case") != std::string::npos);
}

TEST_CASE("ensemble: a data file edited before a continuation is another case") {
  // The wind as a series file: its digest is part of the ensemble's recorded case.
  TempDir dir("ensemble_inputs");
  std::string text = kCase;
  const std::string uniform = "type = \"uniform\"\nspeed = 3.0\ndirection_deg = 250.0";
  text.replace(text.find(uniform), uniform.size(), "type = \"series\"\nfile = \"wind.csv\"");
  // The sampled wind keys do not exist with a series: sample R0 alone.
  text.erase(text.find("\"model.wind.speed\""), text.find("\"model.R0\"") - text.find("\"model.wind.speed\""));
  std::ofstream(dir / "wind.csv") << "time,speed,direction_deg\n0,3,250\n480,4,240\n";
  const fs::path case_file = write_case(dir, text);
  ensemble(case_file, dir / "run", "--members 2");
  CHECK(read_file(dir / "run" / "ensemble_case.toml").find("model.wind.file") != std::string::npos);
  ensemble(case_file, dir / "run", "--members 3");  // the same inputs: continued
  std::ofstream(dir / "wind.csv") << "time,speed,direction_deg\n0,3,250\n480,5,240\n";
  const auto edited = run_bodyfit(fmt::format("ensemble {} -o {} --members 4", case_file.string(), (dir / "run").string()));
  CHECK(edited.exit_code == 1);
  CHECK_MESSAGE(edited.output.find("input_files.model.wind.file") != std::string::npos, edited.output);
}

TEST_CASE("ensemble: killed (SIGKILL) at any point, the same command completes it with the same bytes") {
  TempDir dir("ensemble_killed");
  const fs::path case_file = write_case(dir);
  ensemble(case_file, dir / "full", "--members 8");
  // Killed after 0.3, 0.6 and 0.9 s (wherever that lands: setting up, in a member, writing a
  // record, reducing), each time continued by the same command until it completes.
  for (const char* after : {"0.3", "0.6", "0.9"}) {
    const std::string command = fmt::format("timeout -s KILL {} \"{}\" --threads 1 ensemble {} -o {} --members 8 > {} 2>&1",
                                            after, BODYFIT_EXE, case_file.string(), (dir / "killed").string(),
                                            (dir / "killed.log").string());
    const int status = std::system(command.c_str());
    INFO(read_file(dir / "killed.log"));
    CHECK(status != -1);
  }
  ensemble(case_file, dir / "killed", "--members 8");
  // The leftovers of killed members (their .work directories, temporaries) are gone.
  for (const auto& entry : fs::directory_iterator(dir / "killed/members")) {
    INFO(entry.path().string());
    CHECK(entry.path().extension() != ".work");
    CHECK(entry.path().filename().string().find(".tmp") == std::string::npos);
  }
  require_identical(dir / "full", dir / "killed");
}

TEST_CASE("ensemble: a failing member is recorded with its error and the others complete") {
  TempDir dir("ensemble_failures");
  // Ignitions over a box twice the terrain's: centres are drawn on the terrain only, so no member
  // misses the surface; the injected failure is the one failing member.
  std::string text = kCase;
  const std::string polygon = "polygon = [[250.0, 250.0], [950.0, 250.0], [950.0, 950.0], [250.0, 950.0]]";
  text.replace(text.find(polygon), polygon.size(), "polygon = [[-1200.0, 0.0], [1200.0, 0.0], [1200.0, 1200.0], [-1200.0, 1200.0]]");
  const fs::path case_file = write_case(dir, text);
  const auto result = run_bodyfit(
      fmt::format("--threads 1 ensemble {} -o {} --members 8 --inject-failure 2", case_file.string(), (dir / "out").string()));
  INFO(result.output);
  REQUIRE(result.exit_code == 0);
  std::ifstream table(dir / "out/members.csv");
  std::string row;
  std::getline(table, row);
  int ok = 0;
  for (int i = 0; std::getline(table, row); ++i) {
    INFO(row);
    if (i == 2) {
      CHECK(row.starts_with("2,failed,"));
      CHECK(row.find("numerical error: injected failure") != std::string::npos);
    } else {
      CHECK(row.find(",failed,") == std::string::npos);
      const double x = std::stod(row.substr(row.find(",ok,") + 4));
      CHECK(x >= 0);  // on the terrain [0, 1200]², not in the half of the box beside it
      CHECK(x <= 1200);
      ++ok;
    }
  }
  REQUIRE(ok > 0);
  // The probability counts the completed members.
  const Grid probability = read_grid(dir / "out/burn_probability.asc");
  for (double p : probability.values) REQUIRE(p == std::round(p * ok) / ok);
}

TEST_CASE("ensemble: a grid whose frame differs from another process's first member stops at the first member") {
  // The ranks of an MPI ensemble share the output directory: the first member any of them finishes
  // publishes its grids' frames there (frames/NAME.frame), and a rank whose first member's grid
  // differs stops then, not at the reduction after every member ran. Here another process published
  // a frame of other cells.
  TempDir dir("ensemble_frames");
  const fs::path case_file = write_case(dir);
  fs::create_directories(dir / "out" / "frames");
  std::ofstream(dir / "out" / "frames" / "arrival_time.frame") << "7 5 123.5 0 0 17\n";
  const auto result =
      run_bodyfit(fmt::format("--threads 1 ensemble {} -o {} --members 40", case_file.string(), (dir / "out").string()));
  INFO(result.output);
  CHECK(result.exit_code == 1);
  CHECK(result.output.find("members 17 and 0: their 'arrival_time' grids differ (7 × 5 cells of 123.5") !=
        std::string::npos);
  std::size_t grids = 0;
  for (const auto& entry : fs::directory_iterator(dir / "out" / "members"))
    grids += entry.path().filename().string().find("arrival_time") != std::string::npos;
  CHECK(grids == 0);
  // A frame file that is not one is named with what it should hold.
  std::ofstream(dir / "out" / "frames" / "arrival_time.frame") << "seven\n";
  const auto damaged =
      run_bodyfit(fmt::format("--threads 1 ensemble {} -o {} --members 40", case_file.string(), (dir / "out").string()));
  CHECK(damaged.exit_code == 6);  // the output directory's problem (an I/O error)
  CHECK_MESSAGE(damaged.output.find("arrival_time.frame:1: expected the frame of a grid") != std::string::npos,
                damaged.output);
  // A complete ensemble leaves no frames behind (its files are the same bytes however it ran).
  fs::remove_all(dir / "out");
  ensemble(case_file, dir / "out", "--members 2");
  CHECK(!fs::exists(dir / "out" / "frames"));
}

TEST_CASE("ensemble: under MPI, 1 and 2 ranks give the sequential bytes") {
  if constexpr (!config::have_mpi) {
    MESSAGE("built without MPI: skipped");
    return;
  }
#ifdef BODYFIT_MPIEXEC
  TempDir dir("ensemble_mpi");
  const fs::path case_file = write_case(dir);
  ensemble(case_file, dir / "sequential");
  for (int ranks : {1, 2}) {
    const fs::path out = dir / fmt::format("np{}", ranks);
    // Open MPI leaks by design at MPI_Finalize, in components it loads and unloads itself (no
    // stack to suppress): under the sanitize stage, leak detection is off for these ranks only.
    const std::string command = fmt::format(
        "ASAN_OPTIONS=\"${{ASAN_OPTIONS:-}}:detect_leaks=0\" {} {} --oversubscribe -np {} \"{}\" --threads 1 "
        "ensemble {} -o {} > {} 2>&1",
        BODYFIT_MPIEXEC,
        geteuid() == 0 ? "--allow-run-as-root" : "", ranks, BODYFIT_EXE, case_file.string(), out.string(),
        (dir / fmt::format("np{}.log", ranks)).string());
    const int status = std::system(command.c_str());
    INFO(read_file(dir / fmt::format("np{}.log", ranks)));
    REQUIRE(status == 0);
    // Every rank joined the job (the log names the last one).
    CHECK(read_file(dir / fmt::format("np{}.log", ranks)).find(fmt::format("[rank {}/{}]", ranks - 1, ranks)) !=
          std::string::npos);
    require_identical(dir / "sequential", out);
  }
#endif
}

TEST_CASE("ensemble: a choice among values of any kind, with weights (a wind height, a moisture scenario)") {
  test::TempDir dir("ensemble_choice");
  std::ofstream(dir / "case.toml") << R"([surface]
generator = "plane"
[region]
shape = "disks"
centers = [[0.0, 0.0]]
radii = [0.1]
[model]
name = "fire"
[ensemble]
members = 200
[ensemble.sample]
"model.wind.height" = {dist = "choice", values = ["midflame", "20ft", "10m"], weights = [2, 1, 1]}
"model.u0" = {dist = "choice", values = [30.0, 40.0]}
)";
  const EnsembleSpec spec = read_ensemble_spec(dir / "case.toml", {});
  REQUIRE(spec.parameters.size() == 2);
  PlacementDomain domain;
  domain.xmax = domain.ymax = 1;
  std::map<std::string, int> heights;
  int thirty = 0;
  for (std::size_t i = 0; i < spec.members; ++i) {
    const MemberScenario s = sample_member(spec, domain, i);
    REQUIRE(s.overrides.size() == 3);  // the region, then the parameters in key order
    for (const std::string& o : s.overrides)
      if (o.starts_with("model.wind.height=")) ++heights[o];
    thirty += s.overrides[1] == "model.u0=30.0";
    CHECK((s.overrides[1] == "model.u0=30.0" || s.overrides[1] == "model.u0=40.0"));
  }
  // Weights 2:1:1 over 200 members, equal weights over two values (binomial: ±4 sd).
  CHECK(heights.size() == 3);
  CHECK(std::abs(heights["model.wind.height='midflame'"] - 100) < 29);
  CHECK(std::abs(heights["model.wind.height='20ft'"] - 50) < 25);
  CHECK(std::abs(thirty - 100) < 29);
  // Bad choices: no values, a table among them, weights of another length.
  auto error_of = [&](const std::string& sample) {
    std::ofstream(dir / "bad.toml") << "[surface]\ngenerator = \"plane\"\n[model]\nname = \"fire\"\n[ensemble.sample]\n" << sample;
    try {
      read_ensemble_spec(dir / "bad.toml", {});
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(error_of("\"model.u0\" = {dist = \"choice\"}\n").find("expected a non-empty array") != std::string::npos);
  CHECK(error_of("\"model.u0\" = {dist = \"choice\", values = [{a = 1}]}\n").find("expected strings, numbers or booleans") != std::string::npos);
  CHECK(error_of("\"model.u0\" = {dist = \"choice\", values = [1.0, 2.0], weights = [1.0]}\n") != "no error");
  CHECK(error_of("\"model.u0\" = {dist = \"choice\", values = [1.0, 2.0], weights = [0.0, 0.0]}\n").find("positive sum") != std::string::npos);
}

TEST_CASE("ensemble: sampling only a fuel moisture gives members of different areas, a fixed one equal areas") {
  // Rothermel's GR2 on flat ground: where a member's fire starts does not change its area, what it
  // burns with does.
  const std::string base = R"([surface]
generator = "plane"
size = 1200.0
h = 40.0
[region]
shape = "disks"
centers = [[0.0, 0.0]]
radii = [60.0]
[model]
name = "fire"
spread = "rothermel"
[model.fuel]
model = "GR2"
[model.wind]
type = "uniform"
speed = 3.0
direction_deg = 270.0
height = "20ft"
[model.arrival]
cell_size = 40.0
[time]
dt = 300.0
final_time = 1200.0
[output]
vtu_every = 0
[ensemble]
members = 4
seed = 5
[ensemble.region]
polygon = [[-200.0, -200.0], [200.0, -200.0], [200.0, 200.0], [-200.0, 200.0]]
radius = 60.0
[model.moisture]
dead_10h = 7.0
dead_100h = 8.0
live_herb = 60.0
live_woody = 90.0
)";
  auto areas = [&](const std::string& name, const std::string& more) {
    TempDir dir(name);
    const fs::path file = write_case(dir, base + more);
    ensemble(file, dir / "out");
    const std::vector<double> result = test::csv_column(dir / "out/members.csv", "burnt_area_m2");
    REQUIRE(result.size() == 4);
    return result;
  };
  // dead_1h given in the case: every member burns the same area, wherever it starts (to the
  // remesher's noise).
  const std::vector<double> fixed = areas("ensemble_moisture_fixed", "dead_1h = 6.0\n");
  for (double a : fixed) CHECK(a == doctest::Approx(fixed[0]).epsilon(0.01));
  // dead_1h sampled from 3 % to 12 %: the areas spread.
  const std::vector<double> sampled =
      areas("ensemble_moisture_sampled", "[ensemble.sample]\n\"model.moisture.dead_1h\" = {dist = \"uniform\", min = 3.0, max = 12.0}\n");
  const auto [lo, hi] = std::minmax_element(sampled.begin(), sampled.end());
  CHECK(*hi > 1.2 * *lo);
}

TEST_CASE("ensemble: members whose grids differ stop the ensemble as soon as two have finished, naming both") {
  TempDir dir("ensemble_grids_differ");
  // The arrival grid's cell size sampled: every member's grid has other cells. Two threads run the
  // members; the second to finish stops them, long before the 40 members ran.
  std::string text = kCase;
  const std::string sample = "\"model.R0\" = {dist = \"lognormal\", mu = -0.92, sigma = 0.2}";
  text.replace(text.find(sample), sample.size(),
               sample + "\n\"model.arrival.cell_size\" = {dist = \"uniform\", min = 40, max = 60}");
  const fs::path case_file = write_case(dir, text);
  const auto result = run_bodyfit(
      fmt::format("--threads 2 ensemble {} -o {} --members 40 --jobs 2", case_file.string(), (dir / "out").string()));
  INFO(result.output);
  CHECK(result.exit_code == 1);
  CHECK(result.output.find("their 'arrival_time' grids differ") != std::string::npos);
  CHECK(result.output.find("the grid depends on a sampled parameter") != std::string::npos);
  std::size_t grids = 0;  // written by the members that finished with the first one's frame
  for (const auto& entry : fs::directory_iterator(dir / "out" / "members"))
    grids += entry.path().filename().string().find("arrival_time") != std::string::npos;
  CHECK(grids < 10);
}
