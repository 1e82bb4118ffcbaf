// Medit files after the fast reader and writers (std::from_chars / std::to_chars over the whole
// file in memory, GMF binaries): bit-exact round trips, GMF binaries built here byte by byte
// (expected values come from how the bytes were built), and damaged files refused with an
// InputError naming the file and the line or byte.
#include <bodyfit/atomic_file.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/io.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>
#include <fmt/format.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <sys/stat.h>

using namespace bodyfit;
using bodyfit::test::TempDir;
namespace fs = std::filesystem;

namespace {

void write_bytes(const fs::path& file, const std::string& bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// A sphere with refs, regions, an interface, ridges, required and corner tags, and coordinates
/// that need every digit: last-bit perturbations, -0, subnormals and values far from 1.
SurfaceMesh awkward_sphere(std::size_t faces = 2000) {
  SurfaceMesh mesh = make_sphere({.faces = faces});
  std::mt19937_64 rng(42);
  const double tiny[] = {-0.0, 4.9406564584124654e-324, -2.2250738585072009e-310, 1e-300, 0.1 + 0.2 - 0.3};
  std::size_t k = 0;
  for (auto v : mesh.vertices()) {
    Vec3 p = mesh.point(v);
    for (int c = 0; c < 3; ++c) {
      if (std::abs(p[c]) < 1e-2 && k < std::size(tiny)) p[c] = tiny[k++];
      else p[c] = std::nextafter(p[c], rng() % 2 ? 2.0 : -2.0) * (1 + 1e-9 * double(rng() % 1000));
    }
    mesh.set_point(v, p);
    mesh.phi(v) = p[2] - 0.2;
    mesh.vertex_ref(v) = int(rng() % 4);
    mesh.corner(v) = rng() % 9 == 0;
    mesh.required(v) = rng() % 11 == 0;
  }
  REQUIRE(k == std::size(tiny));
  label_regions_from_phi(mesh);
  for (auto e : mesh.edges()) {
    if (mesh.interface(e)) continue;
    mesh.ridge(e) = rng() % 7 == 0;
    mesh.required(e) = rng() % 13 == 0;
    mesh.edge_ref(e) = rng() % 5 == 0 ? int(1 + rng() % 4) : 0;
  }
  return mesh;
}

/// Bit-exact coordinates, the same triangles in the same order, the same refs and tags.
void check_same_mesh(const SurfaceMesh& a, const SurfaceMesh& b) {
  REQUIRE(a.n_vertices() == b.n_vertices());
  REQUIRE(a.n_faces() == b.n_faces());
  for (auto v : a.vertices()) {
    const VertexHandle w(v.idx());
    for (int c = 0; c < 3; ++c) REQUIRE(same_bits(a.point(v)[c], b.point(w)[c]));
    CHECK(a.vertex_ref(v) == b.vertex_ref(w));
    CHECK(a.corner(v) == b.corner(w));
    CHECK(a.required(v) == b.required(w));
  }
  for (auto f : a.faces()) {
    const FaceHandle g(f.idx());
    std::vector<int> va, vb;
    for (auto v : a.fv_range(f)) va.push_back(v.idx());
    for (auto v : b.fv_range(g)) vb.push_back(v.idx());
    std::rotate(vb.begin(), std::find(vb.begin(), vb.end(), va[0]), vb.end());  // same cycle
    REQUIRE(va == vb);
    CHECK(a.region(f) == b.region(g));
  }
  std::size_t interface = 0, ridges = 0;
  for (auto e : a.edges()) {
    const auto h = a.halfedge_handle(e, 0);
    const auto hb =
        b.find_halfedge(VertexHandle(a.from_vertex_handle(h).idx()), VertexHandle(a.to_vertex_handle(h).idx()));
    REQUIRE(hb.is_valid());
    const auto eb = b.edge_handle(hb);
    CHECK(a.interface(e) == b.interface(eb));
    CHECK(a.ridge(e) == b.ridge(eb));
    CHECK(a.required(e) == b.required(eb));
    CHECK((a.interface(e) ? kInterfaceRef : a.edge_ref(e)) == b.edge_ref(eb));
    interface += a.interface(e), ridges += a.ridge(e);
  }
  CHECK(interface > 0);
  CHECK(ridges > 0);
}

// ---------------------------------------------------------------------------------------------
// GMF bytes, built here from the layout (docs/reference/formats.md), independently of the library.

struct Gmf {
  int version = 2;
  bool big_endian = false;
  std::string bytes;

  template <class T>
  void raw(T value) {
    char b[sizeof(T)];
    std::memcpy(b, &value, sizeof(T));
    if (big_endian) std::reverse(b, b + sizeof(T));
    bytes.append(b, sizeof(T));
  }
  void word(std::int32_t i) { raw(i); }  // always 4 bytes: code word, version, codes, dimension, types
  void integer(std::int64_t i) { version >= 4 ? raw(i) : raw(std::int32_t(i)); }
  void real(double x) { version == 1 ? raw(float(x)) : raw(x); }
  std::size_t position_size() const { return version >= 3 ? 8 : 4; }

  static Gmf file(int version, bool big_endian) {
    Gmf g{version, big_endian, {}};
    g.word(1);
    g.word(version);
    return g;
  }
  Gmf body() const { return Gmf{version, big_endian, {}}; }
  /// Keyword `code` with its body; the next-keyword position is where the keyword ends.
  void keyword(int code, const Gmf& body) {
    word(code);
    const std::uint64_t next = bytes.size() + position_size() + body.bytes.size();
    version >= 3 ? raw(std::int64_t(next)) : raw(std::int32_t(next));
    bytes += body.bytes;
  }
  void end() {
    word(54);
    version >= 3 ? raw(std::int64_t(0)) : raw(std::int32_t(0));
  }
};

// The square [0,1]² as two triangles (ref 3 below the diagonal 1-3, ref 2 above) with every
// keyword of the text format, an unknown keyword and a Normals section to skip.
const double kSquare[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
const int kVertexRefs[4] = {0, 5, 0, 9};

/// The square as a .meshb of `version`; `starts` receives where each keyword begins.
std::string square_meshb(int version, bool big_endian, std::vector<std::size_t>* starts = nullptr) {
  Gmf g = Gmf::file(version, big_endian);
  auto add = [&](int code, const Gmf& body) {
    if (starts) starts->push_back(g.bytes.size());
    g.keyword(code, body);
  };
  Gmf b = g.body();
  b.word(3);
  add(3, b);  // Dimension
  b = g.body();
  b.integer(4);
  for (int i = 0; i < 4; ++i) {
    for (double x : kSquare[i]) b.real(x);
    b.integer(kVertexRefs[i]);
  }
  add(4, b);  // Vertices
  b = g.body();
  b.bytes = "any bytes at all, skipped through the next position";
  add(200, b);  // not a GMF keyword
  b = g.body();
  b.integer(1);
  for (double x : {0.0, 0.0, 1.0}) b.real(x);
  add(60, b);  // Normals
  b = g.body();
  b.integer(2);
  for (int i : {1, 2, 3, 3, 1, 3, 4, 2}) b.integer(i);
  add(6, b);  // Triangles
  b = g.body();
  b.integer(2);
  for (int i : {1, 2, 7, 1, 3, 10}) b.integer(i);
  add(5, b);  // Edges
  for (int code : {14, 16}) {  // Ridges, RequiredEdges: edge 1 (1-2)
    b = g.body();
    b.integer(1);
    b.integer(1);
    add(code, b);
  }
  b = g.body();
  b.integer(1);
  b.integer(2);
  add(13, b);  // Corners: vertex 2
  b = g.body();
  b.integer(1);
  b.integer(4);
  add(15, b);  // RequiredVertices: vertex 4
  if (starts) starts->push_back(g.bytes.size());
  g.end();
  return g.bytes;
}

void check_square(const SurfaceMesh& mesh) {
  REQUIRE(mesh.n_vertices() == 4);
  REQUIRE(mesh.n_faces() == 2);
  for (int i = 0; i < 4; ++i) {
    CHECK(mesh.point(VertexHandle(i)) == Vec3(kSquare[i][0], kSquare[i][1], kSquare[i][2]));
    CHECK(mesh.vertex_ref(VertexHandle(i)) == kVertexRefs[i]);
  }
  CHECK(mesh.region(FaceHandle(0)) == kInside);
  CHECK(mesh.region(FaceHandle(1)) == kOutside);
  auto edge = [&](int a, int b) {
    const auto h = mesh.find_halfedge(VertexHandle(a - 1), VertexHandle(b - 1));
    REQUIRE(h.is_valid());
    return mesh.edge_handle(h);
  };
  CHECK(mesh.edge_ref(edge(1, 2)) == 7);
  CHECK(mesh.ridge(edge(1, 2)));
  CHECK(mesh.required(edge(1, 2)));
  CHECK(mesh.interface(edge(1, 3)));
  CHECK(mesh.edge_ref(edge(1, 3)) == kInterfaceRef);
  CHECK_FALSE(mesh.ridge(edge(1, 3)));
  CHECK(mesh.corner(VertexHandle(1)));
  CHECK(mesh.required(VertexHandle(3)));
  CHECK_FALSE(mesh.corner(VertexHandle(0)));
}

/// A .solb of 3 vertices with a scalar and a vector field (types 1 and 2).
std::string fields_solb(int version, bool big_endian) {
  Gmf g = Gmf::file(version, big_endian);
  Gmf b = g.body();
  b.word(3);
  g.keyword(3, b);
  b = g.body();
  b.integer(3);
  b.word(2);
  b.word(1);
  b.word(2);
  for (int i = 0; i < 3; ++i) {
    b.real(0.5 * i - 1);  // the scalar
    for (int k = 0; k < 3; ++k) b.real(0.25 * (i + 1) * (k + 1));
  }
  g.keyword(62, b);
  g.end();
  return g.bytes;
}

}  // namespace

TEST_CASE("text .mesh: write -> read is bit-exact and writing again gives the same bytes") {
  TempDir dir("io-fast-text");
  const SurfaceMesh mesh = awkward_sphere();
  write_mesh(mesh, dir / "a.mesh");
  const SurfaceMesh back = read_mesh(dir / "a.mesh");
  check_same_mesh(mesh, back);
  write_mesh(back, dir / "b.mesh");
  CHECK(test::read_file(dir / "a.mesh") == test::read_file(dir / "b.mesh"));
}

TEST_CASE("text and binary .sol: write -> read is bit-exact for every kind of double") {
  TempDir dir("io-fast-sol");
  std::mt19937_64 rng(3);
  std::vector<double> values = {0.0, -0.0, 4.9406564584124654e-324, -2.2250738585072014e-308, 1e-300,
                                1.7976931348623157e308, -1e300, 0.1, 1.0 / 3, 123456789.0};
  while (values.size() < 300) {
    std::uint64_t bits = rng();
    double x;
    std::memcpy(&x, &bits, 8);
    if (std::isfinite(x)) values.push_back(x);
  }
  SolField scalar{"", 1, values};
  SolField vector{"", 3, {}};
  for (std::size_t i = 0; i < values.size(); ++i)
    for (int k = 0; k < 3; ++k) vector.values.push_back(values[(i * 7 + std::size_t(k)) % values.size()] * 0.5);
  for (const char* name : {"f.sol", "f.solb"}) {
    CAPTURE(name);
    write_sol(dir / name, {scalar, vector});
    const auto back = read_sol_all(dir / name, values.size());
    REQUIRE(back.size() == 2);
    REQUIRE(back[0].dimension == 1);
    REQUIRE(back[1].dimension == 3);
    for (std::size_t i = 0; i < scalar.values.size(); ++i) REQUIRE(same_bits(back[0].values[i], scalar.values[i]));
    for (std::size_t i = 0; i < vector.values.size(); ++i) REQUIRE(same_bits(back[1].values[i], vector.values[i]));
  }
}

TEST_CASE(".meshb: write -> read is bit-exact with refs, regions, interface, ridges and required tags") {
  TempDir dir("io-fast-meshb");
  const SurfaceMesh mesh = awkward_sphere();
  write_mesh(mesh, dir / "a.meshb");
  const std::string bytes = test::read_file(dir / "a.meshb");
  // GMF version 2, little-endian: code word 1, version 2, then Dimension (3) = 3.
  REQUIRE(bytes.size() > 20);
  std::int32_t head[5];
  std::memcpy(head, bytes.data(), sizeof head);
  CHECK(head[0] == 1);
  CHECK(head[1] == 2);
  CHECK(head[2] == 3);
  CHECK(head[3] == 20);
  CHECK(head[4] == 3);
  const SurfaceMesh back = read_mesh(dir / "a.meshb");
  check_same_mesh(mesh, back);
  write_mesh(back, dir / "b.meshb");
  CHECK(test::read_file(dir / "b.meshb") == bytes);
  // The text and binary paths agree.
  write_mesh(mesh, dir / "a.mesh");
  check_same_mesh(read_mesh(dir / "a.mesh"), back);
}

TEST_CASE("a write with its size announced or not: exactly the bytes written, over a bigger file, no blocks kept past the end") {
  TempDir dir("io-fast-announced");
  const fs::path file = dir / "f.bin";
  const std::string big(3'000'000, 'a'), small(100'000, 'b');
  auto write = [&](const std::string& bytes, std::uint64_t announced) {
    write_atomically(file, [&](std::ostream& out) { out.write(bytes.data(), std::streamsize(bytes.size())); },
                     announced);
  };
  write(big, big.size());
  CHECK(test::read_file(file) == big);
  // Announced 30 times what is written: the file is what was written, and the blocks allocated
  // for the rest are given back (st_blocks counts 512-byte units).
  write(small, 30 * small.size());
  CHECK(test::read_file(file) == small);
  struct stat st {};
  REQUIRE(::stat(file.c_str(), &st) == 0);
  CHECK(std::uint64_t(st.st_size) == small.size());
  CHECK(std::uint64_t(st.st_blocks) * 512 < 2 * small.size());
  // Announced less than is written: the file grows past the announcement.
  write(big, small.size());
  CHECK(test::read_file(file) == big);
  // Nothing announced over a bigger file: the size of the one replaced is allocated, and what was
  // not written is given back the same way.
  write(small, 0);
  CHECK(test::read_file(file) == small);
  REQUIRE(::stat(file.c_str(), &st) == 0);
  CHECK(std::uint64_t(st.st_size) == small.size());
  CHECK(std::uint64_t(st.st_blocks) * 512 < 2 * small.size());
  for (const auto& entry : fs::directory_iterator(dir.path())) CHECK_FALSE(is_atomic_temporary(entry.path().filename().string()));
}

TEST_CASE(".meshb and .solb built byte by byte: versions 1 to 4, both byte orders") {
  TempDir dir("io-fast-handmade");
  for (int version = 1; version <= 4; ++version)
    for (bool big_endian : {false, true}) {
      CAPTURE(version);
      CAPTURE(big_endian);
      write_bytes(dir / "square.meshb", square_meshb(version, big_endian));
      check_square(read_mesh(dir / "square.meshb"));

      write_bytes(dir / "fields.solb", fields_solb(version, big_endian));
      const auto fields = read_sol_all(dir / "fields.solb", 3);
      REQUIRE(fields.size() == 2);
      CHECK(fields[0].values == std::vector<double>{-1, -0.5, 0});
      REQUIRE(fields[1].dimension == 3);
      CHECK(fields[1].values == std::vector<double>{0.25, 0.5, 0.75, 0.5, 1, 1.5, 0.75, 1.5, 2.25});
      CHECK(read_scalar_sol(dir / "fields.solb", 3) == ScalarField{-1, -0.5, 0});
    }
}

TEST_CASE("a large .meshb is parsed by both threads: the same mesh, in both byte orders, and the first bad record's error") {
  // 40k triangles and 20k vertices: records in several chunks. Version 4 (64-bit integers, whose
  // refs can be out of an int's range), built byte by byte.
  TempDir dir("io-fast-meshb-chunks");
  const SurfaceMesh sphere = make_sphere({.faces = 40000});
  const auto corners = [&] {
    std::vector<std::array<int, 3>> c;
    for (auto f : sphere.faces()) {
      std::array<int, 3> t{};
      int k = 0;
      for (auto v : sphere.fv_range(f)) t[std::size_t(k++)] = v.idx();
      c.push_back(t);
    }
    return c;
  }();
  auto meshb = [&](bool big_endian, std::map<std::size_t, std::int64_t> vertex_refs,
                   std::map<std::size_t, std::int64_t> triangle_refs) {
    Gmf g = Gmf::file(4, big_endian);
    Gmf b = g.body();
    b.word(3);
    g.keyword(3, b);
    b = g.body();
    b.integer(std::int64_t(sphere.n_vertices()));
    for (auto v : sphere.vertices()) {
      for (int k = 0; k < 3; ++k) b.real(sphere.point(v)[k]);
      b.integer(vertex_refs.count(std::size_t(v.idx())) ? vertex_refs[std::size_t(v.idx())] : v.idx() % 7);
    }
    g.keyword(4, b);
    b = g.body();
    b.integer(std::int64_t(corners.size()));
    for (std::size_t t = 0; t < corners.size(); ++t) {
      for (int v : corners[t]) b.integer(v + 1);
      b.integer(triangle_refs.count(t) ? triangle_refs[t] : std::int64_t(t % 2 ? kInside : kOutside));
    }
    g.keyword(6, b);
    g.end();
    return g.bytes;
  };
  for (bool big_endian : {false, true}) {
    write_bytes(dir / "a.meshb", meshb(big_endian, {}, {}));
    const SurfaceMesh back = read_mesh(dir / "a.meshb");
    REQUIRE(back.n_vertices() == sphere.n_vertices());
    REQUIRE(back.n_faces() == sphere.n_faces());
    std::size_t differences = 0;
    for (auto v : sphere.vertices())
      differences += back.point(v) != sphere.point(v) || back.vertex_ref(v) != v.idx() % 7;
    for (auto f : back.faces()) {
      std::array<int, 3> t{};
      int k = 0;
      for (auto v : back.fv_range(f)) t[std::size_t(k++)] = v.idx();
      differences += t != corners[std::size_t(f.idx())] || back.region(f) != (f.idx() % 2 ? kInside : kOutside);
    }
    CHECK(differences == 0);
  }
  // Refs beyond 32 bits in two chunks: the earlier record's is named, as one loop would.
  const std::int64_t wide = (std::int64_t(1) << 32) + 3, wider = -(std::int64_t(1) << 33);
  write_bytes(dir / "b.meshb", meshb(false, {}, {{35000, wider}, {20000, wide}}));
  std::string message = error_of([&] { read_mesh(dir / "b.meshb"); });
  INFO(message);
  CHECK(message.find("a triangle ref 4294967299 does not fit in 32 bits") != std::string::npos);
  write_bytes(dir / "b.meshb", meshb(false, {{18000, wide}, {3000, wider}}, {}));
  message = error_of([&] { read_mesh(dir / "b.meshb"); });
  CHECK(message.find("a vertex ref -8589934592 does not fit in 32 bits") != std::string::npos);
}

TEST_CASE("truncated or corrupt .meshb/.solb: an InputError naming the file, never a crash or a huge allocation") {
  TempDir dir("io-fast-corrupt");
  for (int version : {2, 3}) {
    CAPTURE(version);
    std::vector<std::size_t> starts;
    const std::string good = square_meshb(version, version == 3, &starts);
    // Every prefix: an error naming the file, except a cut exactly between two keywords (a file
    // without End, whose sections are complete, is read: what it holds up to the cut) or inside
    // End's position, which is not needed once End's code is read.
    for (std::size_t size = 0; size < good.size(); ++size) {
      CAPTURE(size);
      const fs::path file = dir / "cut.meshb";
      write_bytes(file, good.substr(0, size));
      const bool boundary =
          std::find(starts.begin(), starts.end(), size) != starts.end() || size >= starts.back() + 4;
      try {
        const SurfaceMesh mesh = read_mesh(file);
        CHECK(boundary);
        CHECK(mesh.n_faces() == (size > starts[4] ? 2u : 0u));
      } catch (const InputError& e) {
        CHECK(std::string(e.what()).find("cut.meshb") != std::string::npos);
      }
    }
  }
  // Record counts that no file could hold: refused against the file's length before allocating.
  struct Corruption {
    int version;
    std::int64_t count;
  };
  for (const Corruption& corruption :
       {Corruption{2, 0x7fffffff}, Corruption{2, -5}, Corruption{4, std::int64_t(1) << 62}, Corruption{4, -1}}) {
    const int version = corruption.version;  // variables, not bindings: CAPTURE's lambda takes them (clang 14)
    const std::int64_t count = corruption.count;
    CAPTURE(version);
    CAPTURE(count);
    std::string bytes = square_meshb(version, false);
    // The Vertices count follows Dimension (8 + 4 + position + 4) and Vertices' code and position.
    const std::size_t position = version >= 3 ? 8 : 4;
    const std::size_t at = 8 + (4 + position + 4) + 4 + position;
    if (version >= 4) std::memcpy(&bytes[at], &count, 8);
    else {
      const auto count32 = std::int32_t(count);
      std::memcpy(&bytes[at], &count32, 4);
    }
    write_bytes(dir / "count.meshb", bytes);
    const std::string message = error_of([&] { read_mesh(dir / "count.meshb"); });
    CHECK(message.find("count.meshb: byte") != std::string::npos);

    std::string sol = fields_solb(version, false);
    const std::size_t sol_count = 8 + (4 + position + 4) + 4 + position;
    if (version >= 4) std::memcpy(&sol[sol_count], &count, 8);
    else {
      const auto count32 = std::int32_t(count);
      std::memcpy(&sol[sol_count], &count32, 4);
    }
    write_bytes(dir / "count.solb", sol);
    CHECK(error_of([&] { read_sol_all(dir / "count.solb"); }).find("count.solb: byte") != std::string::npos);
  }
  // A next-keyword position past the end of the file.
  std::string bytes = square_meshb(2, false);
  const std::int32_t beyond = std::int32_t(bytes.size() + 100);
  std::memcpy(&bytes[12], &beyond, 4);
  write_bytes(dir / "next.meshb", bytes);
  CHECK(error_of([&] { read_mesh(dir / "next.meshb"); }).find("next.meshb: byte 8: truncated file") !=
        std::string::npos);
  // Not a GMF file at all.
  write_bytes(dir / "text.meshb", "MeshVersionFormatted 2\n");
  CHECK(error_of([&] { read_mesh(dir / "text.meshb"); }).find("text.meshb: byte 0: bad code word") !=
        std::string::npos);
}

TEST_CASE("text errors name the file and the line") {
  TempDir dir("io-fast-text-errors");
  const std::string head = "MeshVersionFormatted 2\nDimension 3\n";
  auto mesh_error = [&](const std::string& text) {
    write_bytes(dir / "e.mesh", text);
    return error_of([&] { read_mesh(dir / "e.mesh"); });
  };
  // Lines: 1-2 header, 3 Vertices, 4 count, 5.. records.
  std::string m = mesh_error(head + "Vertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0x1 0\n");
  CHECK(m.find("e.mesh:7: malformed number '0x1' in Vertices (record 3 of 3): expected the z coordinate") !=
        std::string::npos);
  m = mesh_error(head + "Vertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\nTriangles\n2000000000\n1 2 3 0\n");
  CHECK(m.find("e.mesh:9: record count 2000000000 of Triangles does not fit in the rest of the file") !=
        std::string::npos);
  m = mesh_error(head + "Vertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\nTriangles\n1\n1 2 3");
  CHECK(m.find("e.mesh:10: unexpected end of file in Triangles (record 1 of 1): expected the triangle ref") !=
        std::string::npos);
  m = mesh_error(head + "Vertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\r\nTriangles\n1\n1 2 3 0 4\n");
  CHECK(m.find("e.mesh:10: expected a keyword, found '4'") != std::string::npos);

  write_bytes(dir / "e.sol", "MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n2\n1 1\n0.5\n1e\n");
  m = error_of([&] { read_sol(dir / "e.sol"); });
  CHECK(m.find("e.sol:7: malformed number '1e' in SolAtVertices (record 2 of 2)") != std::string::npos);
}

TEST_CASE("large text sections are read by both threads: the same mesh, and any other layout or error as on one") {
  // Sections of 16384 records or more, one per line, are shared between the threads; a comment or a
  // blank line among them, a record over two lines or two on one, and every error go back to the
  // reading on one thread, with the same result and the same message.
  TempDir dir("io-fast-text-parallel");
  const SurfaceMesh mesh = awkward_sphere(40000);
  const std::string vertices = std::to_string(mesh.n_vertices()), faces = std::to_string(mesh.n_faces());
  write_mesh(mesh, dir / "a.mesh");
  const std::string text = test::read_file(dir / "a.mesh");
  for (int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    check_same_mesh(mesh, read_mesh(dir / "a.mesh"));
  }
  // Where record k of a section starts (its keyword's line, then the count's, then the records).
  auto record_at = [&](const std::string& section, int k) {
    std::size_t at = text.find("\n" + section + "\n") + section.size() + 2;
    for (int line = 0; line <= k; ++line) at = text.find('\n', at) + 1;
    return at;
  };
  auto line_of = [&](const std::string& t, std::size_t at) { return 1 + std::count(t.begin(), t.begin() + long(at), '\n'); };
  auto with = [&](std::size_t at, std::size_t erase, const std::string& insert) {
    std::string changed = text;
    changed.replace(at, erase, insert);
    return changed;
  };
  auto read_text = [&](const std::string& t) {
    write_bytes(dir / "b.mesh", t);
    return read_mesh(dir / "b.mesh");
  };
  const std::size_t vertex = record_at("Vertices", 12000), triangle = record_at("Triangles", 30000);
  const std::size_t vertex_ref = text.rfind(' ', text.find('\n', vertex));  // before the ref
  const std::size_t triangle_end = text.find('\n', triangle);
  for (const std::string& layout :
       {with(vertex, 0, "# a comment among the vertices\n"), with(triangle, 0, "\n"),
        with(vertex_ref, 1, "\n"), with(triangle_end, 1, " ")})
    check_same_mesh(mesh, read_text(layout));

  // Errors: the line counted here in the text.
  const std::string bad_vertex = with(vertex, 1, "0x1");
  std::string m = error_of([&] { read_text(bad_vertex); });
  INFO(m);
  CHECK(m.find("b.mesh:" + std::to_string(line_of(bad_vertex, vertex)) + ": malformed number '0x1") !=
        std::string::npos);
  CHECK(m.find("in Vertices (record 12001 of " + vertices + "): expected the x coordinate") != std::string::npos);
  const std::string bad_triangle = with(triangle, 0, "x");
  m = error_of([&] { read_text(bad_triangle); });
  CHECK(m.find("b.mesh:" + std::to_string(line_of(bad_triangle, triangle)) + ":") != std::string::npos);
  CHECK(m.find("malformed number 'x") != std::string::npos);
  CHECK(m.find("in Triangles (record 30001 of " + faces + "): expected a vertex index") != std::string::npos);
  // A count larger than the records: the next section's keyword is read as a record.
  const std::size_t count = text.find("\nTriangles\n") + 11;
  const std::string more_faces = std::to_string(mesh.n_faces() + 1);
  const std::string more = with(count, text.find('\n', count) - count, more_faces);
  m = error_of([&] { read_text(more); });
  CHECK(m.find("in Triangles (record " + more_faces + " of " + more_faces + "): expected a vertex index") !=
        std::string::npos);
}

TEST_CASE("a large .sol is read by both threads: bit-exact values, and any other layout or error as on one") {
  TempDir dir("io-fast-sol-parallel");
  const std::size_t n = 20000;
  std::mt19937_64 rng(5);
  SolField scalar{"", 1, {}}, vector{"", 3, {}};
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t bits = rng();
    double x;
    std::memcpy(&x, &bits, 8);
    scalar.values.push_back(std::isfinite(x) ? x : double(i));
    for (int k = 0; k < 3; ++k) vector.values.push_back(double(rng() % 1000003) / 7.0 - 1e5);
  }
  write_sol(dir / "f.sol", {scalar, vector});
  const std::string text = test::read_file(dir / "f.sol");
  auto check_values = [&](const std::vector<SolField>& back) {
    REQUIRE(back.size() == 2);
    for (std::size_t i = 0; i < scalar.values.size(); ++i) REQUIRE(same_bits(back[0].values[i], scalar.values[i]));
    for (std::size_t i = 0; i < vector.values.size(); ++i) REQUIRE(same_bits(back[1].values[i], vector.values[i]));
  };
  check_values(read_sol_all(dir / "f.sol", n));
  // Vertex k's line: the last n lines before "End" hold the values.
  const std::size_t values_start = [&] {
    std::size_t at = text.find("SolAtVertices");
    for (int line = 0; line < 3; ++line) at = text.find('\n', at) + 1;  // keyword, count, types
    while (text[at] == '\n') ++at;                                      // blank lines
    return at;
  }();
  auto record_at = [&](std::size_t k) {
    std::size_t at = values_start;
    for (std::size_t line = 0; line < k; ++line) at = text.find('\n', at) + 1;
    return at;
  };
  REQUIRE(text.compare(record_at(n), 4, "\nEnd") == 0);  // one line per vertex
  const std::size_t at = record_at(15000);
  std::string commented = text;
  commented.insert(at, "# a comment\n");
  write_bytes(dir / "g.sol", commented);
  check_values(read_sol_all(dir / "g.sol", n));
  std::string bad = text;
  bad.insert(at, "x");
  write_bytes(dir / "h.sol", bad);
  const std::string m = error_of([&] { read_sol_all(dir / "h.sol", n); });
  INFO(m);
  const long line = 1 + std::count(bad.begin(), bad.begin() + long(at), '\n');
  CHECK(m.find("h.sol:" + std::to_string(line) + ": malformed number 'x") != std::string::npos);
  CHECK(m.find("in SolAtVertices (record 15001 of 20000)") != std::string::npos);
}

TEST_CASE("a large mesh's checks name its first bad record, whichever block of the parallel checks finds it") {
  // 40k triangles: the checks run over several blocks; the one named is the first in the file.
  TempDir dir("io-fast-first-bad");
  write_mesh(make_sphere({.faces = 40000}), dir / "a.mesh");
  std::vector<std::string> lines;
  {
    std::istringstream in(test::read_file(dir / "a.mesh"));
    for (std::string line; std::getline(in, line);) lines.push_back(line);
  }
  const auto keyword = [&](const std::string& word) {
    return std::size_t(std::find(lines.begin(), lines.end(), word) - lines.begin());
  };
  const std::size_t vertex0 = keyword("Vertices") + 2, triangle0 = keyword("Triangles") + 2;
  auto numbers = [&](std::size_t line) {
    std::istringstream in(lines[line]);
    std::vector<std::string> words;
    for (std::string w; in >> w;) words.push_back(w);
    return words;
  };
  auto error_with = [&](const std::vector<std::pair<std::size_t, std::string>>& changes) {
    std::vector<std::string> changed = lines;
    for (const auto& [line, text] : changes) changed[line] = text;
    std::string text;
    for (const auto& line : changed) text += line + "\n";
    write_bytes(dir / "b.mesh", text);
    return error_of([&] { read_mesh(dir / "b.mesh"); });
  };
  auto triangle = [&](std::size_t t, int k) { return std::stoll(numbers(triangle0 + t)[std::size_t(k)]); };
  // The same vertex twice in triangle 30001, a vertex out of range in triangle 35001.
  std::string m = error_with({{triangle0 + 30000, fmt::format("{0} {0} {1} 0", triangle(30000, 0), triangle(30000, 2))},
                              {triangle0 + 35000, "1 2 999999 0"}});
  INFO(m);
  CHECK(m.find(fmt::format("b.mesh:{}: triangle 30001 uses the same vertex twice", triangle0 + 30001)) !=
        std::string::npos);
  m = error_with({{triangle0 + 35000, "1 2 999999 0"}});
  CHECK(m.find(fmt::format("b.mesh:{}: triangle 35001 refers to vertex 999999", triangle0 + 35001)) !=
        std::string::npos);
  // Infinite coordinates at vertices 19001 and 9001.
  m = error_with({{vertex0 + 19000, "inf 0 0 0"}, {vertex0 + 9000, "0 nan 0 0"}});
  CHECK(m.find(fmt::format("b.mesh:{}: vertex 9001 has a NaN or infinite coordinate", vertex0 + 9001)) !=
        std::string::npos);
  // Triangles 39001 and 12001 made flat: their third corner moved onto their first side's middle.
  std::vector<std::pair<std::size_t, std::string>> flat;
  for (std::size_t t : {std::size_t(39000), std::size_t(12000)}) {
    const auto a = numbers(vertex0 + std::size_t(triangle(t, 0) - 1)), b = numbers(vertex0 + std::size_t(triangle(t, 1) - 1));
    std::string middle;
    for (std::size_t k = 0; k < 3; ++k) middle += fmt::format("{} ", 0.5 * (std::stod(a[k]) + std::stod(b[k])));
    flat.push_back({vertex0 + std::size_t(triangle(t, 2) - 1), middle + "0"});
  }
  m = error_with(flat);
  CHECK(m.find(fmt::format("b.mesh:{}: triangle 12001 has zero area", triangle0 + 12001)) != std::string::npos);
}
