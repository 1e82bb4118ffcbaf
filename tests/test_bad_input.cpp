// Bad input at every entry point: one row per probe — the command, the exit code it must
// end with (docs/reference/running.md, "Exit codes"), a fragment of its message, and the output that must
// not exist afterwards (or must, for MMG's spellings that are aliases). Every refusal by estimate
// (faces, sub-steps) happens before any heavy work, so the whole table runs in seconds.
#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/guards.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/remesh.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>
#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

using namespace bodyfit;
namespace fs = std::filesystem;

namespace {

struct Probe {
  std::string command;  ///< arguments of `bodyfit`; "{d}" stands for the fixtures' directory
  int exit_code;
  std::string message;  ///< a fragment of what bodyfit prints
  std::string output;   ///< relative to {d}: must not exist afterwards ("" for none)
  bool creates = false; ///< the output must exist instead (a successful alias)
};

void write_bytes(const fs::path& file, const std::string& bytes) {
  std::ofstream out(file, std::ios::binary);
  out << bytes;
}

std::string random_bytes(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::string bytes(n, '\0');
  for (char& c : bytes) c = char(rng() & 0xff);
  return bytes;
}

/// A Medit solution file of `dimension` components per vertex, written by hand (so it may hold
/// values the writer would not produce).
std::string sol_text(const std::vector<std::vector<double>>& values, int dimension) {
  std::string text = fmt::format("MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n{}\n1 {}\n", values.size(),
                                 dimension == 1 ? 1 : 2);
  for (const auto& v : values) {
    for (double x : v) text += fmt::format("{} ", x);
    text += "\n";
  }
  return text + "End\n";
}

/// A binary STL of `triangles` records whose header claims `claimed` and which is cut at `size` bytes.
std::string binary_stl(std::uint32_t claimed, std::uint32_t triangles, std::size_t size) {
  std::string bytes(80, ' ');
  bytes.replace(0, 10, "binary stl");
  bytes.append(reinterpret_cast<const char*>(&claimed), 4);
  for (std::uint32_t t = 0; t < triangles; ++t) {
    float record[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    record[3] = float(t);  // distinct triangles
    bytes.append(reinterpret_cast<const char*>(record), sizeof record);
    bytes.append(2, '\0');
  }
  bytes.resize(size, '\0');
  return bytes;
}

const char* kTetrahedron = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
const char* kTetrahedronFaces = "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";

/// The files the probes read, in `dir`.
void make_fixtures(const fs::path& dir) {
  SphereOptions sphere;
  sphere.faces = 320;
  const SurfaceMesh mesh = make_sphere(sphere);
  write_mesh(mesh, dir / "s.mesh");
  write_mesh(mesh, dir / "s.obj");
  fs::create_symlink("/dev/zero", dir / "zero.mesh");  // a device that never ends
  // Refs beyond 32 bits (4294967299 = 2^32 + 3 wrapped to 3: a face joined G silently).
  std::ofstream(dir / "wide_ref.mesh") << "MeshVersionFormatted 2\nDimension 3\nVertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 "
                                          "0\nTriangles\n1\n1 2 3 4294967299\nEnd\n";
  std::ofstream(dir / "wide_vertex_ref.mesh") << "MeshVersionFormatted 2\nDimension 3\nVertices\n3\n0 0 0 "
                                                 "-2147483649\n1 0 0 0\n0 1 0 0\nTriangles\n1\n1 2 3 0\nEnd\n";
  std::vector<std::vector<double>> phi, velocity, huge, phi_nan, velocity_nan;
  for (auto v : mesh.vertices()) {
    const Vec3 p = mesh.point(v);
    phi.push_back({p[2] - 0.3});
    velocity.push_back({-p[1], p[0], 0});
    huge.push_back({-1e200 * p[1], 1e200 * p[0], 0});
  }
  phi_nan = phi;
  phi_nan[7][0] = std::numeric_limits<double>::quiet_NaN();
  velocity_nan = velocity;
  velocity_nan[3][1] = std::numeric_limits<double>::infinity();
  write_bytes(dir / "phi.sol", sol_text(phi, 1));
  write_bytes(dir / "phi_nan.sol", sol_text(phi_nan, 1));
  write_bytes(dir / "v.sol", sol_text(velocity, 3));
  write_bytes(dir / "v_nan.sol", sol_text(velocity_nan, 3));
  write_bytes(dir / "v_huge.sol", sol_text(huge, 3));

  write_bytes(dir / "random.obj", random_bytes(4096, 1));
  write_bytes(dir / "random.stl", random_bytes(4096, 2));
  write_bytes(dir / "random.off", random_bytes(4096, 3));
  write_bytes(dir / "claims.stl", binary_stl(1000000, 2, 184));    // 10⁶ triangles claimed in 184 bytes
  write_bytes(dir / "truncated.stl", binary_stl(20, 20, 600));     // 1084 bytes cut at 600
  const std::string obj = test::read_file(dir / "s.obj");
  write_bytes(dir / "truncated.obj", obj.substr(0, obj.find("\nv ", obj.size() / 8)));  // within the vertices
  write_bytes(dir / "negative.off", "OFF\n-5 3 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  write_bytes(dir / "huge.off", "OFF\n4000000000 4000000000 0\n0 0 0\n");
  write_bytes(dir / "dup.obj", std::string(kTetrahedron) + "v 0 0 0\nf 1 3 2\nf 5 2 4\nf 2 3 4\nf 1 4 3\n");
  // Two triangles touching at one point, each with its own copy of it: merged, the point would join
  // two separate fans (not a surface), so the copies are kept apart, with a warning.
  write_bytes(dir / "touching.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 4 5 6\n");
  write_bytes(dir / "unused.obj", std::string(kTetrahedron) + "v 100 100 100\n" + kTetrahedronFaces);
  const std::string triangles = "Triangles\n4\n1 3 2 0\n1 2 4 0\n2 3 4 0\n1 4 3 0\nEnd\n";
  write_bytes(dir / "far.mesh", "MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 0\n1e300 0 0 0\n0 1 0 0\n"
                                "0 0 1 0\n" + triangles);
  write_bytes(dir / "unused.mesh", "MeshVersionFormatted 2\nDimension 3\nVertices\n5\n0 0 0 0\n1 0 0 0\n0 1 0 0\n"
                                   "0 0 1 0\n9 9 9 0\n" + triangles);
  write_bytes(dir / "big.asc", "ncols 20000\nnrows 20000\nxllcorner 0\nyllcorner 0\ncellsize 10\n1 2 3\n");
  write_bytes(dir / "bad.asc", "ncols 3\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 10\n1 2 3\n4 1e300 6\n7 8 9\n");
  write_bytes(dir / "case.toml", R"(
[surface]
generator = "sphere"
h = 0.2
[region]
shape = "cap"
axis = [0, 0, 1]
angle = 45
[model]
name = "conormal"
[time]
dt = 0.05
iterations = 1
[remesh]
hmax = 0.2
[output]
vtu_every = 0
png_every = 0
)");
  write_bytes(dir / "a_file", "not a directory");
  fs::create_directories(dir / "dir.mesh");  // an output name that is a directory
}

/// Run every probe; each failure names its command.
void run_probes(const std::string& name, const std::vector<Probe>& probes) {
  test::TempDir dir("bad_input_" + name);
  make_fixtures(dir.path());
  for (const auto& probe : probes) {
    std::string command = probe.command;
    for (std::size_t at; (at = command.find("{d}")) != std::string::npos;) command.replace(at, 3, dir.path().string());
    const fs::path output = probe.output.empty() ? fs::path() : dir / probe.output;
    std::error_code ignored;  // (an output "below" a regular file cannot exist, nor be removed)
    if (!output.empty()) fs::remove_all(output, ignored);
    const auto result = test::run_bodyfit(command);
    INFO("bodyfit " << command << "\n" << result.output);
    CHECK(result.exit_code == probe.exit_code);
    CHECK(result.output.find(probe.message) != std::string::npos);
    if (!output.empty()) CHECK(fs::exists(output, ignored) == probe.creates);
  }
}

const std::string kSphere = "{d}/s.mesh";
const std::string kAdvect = "advect {d}/s.mesh --phi {d}/phi.sol -o {d}/out.sol ";

}  // namespace

TEST_CASE("bad options of the stage commands are usage errors (exit 2) and write nothing") {
  const std::string remesh = "remesh " + kSphere + " -o {d}/out.mesh ";
  run_probes("options", {
      {remesh + "--hmax -1", 2, "--hmax", "out.mesh"},
      {remesh + "--hmax 0", 2, "--hmax", "out.mesh"},
      {remesh + "--hmax nan", 2, "not a finite number", "out.mesh"},
      {remesh + "--hmin 0.5 --hmax 0.1", 2, "exceeds --hmax", "out.mesh"},
      {remesh + "--hausd -1", 2, "--hausd", "out.mesh"},
      {remesh + "--hgrad 0.5", 2, "--hgrad", "out.mesh"},
      {remesh + "--passes -3", 2, "--passes", "out.mesh"},
      {remesh + "--angle inf", 2, "--angle", "out.mesh"},
      {remesh + "--bogus 1", 2, "--bogus", "out.mesh"},
      {"discretize " + kSphere + " --phi {d}/phi.sol -o {d}/out.mesh --hmax inf", 2, "--hmax", "out.mesh"},
      {"discretize " + kSphere + " --phi {d}/phi.sol -o {d}/out.mesh --snap nan", 2, "--snap", "out.mesh"},
      {kAdvect + "--velocity {d}/v.sol --time nan", 2, "--time", "out.sol"},
      {kAdvect + "--velocity {d}/v.sol --time -1", 2, "--time", "out.sol"},
      {kAdvect + "--velocity {d}/v.sol --time 1 --cells 0", 2, "--cells", "out.sol"},
      {"distance " + kSphere + " --phi {d}/phi.sol --narrow-band -1 -o {d}/out.sol", 2, "--narrow-band", "out.sol"},
      {"mesh sphere --faces 100 --radius nan -o {d}/out.mesh", 2, "--radius", "out.mesh"},
      {"mesh terrain --extent inf -o {d}/out.mesh", 2, "--extent", "out.mesh"},
      // Whole numbers: a negative one wrapped to 2^64 − n in an unsigned option ("no limit").
      {"--max-faces -5 " + remesh, 2, "'-5' is not a whole number", "out.mesh"},
      {"--max-faces 1e3 " + remesh, 2, "'1e3' is not a whole number", "out.mesh"},
      {"render " + kSphere + " -o {d}/out.png --azimuth nan", 2, "--azimuth", "out.png"},
      {"render " + kSphere + " -o {d}/out.png --elevation 120", 2, "--elevation", "out.png"},
      {"render " + kSphere + " -o {d}/out.png --size -5x3", 1, "--size '-5x3'", "out.png"},
  });
}

TEST_CASE("MMG's spellings are aliases on discretize and remesh, refused with the bodyfit option elsewhere") {
  run_probes("mmg", {
      {"remesh -in " + kSphere + " -hmax 0.5 -hausd 0.01 -hgrad 1.5 -nr -out {d}/out.mesh", 0, "remesh:", "out.mesh", true},
      {"discretize -in " + kSphere + " -sol {d}/phi.sol -ls -hmax 0.5 -out {d}/out.mesh", 0, "discretize:", "out.mesh",
       true},
      {"discretize -in " + kSphere + " -sol {d}/phi.sol -ls 0 -out {d}/out.mesh", 0, "discretize:", "out.mesh", true},
      {"discretize " + kSphere + " -sol {d}/phi.sol -ls 0.3 -out {d}/out.mesh", 2, "level set 0 only", "out.mesh"},
      {"remesh " + kSphere + " -ls -out {d}/out.mesh", 2, "bodyfit discretize", "out.mesh"},
      {"remesh " + kSphere + " -sol {d}/phi.sol -out {d}/out.mesh", 2, "size map", "out.mesh"},
      {"remesh " + kSphere + " -hsiz 0.1 -out {d}/out.mesh", 2, "--hmin and --hmax", "out.mesh"},
      {"remesh " + kSphere + " -noinsert -out {d}/out.mesh", 2, "not supported", "out.mesh"},
      {"remesh " + kSphere + " -hmax -1 -out {d}/out.mesh", 2, "--hmax", "out.mesh"},
      {"remesh " + kSphere + " -hmax=0.5 -out {d}/out.mesh", 0, "remesh:", "out.mesh", true},
      {"remesh " + kSphere + " -hmax=-1 -out {d}/out.mesh", 2, "--hmax", "out.mesh"},
      {"info " + kSphere + " -hmax=0.1", 2, "MMG's spelling", ""},
      {"remesh " + kSphere + " -hmaxx 0.5 -out {d}/out.mesh", 2, "unknown option (bodyfit's long options take two dashes",
       "out.mesh"},
      {"info " + kSphere + " -help", 2, "unknown option", ""},
      {"remesh -in " + kSphere, 2, "--output", ""},
      {"info " + kSphere + " -hmax 0.1", 2, "MMG's spelling", ""},
      {"distance -in " + kSphere + " --region 3 -o {d}/out.sol", 2, "MMG's spelling", "out.sol"},
  });
}

TEST_CASE("damaged, truncated or inconsistent files are input errors (exit 1) naming the file") {
  run_probes("files", {
      {"info {d}/random.obj", 1, "random.obj:", ""},
      {"info {d}/zero.mesh", 1, "zero.mesh: not a regular file, and still going after 1 GiB", ""},
      {"info {d}/wide_ref.mesh", 1, "wide_ref.mesh:10: the triangle ref 4294967299 does not fit in 32 bits", ""},
      {"info {d}/wide_vertex_ref.mesh", 1, "the vertex ref -2147483649 does not fit in 32 bits", ""},
      {"info {d}/random.stl", 1, "random.stl: binary STL: the header declares", ""},
      {"info {d}/random.off", 1, "not an OFF file", ""},
      {"info {d}/claims.stl", 1, "declares 1000000 triangles", ""},
      {"info {d}/truncated.stl", 1, "declares 20 triangles (1084 bytes), the file has 600", ""},
      {"info {d}/truncated.obj", 1, "no triangles", ""},
      {"info {d}/negative.off", 1, "'-5' is not a count", ""},
      {"info {d}/huge.off", 1, "declares 4000000000 vertices", ""},
      // A vertex written twice (a closed surface cut open along the copy): merged, as MMG and CGAL do.
      {"info {d}/dup.obj", 0, "1 vertices at the same point as an earlier one (vertex 5 is vertex 1, ...) merged", ""},
      {"info {d}/touching.obj", 0, "vertices 1 and 4 are at the same point (0, 0, 0), both on a boundary, and merging them would not give a surface", ""},
      {"info {d}/unused.obj", 1, "vertex 5 is not a corner of any triangle", ""},
      {"info {d}/unused.mesh", 1, "unused.mesh:9: vertex 5 is not a corner", ""},
      {"info {d}/far.mesh", 1, "far.mesh:6: vertex 2 (1e+300, 0, 0) is beyond", ""},
      {"mesh terrain --dem {d}/big.asc -o {d}/out.mesh", 1, "more values than the file's", "out.mesh"},
      {"mesh terrain --dem {d}/bad.asc -o {d}/out.mesh", 1, "not a terrain height", "out.mesh"},
      {"advect " + kSphere + " --phi {d}/phi_nan.sol --velocity {d}/v.sol --time 0.1 -o {d}/out.sol", 1,
       "vertex 8 has the value nan", "out.sol"},
      {kAdvect + "--velocity {d}/v_nan.sol --time 0.1", 1, "vertex 4 has the value inf", "out.sol"},
      {"discretize " + kSphere + " --phi {d}/phi_nan.sol -o {d}/out.mesh", 1, "every value must be finite", "out.mesh"},
      {"remesh {d}/missing.mesh -o {d}/out.mesh", 1, "missing.mesh: cannot open", "out.mesh"},
      {"discretize " + kSphere + " --phi {d}/missing.sol -o {d}/out.mesh", 1, "missing.sol: cannot open", "out.mesh"},
      {"run {d}/missing.toml -o {d}/out", 1, "missing.toml: cannot open", "out"},
      {"ensemble {d}/missing.toml -o {d}/out", 1, "missing.toml: cannot open", "out"},
      {"map {d}/missing_run -o {d}/out.png", 1, "missing_run", "out.png"},
      {"render {d}/missing.mesh -o {d}/out.png", 1, "missing.mesh", "out.png"},
      {"plot {d}/missing.csv --column ms_total -o {d}/out.png", 1, "missing.csv", "out.png"},
  });
}

TEST_CASE("sizes and work are estimated before starting and refused above the limits (exit 1)") {
  run_probes("budgets", {
      {"mesh sphere --faces 4000000000 -o {d}/out.mesh", 1, "about 4e+09 faces", "out.mesh"},
      {"--max-faces 100 mesh sphere --faces 320 -o {d}/out.mesh", 1, "above the limit of 100 faces", "out.mesh"},
      {"--max-faces 0 mesh sphere --faces 320 -o {d}/out.mesh", 0, "sphere:", "out.mesh", true},
      {"mesh terrain --extent 50000 --h 0.01 -o {d}/out.mesh", 1, "--max-faces", "out.mesh"},
      {"remesh " + kSphere + " --hmax 1e-5 -o {d}/out.mesh", 1, "above the limit", "out.mesh"},
      {"discretize " + kSphere + " --phi {d}/phi.sol --hmax 1e-5 -o {d}/out.mesh", 1, "above the limit", "out.mesh"},
      {kAdvect + "--velocity {d}/v_huge.sol --time 1", 1, "sub-steps", "out.sol"},
      {kAdvect + "--velocity {d}/v.sol --time 1e12", 1, "sub-steps", "out.sol"},
      {kAdvect + "--velocity {d}/v.sol --time 1 --cells 1e-9", 1, "sub-steps", "out.sol"},
      {kAdvect + "--velocity {d}/v.sol --time 1 --max-substeps 10", 1, "above the limit of 10", "out.sol"},
      // Without the estimate's limit, a speed that overflows loses every characteristic: a wrong
      // answer, so a numerical error (exit 5) and nothing written.
      {kAdvect + "--velocity {d}/v_huge.sol --time 1 --max-substeps 0", 5, "characteristics were lost", "out.sol"},
      // An hmin alone above the input's resolution coarsens (said, not silently clamped away).
      {"remesh " + kSphere + " --hmin 0.5 -o {d}/out.mesh", 0, "hmax raised to 0.5", "out.mesh", true},
  });
}

TEST_CASE("case values: non-finite, out of range or too big are input errors (exit 1) before any output") {
  const std::string run = "run {d}/case.toml -o {d}/out --set ";
  run_probes("case", {
      {run + "remesh.max_passes=-1", 1, "max_passes: -1 is out of range", "out/final.mesh"},
      {run + "time.dt=inf", 1, "dt: inf is not a finite number", "out/final.mesh"},
      {run + "time.dt=nan", 1, "is not a finite number", "out/final.mesh"},
      {run + "remesh.hgrad=0.5", 1, "hgrad: 0.5 is out of range", "out/final.mesh"},
      {run + "advection.max_cells_per_substep=-inf", 1, "not a finite number", "out/final.mesh"},
      {run + "surface.h=1e-5", 1, "[surface] h = 1e-05 on a sphere of radius 1: about", "out/final.mesh"},
      {run + "remesh.hmax=1e-5", 1, "[remesh] hmax = 1e-05: about", "out/final.mesh"},
      // The run's length in steps is estimated at set-up: too many is refused, not begun.
      {run + "time.iterations=100000000", 1, "[time] iterations = 100000000 is 1e+08 steps", "out/final.mesh"},
      {run + "time.max_steps=-1", 1, "max_steps: -1 is out of range", "out/final.mesh"},
      {run + "time.dt=1e6", 1, "sub-steps", "out/final.mesh"},
      {run + "time.dt=1e6 --set time.max_cfl=1 --overwrite", 1, "CFL sub-steps", "out/final.mesh"},
      {run + "time.dt=10 --set time.max_cfl=1 --set time.max_substeps=20 --overwrite", 1, "above the limit of 20", "out/final.mesh"},
  });
}

TEST_CASE("outputs that cannot be written are I/O errors (exit 6)") {
  run_probes("io", {
      {"mesh sphere --faces 100 -o {d}/no/such/dir/out.mesh", 6, "directory does not exist", "no"},
      {"mesh sphere --faces 100 -o {d}/dir.mesh", 6, "cannot rename", ""},
      {"run {d}/case.toml -o {d}/a_file/out", 6, "a_file", "a_file/out"},
  });
}

TEST_CASE("a remesh whose curvature sizes outgrow the face budget stops with an input error, not out of memory") {
  // hmax allows the input's faces (the budget checked before), a tiny hausd asks for ~10⁵.
  const SurfaceMesh sphere = make_sphere({.faces = 500});
  const std::size_t saved = max_faces();
  set_max_faces(3000);
  RemeshOptions options;
  options.hmax = 0.3;
  options.hmin = 1e-4;
  options.hausd = 1e-7;
  SurfaceMesh mesh = sphere;
  CHECK_NOTHROW(check_face_budget(estimate_remesh_faces(mesh, options), "remesh"));
  try {
    remesh(mesh, options);
    FAIL("the remesh grew beyond the budget");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()).find("remesh: the sizes the curvature and hausd ask for") == 0);
  }
  CHECK(mesh.n_faces() <= 3000);
  set_max_faces(saved);
}

TEST_CASE("the guards: face budget, finiteness, and the exit code of each class") {
  const std::size_t saved = max_faces();
  set_max_faces(1000);
  CHECK_NOTHROW(check_face_budget(1000, "a"));
  CHECK_THROWS_AS(check_face_budget(1001, "a"), InputError);
  CHECK_THROWS_AS(check_face_budget(std::numeric_limits<double>::infinity(), "a"), InputError);
  CHECK_THROWS_AS(check_face_budget(std::numeric_limits<double>::quiet_NaN(), "a"), InputError);
  try {
    check_face_budget(4e9, "mesh sphere");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()).find("mesh sphere: about 4e+09 faces (about 2.84 TB at 710 bytes per face), above "
                                     "the limit of 1000 faces") == 0);
  }
  set_max_faces(0);  // no limit
  CHECK_NOTHROW(check_face_budget(1e300, "a"));
  set_max_faces(saved);
  CHECK(default_max_faces() > 1000000);  // any machine that runs the tests holds a million faces
  CHECK(faces_for_edge_length(std::sqrt(3.0) / 4, 1) == doctest::Approx(1));

  const std::vector<double> fine{0, 1, -1e300}, bad{0, std::numeric_limits<double>::quiet_NaN(), 1};
  CHECK(find_non_finite(fine) == std::size_t(-1));
  CHECK(find_non_finite(bad) == 1);
  CHECK_NOTHROW(require_finite(fine, "x"));
  CHECK_THROWS_WITH_AS(require_finite(bad, "advect: phi"), "advect: phi: nan at vertex 2 (of 3)", NumericalError);
  const std::vector<Vec3> vectors{Vec3(0, 0, 0), Vec3(0, std::numeric_limits<double>::infinity(), 0)};
  CHECK_THROWS_AS(require_finite(vectors, "V"), NumericalError);

  CHECK(exit_code_of(InputError("")) == ExitCode::Input);
  CHECK(exit_code_of(PluginError("")) == ExitCode::Plugin);
  CHECK(exit_code_of(NumericalError("")) == ExitCode::Numerical);
  CHECK(exit_code_of(IoError("")) == ExitCode::Io);
  CHECK(exit_code_of(fs::filesystem_error("x", std::make_error_code(std::errc::permission_denied))) == ExitCode::Io);
  CHECK(exit_code_of(std::runtime_error("")) == ExitCode::Internal);
}
