// The seeds of the fast marching: interface segments from a level set's zero set or a region's edges.
#include "distance_seeds.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <numbers>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

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

/// The interface's vertices (in index order) with their interface neighbours; `slot` maps a vertex
/// to its place in `vertices`, −1 off the interface.
struct InterfaceCurve {
  struct End {
    std::array<int, 2> neighbour{-1, -1};
    int degree = 0;
    bool smooth = false;
    Vec3 curvature{0, 0, 0};
  };
  std::vector<int> vertices, slot;
  std::vector<End> ends;
};

InterfaceCurve interface_curve(const SurfaceMesh& mesh) {
  InterfaceCurve curve;
  curve.slot.assign(mesh.n_vertices(), -1);
  std::vector<std::array<int, 2>> edges;
  for (auto e : mesh.edges())
    if (mesh.interface(e)) {
      const auto h = mesh.halfedge_handle(e, 0);
      const int a = mesh.from_vertex_handle(h).idx(), b = mesh.to_vertex_handle(h).idx();
      edges.push_back({a, b});
      for (int v : {a, b})
        if (curve.slot[std::size_t(v)] < 0) {
          curve.slot[std::size_t(v)] = 0;
          curve.vertices.push_back(v);
        }
    }
  std::sort(curve.vertices.begin(), curve.vertices.end());
  for (std::size_t i = 0; i < curve.vertices.size(); ++i) curve.slot[std::size_t(curve.vertices[i])] = int(i);
  curve.ends.resize(curve.vertices.size());
  for (const auto& [a, b] : edges) {
    auto& ea = curve.ends[std::size_t(curve.slot[std::size_t(a)])];
    auto& eb = curve.ends[std::size_t(curve.slot[std::size_t(b)])];
    if (ea.degree < 2) ea.neighbour[std::size_t(ea.degree)] = b;
    if (eb.degree < 2) eb.neighbour[std::size_t(eb.degree)] = a;
    ++ea.degree;
    ++eb.degree;
  }
  return curve;
}

/// Curvature vector of the interface curve (towards the centre of the circle through a vertex and
/// its two interface neighbours, projected on the tangent plane of S: the geodesic curvature) at
/// each interface vertex where the curve is smooth. Not smooth: the vertices of interface-degree
/// ≠ 2, on the boundary of S, or where the curve turns by more than 30°.
void interface_curvature(const SurfaceMesh& mesh, const FlatMesh& m, InterfaceCurve& curve) {
  const double cos_max_turn = std::cos(std::numbers::pi / 6);
  for (std::size_t i = 0; i < curve.vertices.size(); ++i) {
    const int v = curve.vertices[i];
    auto& end = curve.ends[i];
    if (end.degree != 2 || mesh.is_boundary(VertexHandle(v))) continue;
    const Vec3& x = m.point(v);
    const Vec3 u = m.point(end.neighbour[0]) - x, w = m.point(end.neighbour[1]) - x;
    // The turn between the segments (x − u-end) and (w-end − x) has cosine −u·w / (|u||w|).
    if (-(u | w) < cos_max_turn * u.norm() * w.norm()) continue;
    end.smooth = true;
    const Vec3 uw = u % w;
    const double uw2 = uw.sqrnorm();
    if (uw2 == 0) continue;  // collinear: straight
    const Vec3 centre = ((w * u.sqrnorm() - u * w.sqrnorm()) % uw) / (2 * uw2);  // circumcentre − x
    Vec3 k = centre / centre.sqrnorm();
    Vec3 normal(0, 0, 0);
    const FanRange fan = m.fan(v);
    for (int j = fan.begin; j < fan.end; ++j) {
      const FanTriangle t = m.fan_triangle(j);
      normal += (m.point(t.a) - x) % (m.point(t.b) - x);
    }
    const double length = normal.norm();
    if (length > 0) {
      normal /= length;
      k -= normal * (k | normal);
    }
    end.curvature = k;
  }
}

}  // namespace

Seeds seeds_from_region(const SurfaceMesh& mesh, const FlatMesh& m, bool curved) {
  Seeds s;
  InterfaceCurve curve = interface_curve(mesh);
  if (curved) interface_curvature(mesh, m, curve);
  auto on_interface = [&](int v) { return curve.slot[std::size_t(v)] >= 0; };
  const Vec3 zero(0, 0, 0);
  // An interface edge bends only when both its ends are smooth curve points.
  auto add_segment = [&](int a, int b) {
    s.segments.emplace_back(m.point(a), m.point(b));
    if (!curved) return;
    const auto& ea = curve.ends[std::size_t(curve.slot[std::size_t(a)])];
    const auto& eb = curve.ends[std::size_t(curve.slot[std::size_t(b)])];
    if (a != b && ea.smooth && eb.smooth) s.bends.emplace_back(ea.curvature, eb.curvature);
    else s.bends.emplace_back(zero, zero);
  };
  s.sign.assign(m.nv(), 1);
  // −1 at the vertices of the region's faces; several faces may write the same −1 at once.
  tbb::parallel_for(tbb::blocked_range<int>(0, int(mesh.n_faces()), 8192), [&](const tbb::blocked_range<int>& range) {
    for (int f = range.begin(); f != range.end(); ++f)
      if (mesh.inside(FaceHandle(f))) {
        const auto h = mesh.halfedge_handle(FaceHandle(f));
        for (auto v : {mesh.from_vertex_handle(h), mesh.to_vertex_handle(h),
                       mesh.to_vertex_handle(mesh.next_halfedge_handle(h))})
          std::atomic_ref<signed char>(s.sign[std::size_t(v.idx())]).store(-1, std::memory_order_relaxed);
      }
  });
  for (int v : curve.vertices) s.sign[std::size_t(v)] = 0;
  s.zeros = curve.vertices;
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
      } else if (on_interface(a)) {
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
