// Remeshing to any target size in one call (refining ×3 and ×10, coarsening ×10): no edge left
// above the split bound, a stated worst quality, and a report that says why the passes stopped.
// And the arrays remesh() leaves: the spatial order (reorder_spatially: a permutation that keeps the
// mesh, the same for any number of threads, idempotent) and the garbage collection (collect_garbage:
// the arrays OpenMesh's garbage collection gives).
#include <doctest/doctest.h>

#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/levelset_mesher.hpp>
#include <bodyfit/projection.hpp>
#include <bodyfit/remesh.hpp>
#include <bodyfit/validate.hpp>

#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <random>
#include <string>
#include <tuple>
#include <vector>

using namespace bodyfit;
namespace fs = std::filesystem;

namespace {

constexpr double kSplitBound = 1.41;  // the remesher's split ratio (remesher.hpp)

/// Square [0, 1]² in the plane z = 0, n × n cells, two triangles each.
SurfaceMesh make_grid(int n) {
  SurfaceMesh mesh;
  std::vector<VertexHandle> vh;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) vh.push_back(mesh.add_vertex(Vec3(double(i) / n, double(j) / n, 0)));
  auto id = [&](int i, int j) { return vh[std::size_t(j) * std::size_t(n + 1) + std::size_t(i)]; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      mesh.add_face(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      mesh.add_face(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  for (auto f : mesh.faces()) mesh.region(f) = kOutside;
  return mesh;
}

struct Outcome {
  RemeshReport report;
  double longest_ratio = 0;  // longest edge / hmax
  QualityStats quality;
  std::string problems;
};

Outcome remesh_to(SurfaceMesh& mesh, RemeshOptions options) {
  const long euler = euler_characteristic(mesh);
  const std::size_t loops = boundary_loops(mesh).size();
  Outcome out;
  out.report = remesh(mesh, options);
  out.longest_ratio = edge_length_stats(mesh).max / options.hmax;
  out.quality = quality_stats(mesh);
  ValidateOptions vo;
  vo.euler_characteristic = euler;
  vo.boundary_loops = loops;
  auto check = validate_mesh(mesh, vo);
  out.problems = check.ok() ? "" : check.summary();
  MESSAGE("faces " << mesh.n_faces() << ", longest edge / hmax " << out.longest_ratio << ", q min " << out.quality.min
                   << " mean " << out.quality.mean << ", " << out.report.split_rounds << " split rounds + "
                   << out.report.passes << " passes, " << std::string(to_string(out.report.stop)));
  return out;
}

/// Everything a permutation of the elements must keep: vertices with their data, faces and edges by
/// the positions of their vertices with their tags (sorted, so independent of the numbering).
struct Signature {
  std::vector<std::tuple<double, double, double, double, int, int, int>> vertices;
  std::vector<std::tuple<std::array<double, 9>, int>> faces;
  std::vector<std::tuple<std::array<double, 6>, int, int, int, int>> edges;
  bool operator==(const Signature&) const = default;
};

std::array<double, 3> key(const Vec3& p) { return {p[0], p[1], p[2]}; }

Signature signature(const SurfaceMesh& mesh) {
  Signature s;
  for (auto v : mesh.vertices()) {
    const Vec3& p = mesh.point(v);
    s.vertices.emplace_back(p[0], p[1], p[2], mesh.phi(v), mesh.vertex_ref(v), mesh.corner(v), mesh.required(v));
  }
  for (auto f : mesh.faces()) {
    // The face's corners from its smallest one, in its own cyclic order (keeps the orientation).
    auto vs = face_vertices(mesh, f);
    std::array<std::array<double, 3>, 3> c{key(mesh.point(vs[0])), key(mesh.point(vs[1])), key(mesh.point(vs[2]))};
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
    s.faces.emplace_back(std::array<double, 9>{c[0][0], c[0][1], c[0][2], c[1][0], c[1][1], c[1][2], c[2][0], c[2][1], c[2][2]},
                         mesh.region(f));
  }
  for (auto e : mesh.edges()) {
    auto h = mesh.halfedge_handle(e, 0);
    auto a = key(mesh.point(mesh.from_vertex_handle(h))), b = key(mesh.point(mesh.to_vertex_handle(h)));
    if (b < a) std::swap(a, b);
    s.edges.emplace_back(std::array<double, 6>{a[0], a[1], a[2], b[0], b[1], b[2]}, mesh.interface(e), mesh.ridge(e),
                         mesh.required(e), mesh.edge_ref(e));
  }
  std::sort(s.vertices.begin(), s.vertices.end());
  std::sort(s.faces.begin(), s.faces.end());
  std::sort(s.edges.begin(), s.edges.end());
  return s;
}

/// The arrays themselves, in index order (what a checkpoint stores).
struct Arrays {
  std::vector<double> points;
  std::vector<int> connectivity;
  bool operator==(const Arrays&) const = default;
};

Arrays arrays(const SurfaceMesh& mesh) {
  Arrays a;
  for (auto v : mesh.all_vertices()) {
    for (int k = 0; k < 3; ++k) a.points.push_back(mesh.point(v)[k]);
    a.connectivity.push_back(mesh.halfedge_handle(v).idx());
  }
  for (auto h : mesh.all_halfedges()) {
    a.connectivity.push_back(mesh.to_vertex_handle(h).idx());
    a.connectivity.push_back(mesh.next_halfedge_handle(h).idx());
    a.connectivity.push_back(mesh.prev_halfedge_handle(h).idx());
    a.connectivity.push_back(mesh.face_handle(h).idx());
  }
  for (auto f : mesh.all_faces()) a.connectivity.push_back(mesh.halfedge_handle(f).idx());
  return a;
}

/// A cap cut into a sphere whose vertices and faces were added in a random order (no spatial
/// coherence), with a few collapses left uncollected (deleted elements), refs and φ set.
SurfaceMesh scrambled_cap_mesh() {
  auto sphere = make_sphere({.faces = 5000});
  std::mt19937 rng(5);
  std::vector<int> order(sphere.n_vertices());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  SurfaceMesh mesh;
  std::vector<VertexHandle> handle(sphere.n_vertices());
  for (int i : order) handle[std::size_t(i)] = mesh.add_vertex(sphere.point(VertexHandle(i)));
  std::vector<std::array<VertexHandle, 3>> faces;
  for (auto f : sphere.faces()) {
    auto vs = face_vertices(sphere, f);
    faces.push_back({handle[std::size_t(vs[0].idx())], handle[std::size_t(vs[1].idx())], handle[std::size_t(vs[2].idx())]});
  }
  std::shuffle(faces.begin(), faces.end(), rng);
  for (const auto& t : faces) mesh.add_face(t[0], t[1], t[2]);
  for (auto f : mesh.faces()) mesh.region(f) = kOutside;
  ScalarField phi(mesh.n_vertices());
  for (auto v : mesh.vertices()) phi[std::size_t(v.idx())] = std::acos(std::clamp(mesh.point(v)[2], -1.0, 1.0)) - 0.7;
  discretize(mesh, phi, {});
  for (auto v : mesh.vertices()) mesh.vertex_ref(v) = int(v.idx() % 7);
  int collapsed = 0;
  for (auto e : mesh.edges()) {
    if (collapsed == 20) break;
    auto h = mesh.halfedge_handle(e, 0);
    if (e.idx() % 97 != 0 || mesh.status(e).deleted() || mesh.interface(e) || !mesh.is_collapse_ok(h)) continue;
    mesh.collapse(h);
    ++collapsed;
  }
  return mesh;
}

double mean_index_gap(const SurfaceMesh& mesh) {
  double sum = 0;
  for (auto e : mesh.edges()) {
    auto h = mesh.halfedge_handle(e, 0);
    sum += std::abs(mesh.from_vertex_handle(h).idx() - mesh.to_vertex_handle(h).idx());
  }
  return sum / double(mesh.n_edges());
}

}  // namespace

TEST_CASE("refining a sphere ×3 and ×10 in one call: no edge above the split bound, worst quality ≥ 0.6") {
  for (double factor : {3.0, 10.0}) {
    CAPTURE(factor);
    auto mesh = make_sphere({.faces = 500});
    RemeshOptions options;
    options.hmax = edge_length_stats(mesh).mean / factor;  // the input triangles are the reference
    auto out = remesh_to(mesh, options);
    CHECK(out.problems == "");
    CHECK(out.report.long_edges == 0);
    CHECK(out.longest_ratio <= kSplitBound * (1 + 1e-9));
    CHECK(out.report.max_edge_ratio <= kSplitBound * (1 + 1e-9));
    CHECK(out.quality.min >= 0.6);
    CHECK(out.quality.mean >= 0.9);
    // Bisection halves lengths: at least ⌈log2 factor⌉ rounds, and not many more.
    CHECK(out.report.split_rounds >= int(std::ceil(std::log2(factor))));
    CHECK(out.report.split_rounds <= int(std::ceil(std::log2(factor))) + 3);
    CHECK(out.report.stop != RemeshStop::PassLimit);
    // Edges between 0.71 and 1.41 hmax (the mean near hmax): about factor² as many faces.
    CHECK(double(mesh.n_faces()) > 0.5 * factor * factor * 500);
    CHECK(double(mesh.n_faces()) < 3.0 * factor * factor * 500);
  }
}

TEST_CASE("remeshing to a size gives the same arrays with one thread and with two") {
  // Refined ×3, the work lists and a split round's edges span many blocks of the parallel gathers
  // (work edges, midpoint projections, flip screening), and the first pass queues every split's
  // vertex: one thread relocates them in a loop, two in waves (remesh_waves.cpp), which must move
  // each vertex as the loop does. fandisk's creases turn the distance checks on (a chord's sag
  // proven from the triangles at its ends, or searched).
  const auto fandisk = read_mesh(fs::path(BODYFIT_SOURCE_DIR) / "meshes/public/fandisk.off");
  for (const auto& named : {std::pair{"sphere", make_sphere({.faces = 8000})}, std::pair{"fandisk", fandisk}}) {
    const std::string name = named.first;
    const SurfaceMesh& input = named.second;
    CAPTURE(name);
    Arrays expected;
    for (int threads : {1, 2}) {
      CAPTURE(threads);
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
      SurfaceMesh mesh = input;
      RemeshOptions options;
      options.hmax = edge_length_stats(mesh).mean / 3;
      const auto report = remesh(mesh, options);
      CHECK(report.splits > 8192);
      if (threads == 1) expected = arrays(mesh);
      else CHECK(arrays(mesh) == expected);
    }
  }
}

TEST_CASE("coarsening ×10 in one call: a sphere and a flat square, no edge above the split bound") {
  SUBCASE("sphere") {
    auto mesh = make_sphere({.faces = 40000});
    RemeshOptions options;
    options.hmax = 10 * edge_length_stats(mesh).mean;
    options.hausd = options.hmax * options.hmax;  // sizes not bounded by the curvature (h ≤ √(8·hausd))
    options.reference = ReferenceSurface::sphere(Vec3(0, 0, 0), 1.0);
    auto out = remesh_to(mesh, options);
    CHECK(out.problems == "");
    CHECK(out.report.long_edges == 0);
    CHECK(out.longest_ratio <= kSplitBound * (1 + 1e-9));
    CHECK(out.quality.min >= 0.45);
    CHECK(out.report.stop != RemeshStop::PassLimit);
    CHECK(mesh.n_faces() < 40000 / 40);  // ~×100 fewer faces (400 at edges equal to hmax)
    CHECK(mesh.n_faces() > 40000 / 400);
  }
  SUBCASE("flat square with its boundary") {
    auto mesh = make_grid(100);
    RemeshOptions options;
    options.hmax = 0.1;
    auto out = remesh_to(mesh, options);
    CHECK(out.problems == "");
    CHECK(out.report.long_edges == 0);
    CHECK(out.longest_ratio <= kSplitBound * (1 + 1e-9));
    CHECK(out.quality.min >= 0.45);
    CHECK(out.report.stop != RemeshStop::PassLimit);
    CHECK(mesh.n_faces() < 20000 / 25);
  }
}

TEST_CASE("the report says why the passes stopped") {
  SUBCASE("nothing to do: converged, without a pass that changes anything") {
    auto mesh = make_sphere({.faces = 2000});
    RemeshOptions options;
    options.hmax = edge_length_stats(mesh).mean;
    auto report = remesh(mesh, options);
    CHECK(report.stop == RemeshStop::Converged);
    CHECK(report.split_rounds == 0);
    CHECK(report.splits + report.collapses + report.flips + report.relocations == 0);
    CHECK(std::string(to_string(report.stop)) == "converged");
  }
  SUBCASE("a cap on the passes is reported as such, and there is still no long edge") {
    auto mesh = make_sphere({.faces = 20000});  // coarsened ×5: several passes of collapses
    RemeshOptions options;
    options.hmax = 5 * edge_length_stats(mesh).mean;
    options.hausd = options.hmax * options.hmax;
    options.max_passes = 1;
    auto report = remesh(mesh, options);
    CHECK(report.passes == 1);
    CHECK(report.stop == RemeshStop::PassLimit);
    CHECK(std::string(to_string(report.stop)) == "pass limit");
    CHECK(report.long_edges == 0);
  }
  SUBCASE("without a cap: converged or stalled, in a bounded number of passes") {
    auto mesh = make_sphere({.faces = 500});
    RemeshOptions options;
    options.hmax = edge_length_stats(mesh).mean / 4;
    auto report = remesh(mesh, options);
    CHECK((report.stop == RemeshStop::Converged || report.stop == RemeshStop::Stalled));
    CHECK(report.passes >= 1);
    CHECK(report.passes <= 30);
  }
}

TEST_CASE("reorder_spatially: a permutation that keeps the mesh, deterministic, idempotent") {
  auto mesh = scrambled_cap_mesh();
  const auto before_mesh = mesh;
  const auto before = signature(mesh);
  const double gap_before = mean_index_gap(mesh);
  const long euler = long(before.vertices.size()) - long(before.edges.size()) + long(before.faces.size());
  reorder_spatially(mesh);
  // Same vertices (with φ, refs, flags), faces (oriented, with regions) and edges (with tags).
  CHECK(signature(mesh) == before);
  for (auto v : mesh.all_vertices()) CHECK_FALSE(mesh.status(v).deleted());
  for (auto f : mesh.all_faces()) CHECK_FALSE(mesh.status(f).deleted());
  ValidateOptions vo;
  vo.euler_characteristic = euler;
  vo.boundary_loops = 0;
  auto report = validate_mesh(mesh, vo);
  CHECK_MESSAGE(report.ok(), report.summary());
  // Neighbours are close in memory now.
  const double gap_after = mean_index_gap(mesh);
  MESSAGE("mean |index difference| over edges: " << gap_before << " -> " << gap_after << ", disorder "
                                                 << spatial_disorder(before_mesh) << " -> " << spatial_disorder(mesh));
  CHECK(gap_after < 0.1 * gap_before);
  CHECK(spatial_disorder(before_mesh) > 0.3);
  CHECK(spatial_disorder(mesh) < 0.05);
  // Idempotent: a mesh already in this order is left as it is.
  const auto once = arrays(mesh);
  reorder_spatially(mesh);
  CHECK(arrays(mesh) == once);
  // The same arrays with one thread and with two.
  for (int threads : {1, 2}) {
    CAPTURE(threads);
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    auto again = scrambled_cap_mesh();
    reorder_spatially(again);
    CHECK(arrays(again) == once);
  }
}

TEST_CASE("collect_garbage gives the arrays of OpenMesh's garbage collection") {
  auto mesh = scrambled_cap_mesh();  // 20 collapses not yet collected
  auto reference = mesh;
  reference.garbage_collection();
  collect_garbage(mesh);
  CHECK(arrays(mesh) == arrays(reference));
  CHECK(signature(mesh) == signature(reference));
  CHECK(mesh.n_vertices() == reference.n_vertices());
  CHECK(mesh.n_edges() == reference.n_edges());
  CHECK(mesh.n_faces() == reference.n_faces());
  auto report = validate_mesh(mesh, {});
  CHECK_MESSAGE(report.ok(), report.summary());
}

TEST_CASE("a generated sphere is left in its order, remesh() renumbers a scattered mesh, and with spatial_order = false only collects garbage") {
  for (std::size_t faces : {5000, 60000}) {
    CAPTURE(faces);
    CHECK(spatial_disorder(make_sphere({.faces = faces})) < 0.1);
  }

  auto mesh = scrambled_cap_mesh();
  collect_garbage(mesh);
  CHECK(spatial_disorder(mesh) > 0.05);
  auto plain = mesh;
  RemeshOptions options;
  options.reference = ReferenceSurface::sphere(Vec3(0, 0, 0), 1.0);
  auto report = remesh(mesh, options);
  REQUIRE(report.splits + report.collapses + report.flips > 0);
  CHECK(spatial_disorder(mesh) < 0.05);
  const auto ordered = arrays(mesh);
  reorder_spatially(mesh);
  CHECK(arrays(mesh) == ordered);  // already in order
  options.spatial_order = false;
  remesh(plain, options);
  CHECK(signature(plain) == signature(mesh));  // the same mesh, numbered otherwise
  CHECK_FALSE(arrays(plain) == ordered);
  CHECK(spatial_disorder(plain) > 0.05);
}

TEST_CASE("spatial_disorder_after_reorder is the disorder reorder_spatially leaves, and one vertex order serves both") {
  auto mesh = scrambled_cap_mesh();  // deleted elements included: the holes count before, not after
  const double before = spatial_disorder(mesh);
  const std::vector<int> order = spatial_vertex_order(mesh);
  std::size_t live = 0;
  for (auto v : mesh.vertices()) {
    (void)v;
    ++live;
  }
  REQUIRE(order.size() == live);
  const double predicted = spatial_disorder_after_reorder(mesh, order);
  CHECK(predicted == spatial_disorder_after_reorder(mesh));
  auto same = mesh;
  reorder_spatially(mesh, order);
  reorder_spatially(same);
  CHECK(arrays(mesh) == arrays(same));
  CHECK(spatial_disorder(mesh) == predicted);
  CHECK(predicted < 0.5 * before);
}
