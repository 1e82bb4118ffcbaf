// The thermal shape-optimisation plugin end to end (bodyfit run): J decreases at every accepted
// step (but a step the model flags as forced: one that raised J even at the shortest length, a jump
// of the discretisation), a step that raises J is rejected and retried with half the step, a
// resumed run continues exactly (objective history and Δt are model state), and bad input is a
// clear error.
#include "test_support.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

const char* kSphere = R"(
[surface]
generator = "sphere"
h = 0.15
[region]
shape = "cap"
axis = [0, 0, 1]
angle = 30
[model]
name = "thermal"
ell = 0.02
epsilon = 0.3
noise = 0.0        # strict Armijo: every accepted step decreases J
armijo = 0.5       # half the slope: the first step (dt = 0.4) falls 2.7 % short of it by the
                   # descent's curvature, not by noise, and is retried with dt = 0.2
[time]
dt = 0.4
iterations = 6     # short of the optimum (J 3.21 -> 0.44), where J's decrease is the cut's noise
[output]
vtu_every = 0
)";

using Table = std::vector<std::map<std::string, std::string>>;

Table read_csv(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  std::stringstream h(line);
  for (std::string cell; std::getline(h, cell, ',');) header.push_back(cell);
  Table rows;
  while (std::getline(in, line)) {
    std::stringstream cells(line);
    std::map<std::string, std::string> row;
    std::size_t c = 0;
    for (std::string cell; std::getline(cells, cell, ','); ++c) row[header.at(c)] = cell;
    rows.push_back(row);
  }
  return rows;
}

std::string write_case(const bodyfit::test::TempDir& dir, const std::string& text) {
  const auto file = dir / "case.toml";
  std::ofstream(file) << text;
  return file.string();
}

}  // namespace

TEST_CASE("thermal optimisation on a sphere: J decreases at every accepted step, rejected steps are retried "
          "with half the step, and a resume continues exactly") {
  bodyfit::test::TempDir dir("thermal_sphere");
  const std::string case_file = write_case(dir, kSphere);
  auto run = bodyfit::test::run_bodyfit("run " + case_file + " -o " + (dir / "full").string() +
                                        " --set model.volume_every=4");
  REQUIRE_MESSAGE(run.exit_code == 0, run.output);
  // The volume series: tetrahedra with the temperature inside, in a ParaView collection.
  CHECK(std::filesystem::exists(dir / "full" / "volume.pvd"));
  std::ifstream volume(dir / "full" / "volume_00004.vtu");
  std::stringstream vtu;
  vtu << volume.rdbuf();
  CHECK(vtu.str().find("Name=\"temperature\"") != std::string::npos);
  CHECK(vtu.str().find("NumberOfCells=") != std::string::npos);
  const Table rows = read_csv(dir / "full" / "history.csv");
  REQUIRE(rows.size() >= 5);
  double previous = std::nan("");
  int rejected = 0, forced = 0;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    CAPTURE(i);
    const double J = std::stod(rows[i].at("J"));
    const bool jump = rows[i].at("forced") == "1";
    if (i > 1 && !jump) CHECK(J < previous);  // strict Armijo with noise = 0
    forced += jump;
    previous = J;
    rejected += std::stoi(rows[i].at("rejections"));
    CHECK(std::stod(rows[i].at("tets")) > 100);
    CHECK(std::stod(rows[i].at("slope")) < 0);  // a descent direction
  }
  CHECK(rejected > 0);
  CHECK(forced <= 1);
  CHECK(run.output.find("rejected by model 'thermal'") != std::string::npos);
  // G grows first (cooling): the area of the first states increases.
  CHECK(std::stod(rows[2].at("area")) > std::stod(rows[0].at("area")));

  // Interrupted after 3 steps and resumed: the same J, steps and areas.
  auto part = bodyfit::test::run_bodyfit("run " + case_file + " -o " + (dir / "part").string() + " --inject-signal 3:INT");
  CHECK(part.exit_code == 130);
  auto rest = bodyfit::test::run_bodyfit("run " + case_file + " -o " + (dir / "part").string() + " --resume");
  REQUIRE_MESSAGE(rest.exit_code == 0, rest.output);
  const Table resumed = read_csv(dir / "part" / "history.csv");
  REQUIRE(resumed.size() == rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (const char* key : {"time", "dt", "area", "J", "step", "rejections"}) {
      CAPTURE(i);
      CAPTURE(key);
      CHECK(resumed[i].at(key) == rows[i].at(key));
    }
}

TEST_CASE("thermal model: bad input is a clear error") {
  bodyfit::test::TempDir dir("thermal_bad");
  const std::string case_file = write_case(dir, kSphere);
  int runs = 0;  // a run failing in compute leaves a resumable run: each in its own directory
  auto run = [&](const std::string& extra) {
    const std::string out = (dir / ("out" + std::to_string(runs++))).string();
    return bodyfit::test::run_bodyfit("run " + case_file + " -o " + out + " " + extra);
  };
  // ε ≤ 0.
  auto zero = run("--set model.epsilon=0");
  CHECK(zero.exit_code == 1);
  CHECK(zero.output.find("epsilon") != std::string::npos);
  auto negative = run("--set model.epsilon=-0.1");
  CHECK(negative.exit_code == 1);
  CHECK(negative.output.find("epsilon") != std::string::npos);
  // An open surface (a plane) bounds no volume.
  bodyfit::test::TempDir plane_dir("thermal_plane");
  const std::string plane_case = write_case(plane_dir, R"(
[surface]
generator = "plane"
size = 2.0
h = 0.2
[region]
shape = "disks"
centers = [[0.0, 0.0]]
radii = [0.5]
[model]
name = "thermal"
[time]
dt = 0.1
iterations = 2
)");
  auto open = bodyfit::test::run_bodyfit("run " + plane_case + " -o " + (plane_dir / "out").string());
  CHECK(open.exit_code == 1);
  CHECK_MESSAGE(open.output.find("not closed") != std::string::npos, open.output);
  // Γ_N covering all of S leaves no Robin part: the problem has no unique solution.
  auto neumann = run("--set model.neumann.boxes=[[-2,-2,-2,2,2,2,0.0]]");
  CHECK(neumann.exit_code == 1);
  CHECK_MESSAGE(neumann.output.find("covers all") != std::string::npos, neumann.output);
  // An unknown key, with a suggestion.
  auto typo = run("--set model.epsilom=0.1");
  CHECK(typo.exit_code == 1);
  CHECK(typo.output.find("did you mean 'epsilon'") != std::string::npos);
}
