#include <bodyfit/geometry.hpp>

#include "blocks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

namespace bodyfit {

std::array<Vec3, 3> face_points(const SurfaceMesh& mesh, FaceHandle f) {
  auto h = mesh.halfedge_handle(f);
  return {mesh.point(mesh.from_vertex_handle(h)), mesh.point(mesh.to_vertex_handle(h)),
          mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)))};
}

std::array<VertexHandle, 3> face_vertices(const SurfaceMesh& mesh, FaceHandle f) {
  auto h = mesh.halfedge_handle(f);
  return {mesh.from_vertex_handle(h), mesh.to_vertex_handle(h),
          mesh.to_vertex_handle(mesh.next_halfedge_handle(h))};
}

double triangle_area(const Vec3& a, const Vec3& b, const Vec3& c) {
  return 0.5 * OpenMesh::cross(b - a, c - a).norm();
}

double face_area(const SurfaceMesh& mesh, FaceHandle f) {
  auto [a, b, c] = face_points(mesh, f);
  return triangle_area(a, b, c);
}

Vec3 face_normal(const SurfaceMesh& mesh, FaceHandle f) {
  auto [a, b, c] = face_points(mesh, f);
  Vec3 n = OpenMesh::cross(b - a, c - a);
  double len = n.norm();
  return len > 0 ? n / len : Vec3(0, 0, 0);
}

Vec3 vertex_normal(const SurfaceMesh& mesh, VertexHandle v) {
  Vec3 sum(0, 0, 0);
  for (auto f : mesh.vf_range(v)) {
    auto [a, b, c] = face_points(mesh, f);
    sum += OpenMesh::cross(b - a, c - a);  // |cross| = 2·area: area weighting for free
  }
  double len = sum.norm();
  return len > 0 ? sum / len : sum;
}

double edge_length(const SurfaceMesh& mesh, EdgeHandle e) {
  auto h = mesh.halfedge_handle(e, 0);
  return (mesh.point(mesh.to_vertex_handle(h)) - mesh.point(mesh.from_vertex_handle(h))).norm();
}

double triangle_quality(const Vec3& a, const Vec3& b, const Vec3& c) {
  double l2 = (b - a).sqrnorm() + (c - b).sqrnorm() + (a - c).sqrnorm();
  if (l2 <= 0) return 0;
  return 4.0 * std::sqrt(3.0) * triangle_area(a, b, c) / l2;
}

double face_quality(const SurfaceMesh& mesh, FaceHandle f) {
  auto [a, b, c] = face_points(mesh, f);
  return triangle_quality(a, b, c);
}

std::array<Vec3, 3> p1_basis_gradients(const Vec3& a, const Vec3& b, const Vec3& c) {
  // grad λ_i = (n × e_i) / (2·area), e_i the edge opposite vertex i, oriented along the face.
  Vec3 n = OpenMesh::cross(b - a, c - a);
  double twice_area_sq = n.sqrnorm();
  if (twice_area_sq <= 0) return {Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(0, 0, 0)};
  return {OpenMesh::cross(n, c - b) / twice_area_sq, OpenMesh::cross(n, a - c) / twice_area_sq,
          OpenMesh::cross(n, b - a) / twice_area_sq};
}

Vec3 face_gradient(const SurfaceMesh& mesh, FaceHandle f, const ScalarField& u) {
  auto [a, b, c] = face_points(mesh, f);
  auto [va, vb, vc] = face_vertices(mesh, f);
  auto g = p1_basis_gradients(a, b, c);
  return u[va.idx()] * g[0] + u[vb.idx()] * g[1] + u[vc.idx()] * g[2];
}

VectorField face_gradients(const SurfaceMesh& mesh, const ScalarField& u) {
  VectorField grads(mesh.n_faces(), Vec3(0, 0, 0));
  for (auto f : mesh.faces()) grads[f.idx()] = face_gradient(mesh, f, u);
  return grads;
}

namespace {

/// What face f adds at each of its corners to vertex_gradients: 2·area·∇u, its normal (2·area
/// long) and 2·area; nothing for a degenerate face.
struct CornerShare {
  VertexHandle corners[3];
  Vec3 weighted_gradient, normal;
  double twice_area = 0;
};

bool corner_share(const SurfaceMesh& mesh, FaceHandle f, const ScalarField& u, CornerShare& share) {
  auto h = mesh.halfedge_handle(f);
  share.corners[0] = mesh.to_vertex_handle(h);
  share.corners[1] = mesh.to_vertex_handle(mesh.next_halfedge_handle(h));
  share.corners[2] = mesh.from_vertex_handle(h);
  const Vec3 &a = mesh.point(share.corners[0]), &b = mesh.point(share.corners[1]), &c = mesh.point(share.corners[2]);
  share.normal = OpenMesh::cross(b - a, c - a);
  const double twice_area_sq = share.normal.sqrnorm();
  if (twice_area_sq <= 0) return false;
  // 2·area·∇u = n × (u_a (c − b) + u_b (a − c) + u_c (b − a)) / |n|.
  share.weighted_gradient = OpenMesh::cross(share.normal, u[share.corners[0].idx()] * (c - b) +
                                                              u[share.corners[1].idx()] * (a - c) +
                                                              u[share.corners[2].idx()] * (b - a)) /
                            std::sqrt(twice_area_sq);
  share.twice_area = std::sqrt(twice_area_sq);
  return true;
}

Vec3 averaged_tangent_gradient(const Vec3& sum, const Vec3& normal, double weight) {
  if (!(weight > 0)) return Vec3(0, 0, 0);
  const double len = normal.norm();
  return project_tangent(sum / weight, len > 0 ? normal / len : normal);
}

}  // namespace

VectorField vertex_gradients(const SurfaceMesh& mesh, const ScalarField& u) {
  // One pass over the faces, scattering to the corners: the area-weighted sum of the face
  // gradients and the area-weighted normal (|cross| = 2·area weights both alike).
  const std::size_t nv = mesh.n_vertices();
  VectorField sum(nv, Vec3(0, 0, 0)), normal(nv, Vec3(0, 0, 0));
  std::vector<double> weight(nv, 0.0);
  CornerShare share;
  for (auto f : mesh.faces()) {
    if (!corner_share(mesh, f, u, share)) continue;
    for (const VertexHandle& w : share.corners) {
      sum[w.idx()] += share.weighted_gradient;
      normal[w.idx()] += share.normal;
      weight[w.idx()] += share.twice_area;
    }
  }
  VectorField result(nv, Vec3(0, 0, 0));
  for (std::size_t i = 0; i < nv; ++i) result[i] = averaged_tangent_gradient(sum[i], normal[i], weight[i]);
  return result;
}

VectorField vertex_gradients(const SurfaceMesh& mesh, const ScalarField& u, std::span<const int> vertices) {
  VectorField result(mesh.n_vertices(), Vec3(0, 0, 0));
  // Each vertex on its own (in parallel: a front's band is thousands of vertices at every sub-step).
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, vertices.size(), 256), [&](const auto& range) {
    std::vector<FaceHandle> faces;
    CornerShare share;
    for (std::size_t k = range.begin(); k < range.end(); ++k) {
      const VertexHandle v(vertices[k]);
      faces.clear();
      for (FaceHandle f : mesh.vf_range(v)) faces.push_back(f);
      std::sort(faces.begin(), faces.end());  // the scatter's order: by face index
      Vec3 sum(0, 0, 0), normal(0, 0, 0);
      double weight = 0;
      for (FaceHandle f : faces) {
        if (!corner_share(mesh, f, u, share)) continue;
        sum += share.weighted_gradient;
        normal += share.normal;
        weight += share.twice_area;
      }
      result[std::size_t(v.idx())] = averaged_tangent_gradient(sum, normal, weight);
    }
  });
  return result;
}

Vec3 vertex_gradient(const SurfaceMesh& mesh, VertexHandle v, const ScalarField& u) {
  Vec3 sum(0, 0, 0);
  double weight = 0;
  for (auto f : mesh.vf_range(v)) {
    const double area = face_area(mesh, f);
    sum += area * face_gradient(mesh, f, u);
    weight += area;
  }
  return weight > 0 ? project_tangent(sum / weight, vertex_normal(mesh, v)) : Vec3(0, 0, 0);
}

Vec3 project_tangent(const Vec3& v, const Vec3& unit_normal) {
  return v - OpenMesh::dot(v, unit_normal) * unit_normal;
}

std::array<double, 3> barycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  Vec3 n = OpenMesh::cross(b - a, c - a);
  double d = n.sqrnorm();
  if (d <= 0) return {1.0 / 3, 1.0 / 3, 1.0 / 3};
  double la = OpenMesh::dot(OpenMesh::cross(c - b, p - b), n) / d;
  double lb = OpenMesh::dot(OpenMesh::cross(a - c, p - c), n) / d;
  return {la, lb, 1.0 - la - lb};
}

namespace {

/// Spreads the low 21 bits of x to every third bit (Morton interleaving).
std::uint64_t spread_bits(std::uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffULL;
  x = (x | x << 16) & 0x1f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}

}  // namespace

std::vector<int> z_order(const std::vector<Vec3>& points) { return z_order(points, bounding_box(points)); }

std::vector<int> z_order(const std::vector<Vec3>& points, const BoundingBox& box) {
  const Vec3 extent = box.max - box.min;
  const double scale = double((1 << 21) - 1);
  const int n = int(points.size());
  std::vector<std::pair<std::uint64_t, int>> keyed(n);
  tbb::parallel_for(tbb::blocked_range<int>(0, n, 8192), [&](const tbb::blocked_range<int>& range) {
    for (int i = range.begin(); i != range.end(); ++i) {
      std::uint64_t code = 0;
      for (int c = 0; c < 3; ++c) {
        const double t = extent[c] > 0 ? (points[i][c] - box.min[c]) / extent[c] : 0.0;
        code |= spread_bits(std::uint64_t(std::clamp(t, 0.0, 1.0) * scale)) << c;
      }
      keyed[i] = {code, i};
    }
  });
  tbb::parallel_sort(keyed.begin(), keyed.end());
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) order[i] = keyed[i].second;
  return order;
}

BoundingBox bounding_box(std::span<const Vec3> points) {
  BoundingBox box;
  if (!points.empty()) box.min = box.max = points[0];
  for (const Vec3& p : points) {
    box.min.minimize(p);
    box.max.maximize(p);
  }
  return box;
}

BoundingBox bounding_box(const SurfaceMesh& mesh) {
  BoundingBox box;
  bool first = true;
  for (auto v : mesh.vertices()) {
    const Vec3& p = mesh.point(v);
    if (first) {
      box.min = box.max = p;
      first = false;
    } else {
      box.min.minimize(p);
      box.max.maximize(p);
    }
  }
  return box;
}

QualityStats quality_stats(const SurfaceMesh& mesh) {
  // Each face's quality in parallel, then the statistics in index order (the mean to the last bit).
  const std::vector<double> quality = terms(int(mesh.n_faces()), [&](int f) {
    return mesh.status(FaceHandle(f)).deleted() ? -1.0 : face_quality(mesh, FaceHandle(f));
  });
  QualityStats s;
  s.min = std::numeric_limits<double>::infinity();
  double sum = 0;
  std::size_t below = 0;
  for (double q : quality) {
    if (q < 0) continue;  // deleted
    s.min = std::min(s.min, q);
    s.max = std::max(s.max, q);
    sum += q;
    below += q < 0.3;
    ++s.faces;
  }
  if (s.faces == 0) return QualityStats{};
  s.mean = sum / double(s.faces);
  s.share_below_0_3 = double(below) / double(s.faces);
  return s;
}

double mean_edge_length(const SurfaceMesh& mesh) { return edge_length_stats(mesh).mean; }

double resolution_length(const SurfaceMesh& mesh) {
  std::size_t faces = 0;  // not deleted
  for ([[maybe_unused]] auto f : mesh.faces()) ++faces;
  // total_area's sum is the faces' areas added in index order, as a loop would.
  return faces > 0 ? std::sqrt(4 * total_area(mesh) / (std::sqrt(3.0) * double(faces))) : 0.0;
}

EdgeLengthStats edge_length_stats(const SurfaceMesh& mesh) {
  // Each length in parallel, then the statistics in index order (the mean to the last bit).
  const std::vector<double> lengths = terms(int(mesh.n_edges()), [&](int e) {
    return mesh.status(EdgeHandle(e)).deleted() ? -1.0 : edge_length(mesh, EdgeHandle(e));
  });
  EdgeLengthStats s;
  s.min = std::numeric_limits<double>::infinity();
  double sum = 0, sum_sq = 0;
  for (double l : lengths) {
    if (l < 0) continue;  // deleted
    s.min = std::min(s.min, l);
    s.max = std::max(s.max, l);
    sum += l;
    sum_sq += l * l;
    ++s.edges;
  }
  if (s.edges == 0) return EdgeLengthStats{};
  s.mean = sum / double(s.edges);
  s.stddev = std::sqrt(std::max(0.0, sum_sq / double(s.edges) - s.mean * s.mean));
  return s;
}

double total_area(const SurfaceMesh& mesh) {
  return sum_in_order(int(mesh.n_faces()), [&](int f) {
    return mesh.status(FaceHandle(f)).deleted() ? 0.0 : face_area(mesh, FaceHandle(f));
  });
}

double region_area(const SurfaceMesh& mesh, int region) {
  return sum_in_order(int(mesh.n_faces()), [&](int f) {
    const FaceHandle face(f);
    return mesh.region(face) == region && !mesh.status(face).deleted() ? face_area(mesh, face) : 0.0;
  });
}

double interface_length(const SurfaceMesh& mesh) {
  return sum_in_order(int(mesh.n_edges()), [&](int e) {
    const EdgeHandle edge(e);
    return mesh.interface(edge) && !mesh.status(edge).deleted() ? edge_length(mesh, edge) : 0.0;
  });
}

namespace {

double distance_to_segment(const Vec3& p, const Segment& s) {
  const Vec3 e = s.second - s.first;
  const double len2 = e.sqrnorm();
  const double t = len2 > 0 ? std::clamp(OpenMesh::dot(p - s.first, e) / len2, 0.0, 1.0) : 0.0;
  return (p - (s.first + t * e)).norm();
}

/// The largest distance from an end or the midpoint of a segment of `from` to the polyline `to`.
double one_sided(const Segments& from, const Segments& to) {
  std::vector<double> worst(from.size(), 0.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, from.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i)
      for (const Vec3& p : {from[i].first, from[i].second, 0.5 * (from[i].first + from[i].second)}) {
        double nearest = std::numeric_limits<double>::infinity();
        for (const Segment& s : to) nearest = std::min(nearest, distance_to_segment(p, s));
        worst[i] = std::max(worst[i], nearest);
      }
  });
  return worst.empty() ? 0.0 : *std::max_element(worst.begin(), worst.end());
}

}  // namespace

Segments interface_segments(const SurfaceMesh& mesh) {
  Segments segments;
  for (auto e : mesh.edges())
    if (mesh.interface(e)) {
      const auto h = mesh.halfedge_handle(e, 0);
      segments.emplace_back(mesh.point(mesh.from_vertex_handle(h)), mesh.point(mesh.to_vertex_handle(h)));
    }
  return segments;
}

double hausdorff_distance(const Segments& a, const Segments& b) {
  if (a.empty() != b.empty()) return std::numeric_limits<double>::infinity();
  return std::max(one_sided(a, b), one_sided(b, a));
}

double interface_hausdorff(const SurfaceMesh& a, const SurfaceMesh& b) {
  return hausdorff_distance(interface_segments(a), interface_segments(b));
}

double l2_difference(const SurfaceMesh& mesh, const ScalarField& u_h, const std::function<double(const Vec3&)>& u) {
  double sum = 0;
  for (auto f : mesh.faces()) {
    const auto v = face_vertices(mesh, f);
    const double area = face_area(mesh, f);
    for (int i = 0; i < 3; ++i) {
      const auto a = v[i], b = v[(i + 1) % 3];
      const double diff = 0.5 * (u_h[a.idx()] + u_h[b.idx()]) - u(0.5 * (mesh.point(a) + mesh.point(b)));
      sum += area / 3 * diff * diff;
    }
  }
  return std::sqrt(sum);
}

long euler_characteristic(const SurfaceMesh& mesh) {
  auto count = [](auto range) {
    long n = 0;
    for ([[maybe_unused]] auto x : range) ++n;
    return n;
  };
  return count(mesh.vertices()) - count(mesh.edges()) + count(mesh.faces());
}

namespace {

// Flood fill over faces adjacent through edges, restricted to faces accepted by `keep`.
template <class Keep>
int flood_components(const SurfaceMesh& mesh, Keep keep, std::vector<int>* labels) {
  std::vector<int> label(mesh.n_faces(), -1);
  int n = 0;
  std::vector<FaceHandle> stack;
  // The faces kept, found in parallel: a region is often a small part of the mesh.
  const auto kept = collect<FaceHandle>(int(mesh.n_faces()), [&](int i, FaceHandle& f) {
    f = FaceHandle(i);
    return !mesh.status(f).deleted() && keep(f);
  });
  for (auto seed : kept) {
    if (label[seed.idx()] >= 0) continue;
    label[seed.idx()] = n;
    stack.push_back(seed);
    while (!stack.empty()) {
      auto f = stack.back();
      stack.pop_back();
      for (auto g : mesh.ff_range(f))
        if (label[g.idx()] < 0 && keep(g)) {
          label[g.idx()] = n;
          stack.push_back(g);
        }
    }
    ++n;
  }
  if (labels) *labels = std::move(label);
  return n;
}

}  // namespace

int connected_components(const SurfaceMesh& mesh, std::vector<int>* labels) {
  return flood_components(mesh, [](FaceHandle) { return true; }, labels);
}

int region_components(const SurfaceMesh& mesh, int region) {
  return flood_components(mesh, [&](FaceHandle f) { return mesh.region(f) == region; }, nullptr);
}

std::vector<std::vector<VertexHandle>> boundary_loops(const SurfaceMesh& mesh) {
  std::vector<std::vector<VertexHandle>> loops;
  std::vector<char> visited(mesh.n_halfedges(), 0);
  for (auto h : mesh.halfedges()) {
    if (!mesh.is_boundary(h) || visited[h.idx()]) continue;
    std::vector<VertexHandle> loop;
    auto cur = h;
    do {
      visited[cur.idx()] = 1;
      loop.push_back(mesh.from_vertex_handle(cur));
      cur = mesh.next_halfedge_handle(cur);
    } while (cur != h && !visited[cur.idx()]);
    loops.push_back(std::move(loop));
  }
  return loops;
}

InterfaceCurves interface_curves(const SurfaceMesh& mesh) {
  // Walk the interface graph: vertices of interface-degree ≠ 2 or on the boundary end open curves.
  std::vector<int> degree(mesh.n_vertices(), 0);
  for (auto e : mesh.edges())
    if (mesh.interface(e)) {
      auto h = mesh.halfedge_handle(e, 0);
      ++degree[mesh.from_vertex_handle(h).idx()];
      ++degree[mesh.to_vertex_handle(h).idx()];
    }
  std::vector<char> seen(mesh.n_edges(), 0);
  InterfaceCurves curves;
  auto is_end = [&](VertexHandle v) { return degree[v.idx()] != 2; };
  auto walk = [&](VertexHandle start, EdgeHandle first) {
    auto v = start;
    auto e = first;
    while (true) {
      seen[e.idx()] = 1;
      auto h = mesh.halfedge_handle(e, 0);
      v = mesh.from_vertex_handle(h) == v ? mesh.to_vertex_handle(h) : mesh.from_vertex_handle(h);
      if (is_end(v) || v == start) return;
      EdgeHandle next;
      for (auto vh : mesh.voh_range(v)) {
        auto ne = mesh.edge_handle(vh);
        if (mesh.interface(ne) && !seen[ne.idx()]) {
          next = ne;
          break;
        }
      }
      if (!next.is_valid()) return;
      e = next;
    }
  };
  for (auto v : mesh.vertices()) {
    if (!is_end(v) || degree[v.idx()] == 0) continue;
    for (auto vh : mesh.voh_range(v)) {
      auto e = mesh.edge_handle(vh);
      if (mesh.interface(e) && !seen[e.idx()]) {
        walk(v, e);
        ++curves.open;
      }
    }
  }
  for (auto e : mesh.edges())
    if (mesh.interface(e) && !seen[e.idx()]) {
      walk(mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)), e);
      ++curves.closed;
    }
  return curves;
}

}  // namespace bodyfit
