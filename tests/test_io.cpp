// File formats: round trips (bit-exact), MMG-style fixtures, hand-encoded binary files and every
// kind of bad input (each error must name the file and the line or byte offset).
#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <numbers>
#include <sstream>
#include <string>

using namespace bodyfit;
using bodyfit::test::TempDir;
namespace fs = std::filesystem;

namespace {

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The message of the InputError thrown by f ("" when nothing is thrown).
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// Files left in a directory (the writers' temporaries included).
std::size_t files_in(const fs::path& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++n;
  return n;
}

/// A sphere with every property set to something non-trivial and deterministic.
SurfaceMesh tagged_sphere(std::size_t faces) {
  SurfaceMesh mesh = make_sphere({.faces = faces});
  std::mt19937 rng(7);
  for (auto v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    mesh.phi(v) = p[2] - 0.1;
    mesh.vertex_ref(v) = int(rng() % 3);
    mesh.corner(v) = rng() % 7 == 0;
    mesh.required(v) = rng() % 5 == 0;
  }
  label_regions_from_phi(mesh);
  for (auto e : mesh.edges()) {
    if (mesh.interface(e)) continue;
    mesh.edge_ref(e) = rng() % 4 == 0 ? int(1 + rng() % 5) : 0;
    mesh.ridge(e) = rng() % 6 == 0;
    mesh.required(e) = rng() % 8 == 0;
  }
  return mesh;
}

/// Same vertices (bit-exact), same faces in the same order, same refs and tags.
/// With a tolerance > 0, coordinates may differ by that much (formats read in single precision).
void check_identical(const SurfaceMesh& a, const SurfaceMesh& b, bool with_tags, double tolerance = 0) {
  REQUIRE(a.n_vertices() == b.n_vertices());
  REQUIRE(a.n_faces() == b.n_faces());
  for (auto v : a.vertices()) {
    auto w = VertexHandle(v.idx());
    for (int k = 0; k < 3; ++k) {
      if (tolerance > 0)
        REQUIRE(std::abs(a.point(v)[k] - b.point(w)[k]) <= tolerance);
      else
        REQUIRE(std::memcmp(&a.point(v)[k], &b.point(w)[k], sizeof(double)) == 0);
    }
    if (with_tags) {
      CHECK(a.vertex_ref(v) == b.vertex_ref(w));
      CHECK(a.corner(v) == b.corner(w));
      CHECK(a.required(v) == b.required(w));
    }
  }
  for (auto f : a.faces()) {
    auto g = FaceHandle(f.idx());
    std::vector<int> va, vb;
    for (auto v : a.fv_range(f)) va.push_back(v.idx());
    for (auto v : b.fv_range(g)) vb.push_back(v.idx());
    REQUIRE(va == vb);
    if (with_tags) CHECK(a.region(f) == b.region(g));
  }
  if (!with_tags) return;
  for (auto e : a.edges()) {
    auto h = a.halfedge_handle(e, 0);
    auto hb = b.find_halfedge(VertexHandle(a.from_vertex_handle(h).idx()), VertexHandle(a.to_vertex_handle(h).idx()));
    REQUIRE(hb.is_valid());
    auto eb = b.edge_handle(hb);
    CHECK(a.interface(e) == b.interface(eb));
    CHECK(a.ridge(e) == b.ridge(eb));
    CHECK(a.required(e) == b.required(eb));
    CHECK((a.interface(e) ? kInterfaceRef : a.edge_ref(e)) == b.edge_ref(eb));
  }
}

// ------------------------------------------------------------------------------------------
// A GMF binary encoder written independently of the library, one field at a time.

struct GmfEncoder {
  int version;
  bool big_endian = false;
  std::string bytes;

  template <class T>
  void put(T value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    if (big_endian) std::reverse(raw, raw + sizeof(T));
    bytes.append(raw, sizeof(T));
  }
  void integer(std::int64_t i) {
    if (version >= 4)
      put<std::int64_t>(i);
    else
      put<std::int32_t>(std::int32_t(i));
  }
  void real(double x) {
    if (version == 1)
      put<float>(float(x));
    else
      put<double>(x);
  }
  /// Keyword code and a placeholder position, patched by the next keyword.
  void keyword(int code) {
    patch_previous();
    put<std::int32_t>(code);
    position_at = bytes.size();
    if (version >= 3)
      put<std::int64_t>(0);
    else
      put<std::int32_t>(0);
  }
  void patch_previous() {
    if (position_at == 0) return;
    GmfEncoder patch{version, big_endian, {}};
    if (version >= 3)
      patch.put<std::int64_t>(std::int64_t(bytes.size()));
    else
      patch.put<std::int32_t>(std::int32_t(bytes.size()));
    bytes.replace(position_at, patch.bytes.size(), patch.bytes);
  }
  void end() {
    keyword(54);
    position_at = 0;  // End's own next position stays 0
  }
  std::size_t position_at = 0;
};

/// The octahedron of the fixture, as a GMF binary of the given version (with a Normals
/// section to skip).
std::string octahedron_meshb(int version, bool big_endian) {
  GmfEncoder g{version, big_endian, {}};
  g.put<std::int32_t>(1);
  g.put<std::int32_t>(version);
  g.keyword(3);
  g.put<std::int32_t>(3);
  const double points[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  g.keyword(4);
  g.integer(6);
  for (int i = 0; i < 6; ++i) {
    for (double x : points[i]) g.real(x);
    g.integer(i == 1 ? 4 : 0);
  }
  g.keyword(60);  // Normals: skipped
  g.integer(1);
  for (int k = 0; k < 3; ++k) g.real(1.0);
  const int triangles[8][4] = {{1, 3, 5, 3}, {3, 2, 5, 3}, {2, 4, 5, 3}, {4, 1, 5, 3},
                               {3, 1, 6, 2}, {2, 3, 6, 2}, {4, 2, 6, 2}, {1, 4, 6, 2}};
  g.keyword(6);
  g.integer(8);
  for (const auto& t : triangles)
    for (int i : t) g.integer(i);
  g.keyword(5);
  g.integer(2);
  for (int i : {1, 3, 10, 1, 5, 7}) g.integer(i);
  g.keyword(14);  // Ridges
  g.integer(1);
  g.integer(2);
  g.keyword(13);  // Corners
  g.integer(1);
  g.integer(5);
  g.end();
  return g.bytes;
}

EdgeHandle edge_between(const SurfaceMesh& mesh, int a, int b) {
  auto h = mesh.find_halfedge(VertexHandle(a - 1), VertexHandle(b - 1));
  REQUIRE(h.is_valid());
  return mesh.edge_handle(h);
}

void check_fixture_octahedron(const SurfaceMesh& mesh, bool full_tags) {
  REQUIRE(mesh.n_vertices() == 6);
  REQUIRE(mesh.n_faces() == 8);
  for (int f = 0; f < 8; ++f) CHECK(mesh.region(FaceHandle(f)) == (f < 4 ? kInside : kOutside));
  CHECK(mesh.vertex_ref(VertexHandle(1)) == 4);
  int interfaces = 0;
  for (auto e : mesh.edges()) interfaces += mesh.interface(e);
  CHECK(interfaces == 4);
  for (auto [a, b] : {std::pair{1, 3}, {3, 2}, {2, 4}, {4, 1}}) {
    CHECK(mesh.interface(edge_between(mesh, a, b)));
    CHECK(mesh.edge_ref(edge_between(mesh, a, b)) == kInterfaceRef);
  }
  if (!full_tags) return;
  CHECK(mesh.edge_ref(edge_between(mesh, 1, 5)) == 7);
  CHECK(mesh.ridge(edge_between(mesh, 1, 5)));
  CHECK(mesh.corner(VertexHandle(4)));
}

}  // namespace

// ------------------------------------------------------------------------------------------

TEST_CASE("MMG-style .mesh fixture: every section read and mapped onto the mesh properties") {
  auto mesh = read_mesh(test::source_path("meshes/fixtures/mmgs_octahedron.mesh"));
  check_fixture_octahedron(mesh, true);
  CHECK(mesh.required(edge_between(mesh, 3, 2)));
  int ridges = 0, required_edges = 0, corners = 0, required_vertices = 0;
  for (auto e : mesh.edges()) ridges += mesh.ridge(e), required_edges += mesh.required(e);
  for (auto v : mesh.vertices()) corners += mesh.corner(v), required_vertices += mesh.required(v);
  CHECK(ridges == 1);
  CHECK(required_edges == 1);
  CHECK(corners == 2);
  CHECK(mesh.corner(VertexHandle(5)));
  CHECK(required_vertices == 1);
  CHECK(mesh.required(VertexHandle(0)));
  CHECK(mesh.point(VertexHandle(1)) == Vec3(-1, 0, 0));
}

TEST_CASE("compact .mesh (keywords and numbers on shared lines, comments): interface derived from the regions") {
  auto mesh = read_mesh(test::source_path("meshes/fixtures/mmgs_octahedron_compact.mesh"));
  check_fixture_octahedron(mesh, false);
}

TEST_CASE("hand-encoded .meshb of every GMF version and both byte orders") {
  TempDir dir("io-meshb");
  for (int version = 1; version <= 4; ++version)
    for (bool big_endian : {false, true}) {
      CAPTURE(version);
      CAPTURE(big_endian);
      auto file = dir / "octa.meshb";
      write_text(file, octahedron_meshb(version, big_endian));
      auto mesh = read_mesh(file);
      check_fixture_octahedron(mesh, true);
      CHECK(mesh.ridge(edge_between(mesh, 1, 5)));
    }
}

TEST_CASE("round trip .mesh and .meshb: bit-exact points, same faces, refs and tags") {
  TempDir dir("io-roundtrip");
  auto mesh = tagged_sphere(3000);
  // Coordinates that need all 17 digits.
  mesh.point(VertexHandle(0)) *= (1.0 + std::numeric_limits<double>::epsilon());
  mesh.point(VertexHandle(1))[0] = 0.1 + 0.2;
  for (const char* name : {"s.mesh", "s.meshb"}) {
    CAPTURE(name);
    write_mesh(mesh, dir / name);
    auto back = read_mesh(dir / name);
    check_identical(mesh, back, true);
    // Writing what was read gives the same bytes.
    write_mesh(back, dir / (std::string("again-") + name));
    CHECK(read_text(dir / name) == read_text(dir / (std::string("again-") + name)));
  }
  CHECK(files_in(dir.path()) == 4);
}

TEST_CASE("writers skip deleted elements and renumber the vertices") {
  TempDir dir("io-deleted");
  auto mesh = tagged_sphere(320);
  mesh.delete_vertex(VertexHandle(5));  // removes its faces too, leaving a hole
  std::size_t live_vertices = 0, live_faces = 0;
  for (auto v : mesh.vertices()) (void)v, ++live_vertices;
  for (auto f : mesh.faces()) (void)f, ++live_faces;
  for (const char* name : {"d.mesh", "d.meshb", "d.off"}) {
    CAPTURE(name);
    write_mesh(mesh, dir / name);
    auto back = read_mesh(dir / name);
    REQUIRE(back.n_vertices() == live_vertices);
    REQUIRE(back.n_faces() == live_faces);
    const double tolerance = std::string(name) == "d.off" ? 1e-7 : 0.0;
    // The k-th live vertex (face) becomes vertex (face) k, in the same order.
    int k = 0;
    for (auto v : mesh.vertices()) CHECK((mesh.point(v) - back.point(VertexHandle(k++))).norm() <= tolerance);
    k = 0;
    for (auto f : mesh.faces()) {
      std::vector<Vec3> a, b;
      for (auto v : mesh.fv_range(f)) a.push_back(mesh.point(v));
      for (auto v : back.fv_range(FaceHandle(k++))) b.push_back(back.point(v));
      for (int i = 0; i < 3; ++i) CHECK((a[i] - b[i]).norm() <= tolerance);
    }
  }
}

TEST_CASE("Edges section: interface edges with ref 10, ridges, required, refs and boundary edges") {
  TempDir dir("io-edges");
  // An open square of two triangles: four boundary edges, one inner interface edge.
  SurfaceMesh mesh;
  VertexHandle v[4];
  v[0] = mesh.add_vertex(Vec3(0, 0, 0));
  v[1] = mesh.add_vertex(Vec3(1, 0, 0));
  v[2] = mesh.add_vertex(Vec3(1, 1, 0));
  v[3] = mesh.add_vertex(Vec3(0, 1, 0));
  auto f0 = mesh.add_face(v[0], v[1], v[2]);
  auto f1 = mesh.add_face(v[0], v[2], v[3]);
  mesh.region(f0) = kInside;
  mesh.region(f1) = kOutside;
  update_interface_from_regions(mesh);
  write_mesh(mesh, dir / "square.mesh");
  const std::string text = read_text(dir / "square.mesh");
  CHECK(contains(text, "\nEdges\n5\n"));
  CHECK((contains(text, "\n1 3 10\n") || contains(text, "\n3 1 10\n")));
  auto back = read_mesh(dir / "square.mesh");
  check_identical(mesh, back, true);
}

TEST_CASE("round trip .sol and .solb with several scalar and vector fields") {
  TempDir dir("io-sol");
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<SolField> fields(3);
  fields[0] = {"", 1, {}};
  fields[1] = {"", 3, {}};
  fields[2] = {"", 1, {}};
  for (int i = 0; i < 50; ++i)
    for (auto& f : fields)
      for (int k = 0; k < f.dimension; ++k) f.values.push_back(u(rng) * std::pow(10.0, int(rng() % 40) - 20));
  fields[0].values[0] = 5e-324;  // subnormal
  for (const char* name : {"f.sol", "f.solb"}) {
    CAPTURE(name);
    write_sol(dir / name, fields);
    auto back = read_sol_all(dir / name, 50);
    REQUIRE(back.size() == 3);
    for (int i = 0; i < 3; ++i) {
      CHECK(back[i].dimension == fields[i].dimension);
      REQUIRE(back[i].values.size() == fields[i].values.size());
      CHECK(std::memcmp(back[i].values.data(), fields[i].values.data(), 8 * fields[i].values.size()) == 0);
    }
  }
  ScalarField phi{0.5, -0.25, 1e-17};
  write_scalar_sol(dir / "phi.sol", phi);
  CHECK(read_scalar_sol(dir / "phi.sol", 3) == phi);
  VectorField velocity{Vec3(1, 2, 3), Vec3(-0.1, 0.2, 1e300)};
  write_vector_sol(dir / "v.solb", velocity);
  CHECK(read_vector_sol(dir / "v.solb", 2) == velocity);
}

TEST_CASE("mshdist-style .sol fixture with a scalar and a vector field") {
  auto fields = read_sol_all(test::source_path("meshes/fixtures/mshdist_octahedron.sol"), 6);
  REQUIRE(fields.size() == 2);
  CHECK(fields[0].dimension == 1);
  CHECK(fields[1].dimension == 3);
  CHECK(fields[0].values == std::vector<double>{0.5, 0.25, 0, -0.125, -1e-300, 1.5});
  CHECK(fields[1].values[10] == -1);
  auto phi = read_scalar_sol(test::source_path("meshes/fixtures/mshdist_octahedron.sol"), 6);
  CHECK(phi[3] == -0.125);
}

TEST_CASE("OBJ, OFF, PLY, STL round trips (written by OpenMesh)") {
  TempDir dir("io-openmesh");
  auto mesh = make_sphere({.faces = 500});
  for (const char* name : {"s.obj", "s.off", "s.ply", "s.stl"}) {
    CAPTURE(name);
    write_mesh(mesh, dir / name);
    auto back = read_mesh(dir / name);
    REQUIRE(back.n_vertices() == mesh.n_vertices());
    REQUIRE(back.n_faces() == mesh.n_faces());
    // STL has no shared vertices (OpenMesh merges them by position, in single precision):
    // compare the geometry as sets of face corners.
    double max_error = 0;
    if (std::string(name) == "s.stl") {
      for (auto f : back.faces()) {
        Vec3 c(0, 0, 0);
        for (auto v : back.fv_range(f)) c += back.point(v);
        double best = 1e9;
        for (auto g : mesh.faces()) {
          Vec3 d(0, 0, 0);
          for (auto v : mesh.fv_range(g)) d += mesh.point(v);
          best = std::min(best, (c - d).norm());
        }
        max_error = std::max(max_error, best);
      }
      CHECK(max_error < 1e-6);
    } else {
      // OpenMesh's readers parse coordinates as float: single precision (radius 1).
      check_identical(mesh, back, false, 1e-7);
    }
  }
}

TEST_CASE("VTU: the appended raw data holds exactly the mesh and fields") {
  TempDir dir("io-vtu");
  auto mesh = tagged_sphere(800);
  VtuFields fields;
  ScalarField s(mesh.n_vertices());
  VectorField vel(mesh.n_vertices());
  std::vector<double> c(mesh.n_faces());
  for (auto v : mesh.vertices()) s[v.idx()] = 0.5 * v.idx(), vel[v.idx()] = mesh.point(v) * 2.0;
  for (auto f : mesh.faces()) c[f.idx()] = -1.0 * f.idx();
  fields.point_scalars.emplace_back("s", s);
  fields.point_vectors.emplace_back("velocity", vel);
  fields.cell_scalars.emplace_back("c", c);
  const auto file = dir / "m.vtu";
  write_vtu(mesh, file, fields);
  const std::string text = read_text(file);
  REQUIRE(contains(text, "header_type=\"UInt64\""));
  const auto data = text.find("_", text.find("<AppendedData")) + 1;
  // Decode one DataArray from its offset attribute.
  auto array = [&](const std::string& name) {
    auto decl = text.find("Name=\"" + name + "\"");
    REQUIRE(decl != std::string::npos);
    auto off = text.find("offset=\"", decl) + 8;
    std::size_t offset = std::stoull(text.substr(off));
    std::uint64_t size;
    std::memcpy(&size, text.data() + data + offset, 8);
    return text.substr(data + offset + 8, size);
  };
  auto as = [](const std::string& raw, auto zero) {
    std::vector<decltype(zero)> out(raw.size() / sizeof(zero));
    std::memcpy(out.data(), raw.data(), raw.size());
    return out;
  };
  auto points = as(array("Points"), 0.0);
  auto connectivity = as(array("connectivity"), std::int64_t());
  auto offsets = as(array("offsets"), std::int64_t());
  auto types = array("types");
  auto region = as(array("region"), std::int32_t());
  auto quality = as(array("quality"), 0.0);
  auto phi = as(array("phi"), 0.0);
  REQUIRE(points.size() == 3 * mesh.n_vertices());
  REQUIRE(connectivity.size() == 3 * mesh.n_faces());
  REQUIRE(offsets.size() == mesh.n_faces());
  CHECK(types == std::string(mesh.n_faces(), char(5)));
  for (auto v : mesh.vertices()) {
    for (int k = 0; k < 3; ++k) CHECK(points[3 * v.idx() + k] == mesh.point(v)[k]);
    CHECK(phi[v.idx()] == mesh.phi(v));
  }
  for (auto f : mesh.faces()) {
    int k = 0;
    for (auto v : mesh.fv_range(f)) CHECK(connectivity[3 * f.idx() + k++] == v.idx());
    CHECK(offsets[f.idx()] == 3 * (f.idx() + 1));
    CHECK(region[f.idx()] == mesh.region(f));
    CHECK(quality[f.idx()] == face_quality(mesh, f));
  }
  CHECK(as(array("s"), 0.0) == s);
  CHECK(as(array("c"), 0.0) == c);
  CHECK(as(array("velocity"), 0.0)[3 * 5 + 2] == vel[5][2]);
}

TEST_CASE("VTU read back: the mesh, its regions, phi and every field, bit for bit") {
  TempDir dir("io-vtu-read");
  auto mesh = tagged_sphere(500);
  VtuFields fields;
  ScalarField s(mesh.n_vertices());
  VectorField vel(mesh.n_vertices());
  for (auto v : mesh.vertices()) s[v.idx()] = 0.1 * v.idx(), vel[v.idx()] = Vec3(1, v.idx(), -3);
  fields.point_scalars.emplace_back("s", s);
  fields.point_vectors.emplace_back("velocity", vel);
  write_vtu(mesh, dir / "m.vtu", fields);
  VtuFields back;
  const SurfaceMesh read = read_vtu(dir / "m.vtu", &back);
  REQUIRE(read.n_vertices() == mesh.n_vertices());
  REQUIRE(read.n_faces() == mesh.n_faces());
  for (auto v : mesh.vertices()) {
    CHECK(read.point(v) == mesh.point(v));
    CHECK(read.phi(v) == mesh.phi(v));
  }
  for (auto f : mesh.faces()) CHECK(read.region(f) == mesh.region(f));
  std::size_t interface = 0;
  for (auto e : read.edges()) interface += read.interface(e) ? 1 : 0;
  CHECK(interface > 0);  // from the regions, as for every reader
  REQUIRE(back.point_scalars.size() == 2);  // phi, then s
  CHECK(back.point_scalars[1].first == "s");
  CHECK(back.point_scalars[1].second == s);
  REQUIRE(back.point_vectors.size() == 1);
  CHECK(back.point_vectors[0].second == vel);
  REQUIRE(back.cell_scalars.size() == 1);
  CHECK(back.cell_scalars[0].first == "quality");
  // read_mesh takes it too; a truncated file is an error naming the array.
  CHECK(read_mesh(dir / "m.vtu").n_faces() == mesh.n_faces());
  const std::string bytes = read_text(dir / "m.vtu");
  write_text(dir / "cut.vtu", bytes.substr(0, bytes.size() / 2));
  CHECK_THROWS_AS(read_mesh(dir / "cut.vtu"), InputError);
  write_text(dir / "other.vtu", "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\">\n</VTKFile>\n");
  CHECK_THROWS_WITH_AS(read_mesh(dir / "other.vtu"), doctest::Contains("expected an UnstructuredGrid"), InputError);
}

TEST_CASE("VTU written by VTK (ASCII, inline base64, appended base64 and raw) reads the same") {
  if (std::system("/usr/bin/python3 -c 'import vtkmodules.vtkIOXML' > /dev/null 2>&1") != 0) {
    MESSAGE("python3-vtk9 not installed: skipped (scripts/setup.sh installs it)");
    return;
  }
  TempDir dir("io-vtu-vtk");
  auto mesh = tagged_sphere(300);
  write_vtu(mesh, dir / "ours.vtu");
  write_text(dir / "resave.py",
             "import sys\n"
             "from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader, vtkXMLUnstructuredGridWriter\n"
             "r = vtkXMLUnstructuredGridReader(); r.SetFileName(sys.argv[1]); r.Update()\n"
             "for name, mode, encode in [('ascii', 0, 0), ('binary', 1, 0), ('appended64', 2, 1), ('raw', 2, 0)]:\n"
             "    w = vtkXMLUnstructuredGridWriter(); w.SetInputData(r.GetOutput())\n"
             "    w.SetFileName(sys.argv[2] + '/' + name + '.vtu'); w.SetDataMode(mode)\n"
             "    w.SetEncodeAppendedData(encode); w.SetCompressorTypeToNone(); w.SetHeaderTypeToUInt32(); w.Write()\n");
  const std::string command = "/usr/bin/python3 " + (dir / "resave.py").string() + " " + (dir / "ours.vtu").string() +
                              " " + dir.path().string() + " > " + (dir / "log.txt").string() + " 2>&1";
  REQUIRE_MESSAGE(std::system(command.c_str()) == 0, read_text(dir / "log.txt"));
  for (const char* name : {"ascii", "binary", "appended64", "raw"}) {
    CAPTURE(name);
    const SurfaceMesh read = read_vtu(dir / (std::string(name) + ".vtu"));
    REQUIRE(read.n_faces() == mesh.n_faces());
    for (auto v : mesh.vertices()) {
      CHECK((read.point(v) - mesh.point(v)).norm() < 1e-15);  // ASCII prints every digit
      CHECK(read.phi(v) == doctest::Approx(mesh.phi(v)).epsilon(1e-15));
    }
    for (auto f : mesh.faces()) CHECK(read.region(f) == mesh.region(f));
  }
}

TEST_CASE("VTU opens in VTK (python3-vtk9, the reader ParaView uses)") {
  const char* python = "/usr/bin/python3";
  if (std::system("/usr/bin/python3 -c 'import vtkmodules.vtkIOXML' > /dev/null 2>&1") != 0) {
    MESSAGE("python3-vtk9 not installed: skipped (scripts/setup.sh installs it)");
    return;
  }
  TempDir dir("io-vtk");
  auto mesh = tagged_sphere(500);
  VtuFields fields;
  VectorField vel(mesh.n_vertices(), Vec3(1, 2, 3));
  fields.point_vectors.emplace_back("velocity", vel);
  write_vtu(mesh, dir / "m.vtu", fields);
  const auto script = dir / "check.py";
  write_text(script,
             "import sys\n"
             "from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader\n"
             "r = vtkXMLUnstructuredGridReader()\n"
             "r.SetFileName(sys.argv[1])\n"
             "r.Update()\n"
             "g = r.GetOutput()\n"
             "pd, cd = g.GetPointData(), g.GetCellData()\n"
             "print(g.GetNumberOfPoints(), g.GetNumberOfCells(), g.GetCellType(0),\n"
             "      cd.GetArray('region').GetValue(0), '%.17g' % pd.GetArray('phi').GetValue(7),\n"
             "      pd.GetArray('velocity').GetNumberOfComponents(), '%.17g' % g.GetPoint(3)[2])\n");
  const auto out = dir / "out.txt";
  const std::string command =
      std::string(python) + " " + script.string() + " " + (dir / "m.vtu").string() + " > " + out.string() + " 2>&1";
  REQUIRE(std::system(command.c_str()) == 0);
  std::istringstream result(read_text(out));
  std::size_t points = 0, cells = 0;
  int type = 0, region = 0, components = 0;
  double phi7 = 0, z3 = 0;
  result >> points >> cells >> type >> region >> phi7 >> components >> z3;
  INFO(read_text(out));
  CHECK(points == mesh.n_vertices());
  CHECK(cells == mesh.n_faces());
  CHECK(type == 5);
  CHECK(region == mesh.region(FaceHandle(0)));
  CHECK(phi7 == mesh.phi(VertexHandle(7)));
  CHECK(components == 3);
  CHECK(z3 == mesh.point(VertexHandle(3))[2]);
}

TEST_CASE("meshio (an independent Medit/VTU implementation) reads our files and writes files we read") {
  if (std::system("/usr/bin/python3 -c 'import meshio' > /dev/null 2>&1") != 0) {
    MESSAGE("python3-meshio not installed: skipped (scripts/setup.sh installs it)");
    return;
  }
  TempDir dir("io-meshio");
  // Regions and interface edges only: meshio 5 does not know Ridges/RequiredEdges/Corners.
  auto mesh = make_sphere({.faces = 500});
  for (auto v : mesh.vertices()) mesh.phi(v) = mesh.point(v)[2] - 0.1;
  label_regions_from_phi(mesh);
  for (const char* name : {"s.mesh", "s.meshb", "s.vtu"}) write_mesh(mesh, dir / name);
  write_text(dir / "check.py",
             "import sys, warnings\n"
             "warnings.simplefilter('ignore')\n"
             "import meshio, numpy as np\n"
             "d = sys.argv[1]\n"
             "ms = [meshio.read(d + '/s.' + e) for e in ('mesh', 'meshb', 'vtu')]\n"
             "tri = [m.get_cells_type('triangle') for m in ms]\n"
             "same = all(np.array_equal(ms[0].points, m.points) for m in ms) and "
             "all(np.array_equal(tri[0], t) for t in tri)\n"
             "print(len(ms[0].points), len(tri[0]), int(same), '%.17g' % ms[1].points[7][2])\n"
             "pts = np.array([[1,0,0],[-1,0,0],[0,1,0],[0,-1,0],[0,0,1],[0,0,-1.0]])\n"
             "t = np.array([[1,3,5],[3,2,5],[2,4,5],[4,1,5],[3,1,6],[2,3,6],[4,2,6],[1,4,6]]) - 1\n"
             "o = meshio.Mesh(pts, [('triangle', t)], cell_data={'medit:ref': [np.array([3,3,3,3,2,2,2,2])]},\n"
             "                point_data={'medit:ref': np.array([0,4,0,0,0,0])})\n"
             "o.write(d + '/o.meshb')\n"
             "o.write(d + '/o.mesh')\n");
  const auto out = dir / "out.txt";
  const std::string command = "/usr/bin/python3 " + (dir / "check.py").string() + " " + dir.path().string() + " > " +
                              out.string() + " 2>&1";
  const int status = std::system(command.c_str());
  INFO(read_text(out));
  REQUIRE(status == 0);
  std::istringstream result(read_text(out));
  std::size_t points = 0, triangles = 0;
  int same = 0;
  double z7 = 0;
  result >> points >> triangles >> same >> z7;
  CHECK(points == mesh.n_vertices());
  CHECK(triangles == mesh.n_faces());
  CHECK(same == 1);
  CHECK(z7 == mesh.point(VertexHandle(7))[2]);
  for (const char* name : {"o.meshb", "o.mesh"}) {
    CAPTURE(name);
    check_fixture_octahedron(read_mesh(dir / name), false);
  }
}

TEST_CASE("PVD: valid after each add, resume keeps the entries up to max_time") {
  TempDir dir("io-pvd");
  const auto file = dir / "series.pvd";
  auto check_valid = [&](std::size_t entries) {
    const std::string text = read_text(file);
    CHECK(text.rfind("<?xml", 0) == 0);
    CHECK(contains(text, "</Collection>\n</VTKFile>\n"));
    std::size_t count = 0;
    for (auto p = text.find("<DataSet"); p != std::string::npos; p = text.find("<DataSet", p + 1)) ++count;
    CHECK(count == entries);
  };
  {
    PvdWriter pvd(file);
    for (int i = 0; i < 4; ++i) {
      pvd.add(0.25 * i, "step_" + std::to_string(i) + ".vtu");
      check_valid(std::size_t(i) + 1);
    }
    pvd.add(1.0, "a&b<\"c\">.vtu");  // escaped in XML
    check_valid(5);
  }
  CHECK(contains(read_text(file), "a&amp;b&lt;&quot;c&quot;&gt;.vtu"));
  {
    auto pvd = PvdWriter::resume(file, 0.5);
    CHECK(pvd.size() == 3);
    check_valid(3);
    CHECK(!contains(read_text(file), "step_3.vtu"));
    pvd.add(0.75, "again.vtu");
    check_valid(4);
  }
  auto all = PvdWriter::resume(file, 10);
  CHECK(all.size() == 4);
  auto fresh = PvdWriter::resume(dir / "none.pvd", 1);
  CHECK(fresh.size() == 0);
  write_text(dir / "bad.pvd", "<VTKFile>\n<Collection>\n<DataSet timestep=\"x1\" file=\"a.vtu\"/>\n");
  auto message = error_of([&] { PvdWriter::resume(dir / "bad.pvd", 1); });
  CHECK(contains(message, "bad.pvd:3:"));
  CHECK(contains(message, "timestep"));
  CHECK(files_in(dir.path()) == 2);
}

// ------------------------------------------------------------------------------------------
// Bad input.

namespace {

const char* kHeader = "MeshVersionFormatted 2\nDimension 3\n";
const char* kSquareVertices = "Vertices\n4\n0 0 0 0\n1 0 0 0\n1 1 0 0\n0 1 0 0\n";

/// Write `text` to dir/name, read it, and return the error message.
std::string read_error(const TempDir& dir, const std::string& name, const std::string& text) {
  write_text(dir / name, text);
  return error_of([&] { read_mesh(dir / name); });
}

}  // namespace

TEST_CASE("bad input: missing file, unknown extension") {
  TempDir dir("io-bad-files");
  auto m = error_of([&] { read_mesh(dir / "absent.mesh"); });
  CHECK(contains(m, "absent.mesh"));
  CHECK(contains(m, "cannot open"));
  write_text(dir / "x.xyz", "whatever");
  m = error_of([&] { read_mesh(dir / "x.xyz"); });
  CHECK(contains(m, "x.xyz"));
  CHECK(contains(m, "unknown mesh extension '.xyz'"));
  m = error_of([&] { read_sol(dir / "absent.sol"); });
  CHECK(contains(m, "absent.sol"));
  m = error_of([&] { read_mesh(dir / "absent.obj"); });
  CHECK(contains(m, "absent.obj"));
}

TEST_CASE("bad input in .mesh text: each error names the file, the line and what was expected") {
  TempDir dir("io-bad-text");
  std::string h = kHeader;
  // Line numbers: the header takes lines 1-2, Vertices 3, count 4, records 5-8.
  auto m = read_error(dir, "number.mesh", h + "Vertices\n4\n0 0 0 0\n1 0 zero 0\n");
  CHECK(contains(m, "number.mesh:6:"));
  CHECK(contains(m, "malformed number 'zero'"));
  CHECK(contains(m, "z coordinate"));

  m = read_error(dir, "truncated.mesh", h + kSquareVertices + "Triangles\n2\n1 2 3 3\n1 3");
  CHECK(contains(m, "truncated.mesh:12:"));
  CHECK(contains(m, "unexpected end of file in Triangles (record 2 of 2)"));

  m = read_error(dir, "zero-index.mesh", h + kSquareVertices + "Triangles\n2\n1 2 3 3\n0 3 4 3\nEnd\n");
  CHECK(contains(m, "zero-index.mesh:12:"));
  CHECK(contains(m, "refers to vertex 0, expected an index in 1..4"));

  m = read_error(dir, "big-index.mesh", h + kSquareVertices + "Triangles\n2\n1 2 3 3\n1 3 5 3\nEnd\n");
  CHECK(contains(m, "big-index.mesh:12:"));
  CHECK(contains(m, "vertex 5"));

  m = read_error(dir, "nan.mesh", h + "Vertices\n4\n0 0 0 0\n1 0 nan 0\n1 1 0 0\n0 1 0 0\nTriangles\n1\n1 2 3 0\n");
  CHECK(contains(m, "nan.mesh:6:"));
  CHECK(contains(m, "NaN or infinite"));
  m = read_error(dir, "inf.mesh", h + "Vertices\n4\n0 0 0 0\n1 0 0 0\n1 1 0 0\n0 1 -inf 0\nTriangles\n1\n1 2 3 0\n");
  CHECK(contains(m, "inf.mesh:8:"));

  // Three triangles on edge 1-2.
  m = read_error(dir, "nm-edge.mesh",
                 h + "Vertices\n5\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 -1 0 0\n0 0 1 0\n" +
                     "Triangles\n3\n1 2 3 0\n2 1 4 0\n1 2 5 0\nEnd\n");
  CHECK(contains(m, "nm-edge.mesh:14:"));
  CHECK(contains(m, "non-manifold edge 1-2"));

  // Two triangles touching at vertex 1 only (a bow tie).
  m = read_error(dir, "nm-vertex.mesh",
                 h + "Vertices\n5\n0 0 0 0\n1 0 0 0\n1 1 0 0\n-1 0 0 0\n-1 -1 0 0\n" +
                     "Triangles\n2\n1 2 3 0\n1 4 5 0\nEnd\n");
  CHECK(contains(m, "nm-vertex.mesh:5:"));
  CHECK(contains(m, "vertex 1 is non-manifold"));

  // Two closed tetrahedra sharing vertex 1: OpenMesh refuses the first face of the second one.
  m = read_error(dir, "pinch.mesh",
                 h + "Vertices\n7\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n-1 0 0 0\n0 -1 0 0\n0 0 -1 0\n" +
                     "Triangles\n8\n1 3 2 0\n1 2 4 0\n2 3 4 0\n1 4 3 0\n1 6 5 0\n1 5 7 0\n5 6 7 0\n1 7 6 0\nEnd\n");
  CHECK(contains(m, "pinch.mesh:18:"));
  CHECK(contains(m, "triangle 5: non-manifold vertex"));

  m = read_error(dir, "flat.mesh",
                 h + "Vertices\n4\n0 0 0 0\n1 0 0 0\n2 0 0 0\n0 1 0 0\nTriangles\n2\n1 2 4 0\n1 2 3 0\nEnd\n");
  CHECK(contains(m, "flat.mesh:12:"));
  CHECK(contains(m, "triangle 2 has zero area"));

  m = read_error(dir, "dup.mesh", h + kSquareVertices + "Triangles\n2\n1 2 3 0\n2 3 1 0\nEnd\n");
  CHECK(contains(m, "dup.mesh:12:"));
  CHECK(contains(m, "duplicate"));
  m = read_error(dir, "dup-flipped.mesh", h + kSquareVertices + "Triangles\n2\n1 2 3 0\n1 3 2 0\nEnd\n");
  CHECK(contains(m, "dup-flipped.mesh:12:"));
  CHECK(contains(m, "duplicate"));

  m = read_error(dir, "orientation.mesh", h + kSquareVertices + "Triangles\n2\n1 2 3 0\n1 4 3 0\nEnd\n");
  CHECK(contains(m, "orientation.mesh:12:"));
  CHECK(contains(m, "inconsistent orientation"));

  m = read_error(dir, "extra.mesh", h + kSquareVertices + "Triangles\n1\n1 2 3 0\n1 3 4 0\nEnd\n");
  CHECK(contains(m, "extra.mesh:12:"));
  CHECK(contains(m, "expected a keyword"));

  m = read_error(dir, "ridge.mesh",
                 h + kSquareVertices + "Triangles\n1\n1 2 3 0\nEdges\n1\n1 2 0\nRidges\n1\n2\nEnd\n");
  CHECK(contains(m, "ridge.mesh:17:"));
  CHECK(contains(m, "Ridges entry 1 refers to edge 2"));

  m = read_error(dir, "edge.mesh", h + kSquareVertices + "Triangles\n1\n1 2 3 0\nEdges\n1\n1 4 0\nEnd\n");
  CHECK(contains(m, "edge.mesh:14:"));
  CHECK(contains(m, "not a side of any triangle"));

  m = read_error(dir, "huge.mesh", h + "Vertices\n99999999999\n0 0 0 0\n");
  CHECK(contains(m, "huge.mesh:4:"));

  m = read_error(dir, "version.mesh", "MeshVersionFormatted 7\nDimension 3\n");
  CHECK(contains(m, "version.mesh:1:"));
  m = read_error(dir, "empty.mesh", "");
  CHECK(contains(m, "empty.mesh:1:"));
  CHECK(contains(m, "MeshVersionFormatted"));
}

TEST_CASE("bad input in .meshb: errors name the byte offset") {
  TempDir dir("io-bad-binary");
  auto good = octahedron_meshb(2, false);
  std::string bad = good;
  bad[0] = 7;
  auto m = read_error(dir, "code.meshb", bad);
  CHECK(contains(m, "code.meshb: byte 0: bad code word 7"));
  bad = good;
  bad[4] = 9;
  m = read_error(dir, "version.meshb", bad);
  CHECK(contains(m, "version.meshb: byte 4: unsupported version 9"));
  // Cut inside the Vertices records: Dimension takes bytes 8-19, Vertices starts at 20, its
  // count at 28 and its records at 32.
  m = read_error(dir, "cut.meshb", good.substr(0, 100));
  CHECK(contains(m, "cut.meshb: byte 20: truncated file"));
  // A vertex count larger than the data (positions intact).
  bad = good;
  std::int32_t many = 100;
  std::memcpy(&bad[28], &many, 4);
  m = read_error(dir, "count.meshb", bad);
  CHECK(contains(m, "count.meshb: byte 32: unexpected end of file"));
  // A next-keyword position pointing backwards.
  bad = good;
  std::int32_t back = 4;
  std::memcpy(&bad[12], &back, 4);
  m = read_error(dir, "loop.meshb", bad);
  CHECK(contains(m, "loop.meshb: byte 8:"));
  CHECK(contains(m, "next keyword position 4"));
  // A triangle index out of range, located at its record: triangles start after the header
  // (8), Dimension (12), Vertices (12 + 6 x 28) and Normals (12 + 24): keyword at 236, records
  // at 248, 16 bytes each; the second index of triangle 2 is at 248 + 16 + 4.
  bad = good;
  std::int32_t seven = 7;
  std::memcpy(&bad[248 + 16 + 4], &seven, 4);
  m = read_error(dir, "index.meshb", bad);
  CHECK(contains(m, "index.meshb: byte 264: triangle 2 refers to vertex 7"));
}

TEST_CASE("bad input in .sol: count mismatch, wrong kind of field, truncation") {
  TempDir dir("io-bad-sol");
  write_scalar_sol(dir / "phi.sol", ScalarField(5, 1.0));
  auto m = error_of([&] { read_scalar_sol(dir / "phi.sol", 6); });
  CHECK(contains(m, "phi.sol:5:"));
  CHECK(contains(m, "SolAtVertices has 5 values per field, but the mesh has 6 vertices"));
  write_scalar_sol(dir / "phi.solb", ScalarField(5, 1.0));
  m = error_of([&] { read_scalar_sol(dir / "phi.solb", 4); });
  CHECK(contains(m, "phi.solb: byte 20:"));
  m = error_of([&] { read_vector_sol(dir / "phi.sol", 5); });
  CHECK(contains(m, "expected a vector field"));
  write_text(dir / "cut.sol", "MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n3\n1 1\n0.5\n0.25\n");
  m = error_of([&] { read_scalar_sol(dir / "cut.sol", 3); });
  CHECK(contains(m, "cut.sol:8:"));
  CHECK(contains(m, "unexpected end of file in SolAtVertices (record 3 of 3)"));
  write_text(dir / "type.sol", "MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n1\n1 9\n0.5\nEnd\n");
  m = error_of([&] { read_sol(dir / "type.sol"); });
  CHECK(contains(m, "type.sol:5:"));
  CHECK(contains(m, "unknown solution type 9"));
  write_text(dir / "none.sol", "MeshVersionFormatted 2\nDimension 3\nEnd\n");
  CHECK(contains(error_of([&] { read_sol(dir / "none.sol"); }), "no SolAtVertices"));
}

TEST_CASE("bad input through OpenMesh formats: non-manifold input is refused, not repaired") {
  TempDir dir("io-bad-openmesh");
  auto m = read_error(dir, "nm.off", "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n");
  CHECK(contains(m, "nm.off"));
  CHECK(contains(m, "non-manifold"));
  m = read_error(dir, "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  CHECK(contains(m, "flat.obj"));
  CHECK(contains(m, "zero area"));
  m = read_error(dir, "nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
  CHECK(contains(m, "nan.obj"));
}

namespace {

/// The unit cube as six quads (OFF corners are 0-based), outward normals.
const char* kCubeVertices = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n";
const int kCubeQuads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};

/// Σ p0·(p1 × p2)/6: the volume a closed mesh encloses, positive when its normals point outward.
double enclosed_volume(const SurfaceMesh& mesh) {
  double six_volumes = 0;
  for (auto f : mesh.faces()) {
    std::vector<Vec3> p;
    for (auto v : mesh.fv_range(f)) p.push_back(mesh.point(v));
    six_volumes += p[0].dot(p[1].cross(p[2]));
  }
  return six_volumes / 6;
}

std::string cube_faces_text(const std::string& after_each) {
  std::string text;
  for (const auto& q : kCubeQuads) text += fmt::format("4 {} {} {} {}{}\n", q[0], q[1], q[2], q[3], after_each);
  return text;
}

/// Geomview's binary OFF of the cube, big-endian (or little-endian), a colour on face 2.
std::string binary_cube(bool little_endian) {
  std::string bytes = "OFF BINARY\n";
  auto word = [&](std::uint32_t w) {
    if (!little_endian) w = __builtin_bswap32(w);  // (the test machine is little-endian)
    bytes.append(reinterpret_cast<const char*>(&w), 4);
  };
  auto real = [&](float x) {
    std::uint32_t w;
    std::memcpy(&w, &x, 4);
    word(w);
  };
  word(8), word(6), word(12);
  std::istringstream vertices(kCubeVertices);
  for (float x; vertices >> x;) real(x);
  for (int f = 0; f < 6; ++f) {
    word(4);
    for (int c : kCubeQuads[f]) word(std::uint32_t(c));
    word(f == 2 ? 3 : 0);
    if (f == 2) real(1), real(0.5f), real(0);
  }
  return bytes;
}

}  // namespace

TEST_CASE("OFF is read by bodyfit's parser: its variants give the same mesh, errors name the line") {
  TempDir dir("io-off");
  auto check_cube = [&](const std::string& name, const std::string& text) {
    INFO(name);
    write_text(dir / name, text);
    const SurfaceMesh mesh = read_mesh(dir / name);
    CHECK(mesh.n_vertices() == 8);
    CHECK(mesh.n_faces() == 12);  // each quad a fan of two triangles
    CHECK(total_area(mesh) == doctest::Approx(6).epsilon(1e-12));
    CHECK(enclosed_volume(mesh) == doctest::Approx(1).epsilon(1e-12));  // oriented outward, as given
  };
  const std::string faces = cube_faces_text("");
  check_cube("plain.off", std::string("OFF\n8 6 12\n") + kCubeVertices + faces);
  check_cube("comments.off", std::string("# a cube\nOFF # keyword\n\n8 6 # no edge count\n") + kCubeVertices +
                                 "# faces\n" + faces + "trailing words after the faces are ignored\n");
  check_cube("same_line.off", std::string("OFF 8 6 0\n") + kCubeVertices + faces);
  std::string coloured, homogeneous, with_normals;
  std::istringstream lines(kCubeVertices);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream xyz(line);
    double x, y, z;
    xyz >> x >> y >> z;
    coloured += line + " 0.2 0.4 0.6 1\n";
    homogeneous += fmt::format("{} {} {} 2\n", 2 * x, 2 * y, 2 * z);
    with_normals += line + " 0 0 1\n";
  }
  check_cube("colours.off", "COFF\n8 6 0\n" + coloured + cube_faces_text(" 255 0 0"));
  check_cube("homogeneous.off", "4OFF\n8 6 0\n" + homogeneous + faces);
  check_cube("normals.off", "NOFF\n8 6 0\n" + with_normals + faces);
  check_cube("dimension.off", std::string("nOFF\n3\n8 6 0\n") + kCubeVertices + faces);
  check_cube("big_endian.off", binary_cube(false));
  check_cube("little_endian.off", binary_cube(true));

  const std::string head = std::string("OFF\n8 6 0\n") + kCubeVertices;  // vertices on lines 3-10
  auto with_face = [&](int index, const std::string& line) {  // the cube with face `index` replaced
    std::string text = head;
    std::istringstream in(faces);
    int f = 0;
    for (std::string face; std::getline(in, face); ++f) text += (f == index ? line : face) + "\n";
    return text;
  };
  auto m = read_error(dir, "word.off", "OFF\n3 1 0\n0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n");
  CHECK(contains(m, "word.off:4: vertex 2: 'zero' is not a number"));
  m = read_error(dir, "short.off", with_face(1, "4 4 5 6"));
  CHECK(contains(m, "short.off:12: face 2: expected 4 corners"));
  m = read_error(dir, "index.off", with_face(0, "3 0 1 8"));
  CHECK(contains(m, "index.off:11: face 1: corner '8' is not a vertex index (0 to 7)"));
  m = read_error(dir, "corners.off", with_face(0, "-1 0 1 2"));
  CHECK(contains(m, "corners.off:11: face 1 has -1 corners, expected 3 to 8"));
  m = read_error(dir, "truncated.off", head + "# the last three faces are missing\n" + faces.substr(0, faces.find("4 1 2")));
  CHECK(contains(m, "the file ends after 3 of its 6 faces"));
  m = read_error(dir, "cut.off", "OFF\n8 6 0\n0 0 0\n1 0 0\n");
  CHECK(contains(m, "declares 8 vertices and 6 faces"));
  m = read_error(dir, "dim4.off", "nOFF\n4\n1 1 0\n0 0 0 0\n3 0 0 0\n");
  CHECK(contains(m, "only 3 is supported"));
  m = read_error(dir, "noff.off", "OF\n");
  CHECK(contains(m, "not an OFF file"));
  std::string cut_binary = binary_cube(false);
  cut_binary.resize(cut_binary.size() - 10);
  m = read_error(dir, "cut_binary.off", cut_binary);
  CHECK(contains(m, "binary OFF"));
  CHECK(contains(m, "the file ends within face 6"));
  // A duplicated face is caught by the builder every reader shares, at its line.
  m = read_error(dir, "twice.off", std::string("OFF\n8 7 0\n") + kCubeVertices + faces + "3 0 3 2\n");
  CHECK(contains(m, "twice.off:17: triangle 13: non-manifold edge"));
}

namespace {

/// Binary PLY values in either byte order (the test machine is little-endian).
class PlyEncoder {
 public:
  explicit PlyEncoder(bool big_endian) : big_endian_(big_endian) {}
  template <class T>
  PlyEncoder& put(T value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    if (big_endian_) std::reverse(raw, raw + sizeof(T));
    bytes.append(raw, sizeof(T));
    return *this;
  }
  std::string bytes;

 private:
  bool big_endian_;
};

/// A binary PLY of `mesh` with double coordinates, and properties and an element to skip: a
/// vertex normal (float) and label (uchar) around x y z, an "edge" element with a list between
/// the vertices and the faces, a face flag after the index list (uchar counts, int indices).
std::string binary_ply(const SurfaceMesh& mesh, bool big_endian) {
  std::string header = fmt::format(
      "ply\nformat {} 1.0\ncomment written by test_io\nelement vertex {}\nproperty float nx\nproperty double x\n"
      "property double y\nproperty uchar label\nproperty double z\nelement edge 2\nproperty list ushort int16 ends\n"
      "property int weight\nelement face {}\nproperty list uchar int vertex_indices\nproperty short flag\nend_header\n",
      big_endian ? "binary_big_endian" : "binary_little_endian", mesh.n_vertices(), mesh.n_faces());
  PlyEncoder body(big_endian);
  for (auto v : mesh.vertices()) {
    const Vec3& p = mesh.point(v);
    body.put(float(0.5)).put(p[0]).put(p[1]).put(std::uint8_t(v.idx() % 251)).put(p[2]);
  }
  body.put(std::uint16_t(3)).put(std::int16_t(1)).put(std::int16_t(2)).put(std::int16_t(3)).put(std::int32_t(7));
  body.put(std::uint16_t(0)).put(std::int32_t(-7));
  for (auto f : mesh.faces()) {
    body.put(std::uint8_t(3));
    for (auto v : mesh.fv_range(f)) body.put(std::int32_t(v.idx()));
    body.put(std::int16_t(-1));
  }
  return header + body.bytes;
}

/// The unit cube as an OBJ file, its quads written with every corner syntax and relative indices.
std::string cube_obj() {
  std::string text = "# a cube\nmtllib cube.mtl\no cube\n";
  std::istringstream vertices(kCubeVertices);
  for (std::string line; std::getline(vertices, line);) text += "v " + line + "\n";
  text += "vt 0 0\nvt 1 0\nvn 0 0 1\ng sides\nusemtl grey\ns off\n";
  const char* forms[6] = {"{}", "{}/1", "{}//1", "{}/2/1", "{}", "{}/1/1"};
  for (int f = 0; f < 6; ++f) {
    text += "f";
    for (int c : kCubeQuads[f]) {
      // Faces 4 and 5 count back from the last vertex (-1 is vertex 8).
      const int index = f >= 4 ? c - 8 : c + 1;
      text += ' ';
      text += fmt::format(fmt::runtime(forms[f]), index);
    }
    text += "\n";
  }
  return text;
}

}  // namespace

TEST_CASE("OBJ and PLY are read by bodyfit's parsers: written meshes come back vertex for vertex") {
  TempDir dir("io-objply");
  const SurfaceMesh mesh = make_sphere({.faces = 500});
  // The writers are OpenMesh's (OBJ, ASCII PLY): coordinates rounded to float and written with
  // 17 digits, so read back exactly as the rounded coordinates.
  for (const std::string name : {"s.obj", "s.ply"}) {
    CAPTURE(name);
    write_mesh(mesh, dir / name);
    const SurfaceMesh back = read_mesh(dir / name);
    REQUIRE(back.n_vertices() == mesh.n_vertices());
    std::size_t different = 0;
    for (auto v : mesh.vertices())
      for (int k = 0; k < 3; ++k) {
        const float written = static_cast<float>(mesh.point(v)[k]);
        different += back.point(VertexHandle(v.idx()))[k] != double(written);  // (0 == -0: the sign is not kept)
      }
    CHECK(different == 0);
    check_identical(mesh, back, false, 1e-7);  // the faces, in order
  }
  for (bool big_endian : {false, true}) {
    CAPTURE(big_endian);
    write_text(dir / "binary.ply", binary_ply(mesh, big_endian));
    check_identical(mesh, read_mesh(dir / "binary.ply"), false);
  }
}

TEST_CASE("OBJ and PLY polygons: every corner syntax, relative indices, quads as fans of the right area") {
  TempDir dir("io-objply-cube");
  auto check_cube = [&](const std::string& name, const std::string& text) {
    INFO(name);
    write_text(dir / name, text);
    const SurfaceMesh mesh = read_mesh(dir / name);
    CHECK(mesh.n_vertices() == 8);
    CHECK(mesh.n_faces() == 12);
    CHECK(total_area(mesh) == doctest::Approx(6).epsilon(1e-12));
    CHECK(enclosed_volume(mesh) == doctest::Approx(1).epsilon(1e-12));
  };
  check_cube("cube.obj", cube_obj());
  // A statement continued with '\', CRLF line ends, a vertex colour.
  std::string continued = cube_obj();
  continued.replace(continued.find("f 1 4"), 5, "f 1 \\\n  4");
  continued.replace(continued.find("v 0 0 0"), 7, "v 0 0 0 0.5 0.5 0.5");
  std::string crlf;
  for (char c : continued) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  check_cube("continued.obj", crlf);

  const std::string ply_header =
      "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 6\nproperty list uchar int vertex_indices\nend_header\n";
  check_cube("cube.ply", ply_header + kCubeVertices + cube_faces_text(""));
  // Other elements are skipped, lists included; one without properties takes no bytes, however
  // many instances it declares (and no time: nothing is read for it).
  std::string skipping = ply_header;
  skipping.replace(skipping.find("element face"), 0,
                   "element material 2\nproperty list int float colour\nproperty uchar shine\n"
                   "element nothing 1000000000000000\n");
  std::string cube_ply_body = kCubeVertices + std::string("3 1 0.5 0.25 7\n0 9\n") + cube_faces_text(" ");
  check_cube("skipping.ply", skipping + cube_ply_body);
  for (bool big_endian : {false, true}) {
    // Integer coordinates, unsigned short counts, unsigned indices: any scalar type.
    std::string header = fmt::format(
        "ply\nformat {} 1.0\nelement vertex 8\nproperty int x\nproperty short y\nproperty uchar z\n"
        "element face 6\nproperty list ushort uint vertex_index\nend_header\n",
        big_endian ? "binary_big_endian" : "binary_little_endian");
    PlyEncoder body(big_endian);
    std::istringstream vertices(kCubeVertices);
    for (int x, y, z; vertices >> x >> y >> z;) body.put(std::int32_t(x)).put(std::int16_t(y)).put(std::uint8_t(z));
    for (const auto& q : kCubeQuads) {
      body.put(std::uint16_t(4));
      for (int c : q) body.put(std::uint32_t(c));
    }
    check_cube(big_endian ? "big.ply" : "little.ply", header + body.bytes);
  }
}

TEST_CASE("bad OBJ and PLY files: each error names the file, its line (or byte) and what was expected") {
  TempDir dir("io-objply-bad");
  const std::string cube = cube_obj();  // vertices on lines 4-11, faces on 18-23
  auto with_line = [&](int number, const std::string& line) {
    std::istringstream in(cube);
    std::string text;
    int n = 0;
    for (std::string l; std::getline(in, l);) text += (++n == number ? line : l) + "\n";
    return text;
  };
  auto m = read_error(dir, "range.obj", with_line(18, "f 1 4 9"));
  CHECK(contains(m, "range.obj:18: face 1: vertex index 9 is out of range: 8 vertices are defined before this line"));
  m = read_error(dir, "relative.obj", with_line(18, "f -1 -4 -9"));
  CHECK(contains(m, "relative.obj:18: face 1: vertex index -9 is out of range"));
  m = read_error(dir, "zero.obj", with_line(19, "f 0 1 2"));
  CHECK(contains(m, "zero.obj:19: face 2: corner '0' is not v, v/vt, v//vn or v/vt/vn"));
  m = read_error(dir, "corner.obj", with_line(19, "f 1/x 2 3"));
  CHECK(contains(m, "corner.obj:19: face 2: corner '1/x'"));
  m = read_error(dir, "two.obj", with_line(20, "f 1 2"));
  CHECK(contains(m, "two.obj:20: face 3 has 2 corners, expected at least 3"));
  m = read_error(dir, "number.obj", with_line(5, "v 1 zero 0"));
  CHECK(contains(m, "number.obj:5: vertex 2: 'zero' is not a number"));
  m = read_error(dir, "short.obj", with_line(5, "v 1 0"));
  CHECK(contains(m, "short.obj:5: vertex 2: expected 3 coordinates"));
  m = read_error(dir, "garbage.obj", with_line(12, "hello world"));
  CHECK(contains(m, "garbage.obj:12: 'hello' is not an OBJ statement"));
  m = read_error(dir, "curve.obj", with_line(12, "curv 0 1 1 2"));
  CHECK(contains(m, "curve.obj:12: 'curv': OBJ free-form curves and surfaces are not supported"));
  // A continued statement is reported at its first line; the lines after it keep their numbers.
  std::string continued = with_line(12, "vt 0 \\");
  continued.replace(continued.find("vt 1 0"), 6, "  1");
  m = read_error(dir, "continued.obj", continued.replace(continued.find("f 1 4"), 5, "f 1 44"));
  CHECK(contains(m, "continued.obj:18: face 1: vertex index 44"));
  // An error inside a continued statement is reported at its first line.
  m = read_error(dir, "inside.obj", with_line(18, "f 1 4 \\ # a comment after the backslash\n  3 99"));
  CHECK(contains(m, "inside.obj:18: face 1: vertex index 99"));
  // The builder every reader shares: an unused vertex at its line.
  m = read_error(dir, "unused.obj", cube + "v 9 9 9\n");
  CHECK(contains(m, "unused.obj:24: vertex 9 is not a corner of any triangle"));

  const std::string head = "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
                           "property float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string ply = head + kCubeVertices + cube_faces_text("");  // vertices on lines 10-17, faces 18-23
  m = read_error(dir, "word.ply", head + "0 0 0\n1 zero 0\n" + ply.substr(ply.find("1 1 0")));
  CHECK(contains(m, "word.ply:11: vertex 2 (property 'y'): 'zero' is not a number"));
  m = read_error(dir, "index.ply", ply.substr(0, ply.find("4 4 5")) + "4 4 5 6 8\n" + ply.substr(ply.find("4 0 1 5")));
  CHECK(contains(m, "index.ply:19: face 2: corner 8 is not a vertex index (0 to 7)"));
  m = read_error(dir, "corners.ply", ply.substr(0, ply.find("4 4 5")) + "2 4 5\n" + ply.substr(ply.find("4 0 1 5")));
  CHECK(contains(m, "corners.ply:19: face 2: 2 corners, expected at least 3"));
  m = read_error(dir, "long.ply", ply.substr(0, ply.find("4 4 5")) + "200 4 5\n");
  CHECK(contains(m, "long.ply:19: face 2: 200 corners, more than the rest of the file holds"));
  m = read_error(dir, "cut.ply", head + "0 0 0\n");
  CHECK(contains(m, "declares 8 vertices and 6 faces"));
  m = read_error(dir, "ends.ply", ply.substr(0, ply.size() - 10) + std::string(40, '\n'));
  CHECK(contains(m, "the file ends within face 6 (property 'vertex_indices') of 6"));
  m = read_error(dir, "typo.ply", "ply\nformat ascii 1.0\nelement vertex 8\nproperty flaot x\n");
  CHECK(contains(m, "typo.ply:4: PLY header: 'flaot' is not a PLY type"));
  m = read_error(dir, "noz.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n");
  CHECK(contains(m, "noz.ply:3: PLY header: the vertex element needs the properties x, y and z"));
  m = read_error(dir, "nolist.ply", "ply\nformat ascii 1.0\nelement face 1\nproperty int vertex_indices\nend_header\n3\n");
  CHECK(contains(m, "nolist.ply:4: PLY header: 'vertex_indices' must be a list of an integer type"));
  m = read_error(dir, "format.ply", "ply\nformat binary 1.0\nend_header\n");
  CHECK(contains(m, "format.ply:2: PLY header: unknown format 'binary'"));
  m = read_error(dir, "noend.ply", "ply\nformat ascii 1.0\nelement vertex 0\n");
  CHECK(contains(m, "no 'end_header' line"));
  m = read_error(dir, "notply.ply", "PLY\n");
  CHECK(contains(m, "notply.ply:1: not a PLY file"));
  // Binary: truncated within a face, and a list count beyond the file, at their byte.
  const SurfaceMesh mesh = make_sphere({.faces = 20});
  std::string binary = binary_ply(mesh, true);
  const std::size_t faces = mesh.n_faces();
  m = read_error(dir, "truncated.ply", binary.substr(0, binary.size() - 5));
  CHECK(contains(m, fmt::format("truncated.ply: byte {}: face {}: 3 corners, more than the rest of the file holds",
                                binary.size() - 15, faces)));
  m = read_error(dir, "flag.ply", binary.substr(0, binary.size() - 1));
  CHECK(contains(m, fmt::format("flag.ply: byte {}: the file ends within face {} (property 'flag') of {}",
                                binary.size() - 2, faces, faces)));
  // The first edge's count, after the vertices (29 bytes each).
  const std::size_t edge = binary.find("end_header\n") + 11 + mesh.n_vertices() * (4 + 3 * 8 + 1);
  binary[edge] = char(0xff), binary[edge + 1] = char(0xff);
  m = read_error(dir, "list.ply", binary);
  CHECK(contains(m, "edge 1 (property 'ends'): a list of 65535 items, more than the rest of the file holds"));
}

TEST_CASE("writers: unknown extension or missing directory throws and leaves no file") {
  TempDir dir("io-bad-write");
  auto mesh = make_sphere({.faces = 320});
  auto m = error_of([&] { write_mesh(mesh, dir / "x.unknownext"); });
  CHECK(contains(m, "x.unknownext"));
  CHECK(contains(m, "unknown mesh extension"));
  // An output that cannot be written is an IoError (exit code 6), not an InputError.
  CHECK_THROWS_WITH_AS(write_mesh(mesh, dir / "no" / "such" / "x.mesh"),
                       doctest::Contains("x.mesh: cannot write: directory does not exist"), IoError);
  m = error_of([&] { write_sol(dir / "x.txt", {SolField{"", 1, {1.0}}}); });
  CHECK(contains(m, "x.txt"));
  VtuFields wrong;
  wrong.point_scalars.emplace_back("short", ScalarField(3));
  m = error_of([&] { write_vtu(mesh, dir / "x.vtu", wrong); });
  CHECK(contains(m, "field 'short' has 3 values"));
  CHECK(files_in(dir.path()) == 0);
}

TEST_CASE("CLI: writing to an unknown extension fails with one clear line and leaves no file") {
  TempDir dir("io-cli");
  auto target = dir / "x.unknownext";
  auto result = test::run_bodyfit("mesh sphere --faces 500 -o " + target.string());
  INFO(result.output);
  CHECK(result.exit_code != 0);
  CHECK(contains(result.output, "x.unknownext"));
  CHECK(contains(result.output, "unknown mesh extension"));
  CHECK(files_in(dir.path()) == 0);
}

TEST_CASE("polygons of any shape: concave and star-shaped caps keep their area in OBJ, OFF and PLY, and a polygon "
          "crossing itself is refused naming its line") {
  TempDir dir("io-polygons");
  // A prism whose caps are a star of `points` tips (radii alternating 1 and `inner`, rotated by
  // `turn`) and whose sides are quads: every cap is concave, and a fan from its first corner
  // overlaps itself (a pentagon of area 2.5 became 3.5).
  struct Star {
    int points;
    double inner, turn;
  };
  for (const Star& star : {Star{5, 0.4, 0.0}, Star{8, 0.25, 0.3}, Star{12, 0.6, 1.1}, Star{3, 0.2, 0.0}}) {
    CAPTURE(star.points);
    const int n = 2 * star.points;
    const double height = 0.7;
    std::vector<std::array<double, 2>> outline;
    for (int i = 0; i < n; ++i) {
      const double r = i % 2 ? star.inner : 1.0, a = star.turn + 2 * std::numbers::pi * i / n;
      outline.push_back({r * std::cos(a), r * std::sin(a)});
    }
    double area = 0, perimeter = 0;
    for (int i = 0; i < n; ++i) {
      const auto &p = outline[std::size_t(i)], &q = outline[std::size_t((i + 1) % n)];
      area += 0.5 * (p[0] * q[1] - p[1] * q[0]);
      perimeter += std::hypot(q[0] - p[0], q[1] - p[1]);
    }
    std::string vertices, faces_obj, faces_off;
    for (double z : {0.0, height})
      for (const auto& p : outline) vertices += fmt::format("{:.17g} {:.17g} {:.17g}\n", p[0], p[1], z);
    std::vector<std::vector<int>> faces;
    std::vector<int> bottom, top;
    for (int i = n - 1; i >= 0; --i) bottom.push_back(i);  // outward: facing −z
    for (int i = 0; i < n; ++i) top.push_back(n + i);
    faces.push_back(bottom);
    faces.push_back(top);
    for (int i = 0; i < n; ++i) faces.push_back({i, (i + 1) % n, n + (i + 1) % n, n + i});
    std::string obj, off = fmt::format("OFF\n{} {} 0\n", 2 * n, faces.size()) + vertices;
    std::istringstream lines(vertices);
    for (std::string line; std::getline(lines, line);) obj += "v " + line + "\n";
    for (const auto& f : faces) {
      obj += "f";
      off += fmt::format("{}", f.size());
      for (int c : f) obj += fmt::format(" {}", c + 1), off += fmt::format(" {}", c);
      obj += "\n", off += "\n";
    }
    std::string ply = fmt::format("ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\n"
                                  "property double z\nelement face {}\nproperty list uchar int vertex_indices\n"
                                  "end_header\n",
                                  2 * n, faces.size()) +
                      vertices;
    for (const auto& f : faces) {
      ply += fmt::format("{}", f.size());
      for (int c : f) ply += fmt::format(" {}", c);
      ply += "\n";
    }
    for (const auto& file : {std::pair{"star.obj", obj}, std::pair{"star.off", off}, std::pair{"star.ply", ply}}) {
      const std::string name = file.first;  // not a structured binding: CAPTURE (clang 14)
      CAPTURE(name);
      write_text(dir / name, file.second);
      const SurfaceMesh mesh = read_mesh(dir / name);
      CHECK(mesh.n_faces() == std::size_t(2 * (n - 2) + 2 * n));  // n − 2 triangles per cap
      CHECK(total_area(mesh) == doctest::Approx(2 * area + perimeter * height).epsilon(1e-12));
      CHECK(enclosed_volume(mesh) == doctest::Approx(area * height).epsilon(1e-12));
    }
  }
  // A non-planar quad is triangulated in the plane of its normal; a bow tie crosses itself.
  write_text(dir / "warped.obj", "v 0 0 0\nv 1 0 0.1\nv 1 1 0\nv 0 1 0.1\nf 1 2 3 4\n");
  CHECK(read_mesh(dir / "warped.obj").n_faces() == 2);
  write_text(dir / "bowtie.obj", "# a bow tie\nv 0 0 0\nv 2 0 0\nv 0 2 0\nv 2 2 0\nf 1 2 3 4\n");
  CHECK_THROWS_WITH_AS(read_mesh(dir / "bowtie.obj"),
                       doctest::Contains("bowtie.obj:6: face 1: a polygon of 4 corners whose outline crosses itself"),
                       InputError);
  write_text(dir / "bowtie.off", "OFF\n4 1 0\n0 0 0\n2 0 0\n0 2 0\n2 2 0\n4 0 1 2 3\n");
  CHECK_THROWS_WITH_AS(read_mesh(dir / "bowtie.off"), doctest::Contains("bowtie.off:7: face 1: a polygon of 4 corners"),
                       InputError);
  write_text(dir / "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3 4\n");
  CHECK_THROWS_WITH_AS(read_mesh(dir / "flat.obj"), doctest::Contains("has no area"), InputError);
}

TEST_CASE("a vertex written twice is merged into the first: the surface comes back closed, its vertices renumbered") {
  TempDir dir("io-duplicates");
  // A tetrahedron whose first corner is written again as vertex 5 and used by one face (a closed
  // surface cut open along that face's two edges, as CAD exports and CGAL's examples have them).
  write_text(dir / "dup.off", "OFF\n5 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 0 0\n3 0 2 1\n3 4 1 3\n3 1 2 3\n3 0 3 2\n");
  const SurfaceMesh mesh = read_mesh(dir / "dup.off");
  CHECK(mesh.n_vertices() == 4);
  CHECK(mesh.n_faces() == 4);
  std::size_t boundary = 0;
  for (auto e : mesh.edges()) boundary += mesh.is_boundary(e);
  CHECK(boundary == 0);
  CHECK(enclosed_volume(mesh) == doctest::Approx(1.0 / 6.0).epsilon(1e-12));
}

