// The seeds of the fast marching: interface segments from a level set's zero set or a region's edges.
#include "distance_seeds.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace bodyfit::distance_detail {

/// The zero set of φ in face f, appended to s as one seed face when φ vanishes there.
void add_phi_seed(const FlatMesh& m, const ScalarField& phi, int f, Seeds& s) {
  auto sign = [&](int v) { return phi[v] > 0 ? 1 : phi[v] < 0 ? -1 : 0; };
  std::array<Vec3, 3> zero;
  int count = 0;
  for (int c = 0; c < 3; ++c) {
    const int a = m.corner_vertex(3 * f + c), b = m.corner_vertex(3 * f + (c + 1) % 3);
    if (sign(a) == 0) zero[count++] = m.point(a);
    if (sign(a) * sign(b) < 0) {
      const double t = phi[a] / (phi[a] - phi[b]);  // scale-free
      zero[count++] = m.point(a) + (m.point(b) - m.point(a)) * t;
    }
  }
  if (count == 0) return;
  s.faces.push_back(f);
  if (count == 1) s.segments.emplace_back(zero[0], zero[0]);
  else if (count == 2) s.segments.emplace_back(zero[0], zero[1]);
  else
    for (int i = 0; i < 3; ++i) s.segments.emplace_back(zero[i], zero[(i + 1) % 3]);
  s.seg_start.push_back(int(s.segments.size()));
}

Seeds seeds_from_phi(const FlatMesh& m, const ScalarField& phi) {
  Seeds s;
  s.sign.resize(m.nv());
  for (std::size_t v = 0; v < m.nv(); ++v) {
    s.sign[v] = phi[v] > 0 ? 1 : phi[v] < 0 ? -1 : 0;
    if (s.sign[v] == 0) s.zeros.push_back(int(v));
  }
  s.seg_start.push_back(0);
  for (std::size_t f = 0; f < m.nf(); ++f) add_phi_seed(m, phi, int(f), s);
  return s;
}

namespace {

/// Curvature vector of the interface curve (towards the centre of the circle through a vertex and
/// its two interface neighbours, projected on the tangent plane of S: the geodesic curvature) at
/// each interface vertex where the curve is smooth. `smooth` is false at the vertices of
/// interface-degree ≠ 2, on the boundary of S, or where the curve turns by more than 30°.
void interface_curvature(const SurfaceMesh& mesh, const FlatMesh& m, std::vector<Vec3>& curvature,
                         std::vector<char>& smooth) {
  std::vector<std::array<int, 2>> neighbour(m.nv(), {-1, -1});
  std::vector<int> degree(m.nv(), 0);
  for (auto e : mesh.edges()) {
    if (!mesh.interface(e)) continue;
    const auto h = mesh.halfedge_handle(e, 0);
    const int a = mesh.from_vertex_handle(h).idx(), b = mesh.to_vertex_handle(h).idx();
    if (degree[a] < 2) neighbour[a][degree[a]] = b;
    if (degree[b] < 2) neighbour[b][degree[b]] = a;
    ++degree[a];
    ++degree[b];
  }
  const double cos_max_turn = std::cos(std::numbers::pi / 6);
  curvature.assign(m.nv(), Vec3(0, 0, 0));
  smooth.assign(m.nv(), 0);
  for (std::size_t v = 0; v < m.nv(); ++v) {
    if (degree[v] != 2 || mesh.is_boundary(VertexHandle(int(v)))) continue;
    const Vec3& x = m.point(int(v));
    const Vec3 u = m.point(neighbour[v][0]) - x, w = m.point(neighbour[v][1]) - x;
    // The turn between the segments (x − u-end) and (w-end − x) has cosine −u·w / (|u||w|).
    if (-(u | w) < cos_max_turn * u.norm() * w.norm()) continue;
    smooth[v] = 1;
    const Vec3 uw = u % w;
    const double uw2 = uw.sqrnorm();
    if (uw2 == 0) continue;  // collinear: straight
    const Vec3 centre = ((w * u.sqrnorm() - u * w.sqrnorm()) % uw) / (2 * uw2);  // circumcentre − x
    Vec3 k = centre / centre.sqrnorm();
    Vec3 normal(0, 0, 0);
    const FanRange fan = m.fan(int(v));
    for (int j = fan.begin; j < fan.end; ++j) {
      const FanTriangle t = m.fan_triangle(j);
      normal += (m.point(t.a) - x) % (m.point(t.b) - x);
    }
    const double length = normal.norm();
    if (length > 0) {
      normal /= length;
      k -= normal * (k | normal);
    }
    curvature[v] = k;
  }
}

}  // namespace

Seeds seeds_from_region(const SurfaceMesh& mesh, const FlatMesh& m, bool curved) {
  Seeds s;
  std::vector<Vec3> curvature;
  std::vector<char> smooth;
  if (curved) interface_curvature(mesh, m, curvature, smooth);
  const Vec3 zero(0, 0, 0);
  // An interface edge bends only when both its ends are smooth curve points.
  auto add_segment = [&](int a, int b) {
    s.segments.emplace_back(m.point(a), m.point(b));
    if (!curved) return;
    if (a != b && smooth[a] && smooth[b]) s.bends.emplace_back(curvature[a], curvature[b]);
    else s.bends.emplace_back(zero, zero);
  };
  s.sign.assign(m.nv(), 1);
  for (auto f : mesh.faces())
    if (mesh.inside(f)) {
      const auto h = mesh.halfedge_handle(f);
      s.sign[std::size_t(mesh.from_vertex_handle(h).idx())] = -1;
      s.sign[std::size_t(mesh.to_vertex_handle(h).idx())] = -1;
      s.sign[std::size_t(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)).idx())] = -1;
    }
  std::vector<char> on_interface(m.nv(), 0);
  for (auto e : mesh.edges()) {
    if (!mesh.interface(e)) continue;
    const auto h = mesh.halfedge_handle(e, 0);
    on_interface[mesh.from_vertex_handle(h).idx()] = 1;
    on_interface[mesh.to_vertex_handle(h).idx()] = 1;
  }
  for (std::size_t v = 0; v < m.nv(); ++v)
    if (on_interface[v]) {
      s.sign[v] = 0;
      s.zeros.push_back(int(v));
    }
  s.seg_start.push_back(0);
  // A seed face has an interface edge or a corner on the interface: one of the faces around the
  // interface's vertices (in index order, as a pass over every face would find them).
  std::vector<int> around;
  for (int v : s.zeros)
    for (auto f : mesh.vf_range(VertexHandle(v))) around.push_back(f.idx());
  std::sort(around.begin(), around.end());
  around.erase(std::unique(around.begin(), around.end()), around.end());
  for (int f : around) {
    const auto h0 = mesh.halfedge_handle(FaceHandle(f));
    bool seed = false;
    for (auto h : {h0, mesh.next_halfedge_handle(h0), mesh.prev_halfedge_handle(h0)}) {
      const int a = mesh.from_vertex_handle(h).idx(), b = mesh.to_vertex_handle(h).idx();
      if (mesh.interface(mesh.edge_handle(h))) {
        add_segment(a, b);
        seed = true;
      } else if (on_interface[a]) {
        add_segment(a, a);
        seed = true;
      }
    }
    if (!seed) continue;
    s.faces.push_back(f);
    s.seg_start.push_back(int(s.segments.size()));
  }
  return s;
}

}  // namespace bodyfit::distance_detail
