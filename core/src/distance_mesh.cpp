// The flat mesh of the fast marching: arrays, fans, and the unfolding that splits obtuse corners.
#include "distance_mesh.hpp"

#include <bodyfit/error.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace bodyfit::distance_detail {
namespace {

FlatMesh flatten(const SurfaceMesh& mesh) {
  FlatMesh m;
  m.nv = mesh.n_vertices();
  m.nf = mesh.n_faces();
  m.points.resize(m.nv);
  for (std::size_t i = 0; i < m.nv; ++i) m.points[i] = mesh.point(VertexHandle(int(i)));
  m.corner_vertex.resize(3 * m.nf);
  m.across.resize(3 * m.nf);
  m.obtuse.assign(3 * m.nf, -1);
  for (std::size_t f = 0; f < m.nf; ++f)
    if (mesh.status(FaceHandle(int(f))).deleted())
      throw InputError("signed_distance: the mesh must be garbage-collected");
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m.nf, 4096), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t f = range.begin(); f != range.end(); ++f) {
      const auto h0 = mesh.halfedge_handle(FaceHandle(int(f)));
      const auto h1 = mesh.next_halfedge_handle(h0);
      const auto h2 = mesh.next_halfedge_handle(h1);
      m.corner_vertex[3 * f + 0] = mesh.from_vertex_handle(h0).idx();
      m.corner_vertex[3 * f + 1] = mesh.to_vertex_handle(h0).idx();
      m.corner_vertex[3 * f + 2] = mesh.to_vertex_handle(h1).idx();
      // corner c is opposite the halfedge from corner c+1 to corner c+2
      m.across[3 * f + 0] = mesh.opposite_face_handle(h1).idx();
      m.across[3 * f + 1] = mesh.opposite_face_handle(h2).idx();
      m.across[3 * f + 2] = mesh.opposite_face_handle(h0).idx();
    }
  });
  return m;
}

/// The fans, after the obtuse corners are known.
void build_fans(FlatMesh& m) {
  m.split_start.assign(m.nv + 1, 0);
  for (const auto& s : m.splits) ++m.split_start[s.vertex + 1];
  for (std::size_t i = 0; i < m.nv; ++i) m.split_start[i + 1] += m.split_start[i];
  m.split_list.resize(m.splits.size());
  std::vector<int> next(m.split_start.begin(), m.split_start.end() - 1);
  for (std::size_t i = 0; i < m.splits.size(); ++i) m.split_list[next[m.splits[i].vertex]++] = int(i);

  m.fan_start.assign(m.nv + 1, 0);
  for (int v : m.corner_vertex) ++m.fan_start[v + 1];
  for (std::size_t i = 0; i < m.nv; ++i) m.fan_start[i + 1] += m.fan_start[i];
  m.fan.resize(3 * m.nf);
  std::vector<int> fill(m.fan_start.begin(), m.fan_start.end() - 1);
  for (std::size_t k = 0; k < 3 * m.nf; ++k) {
    const std::size_t f = k / 3, c = k % 3;
    FanTriangle t;
    t.a = m.corner_vertex[3 * f + (c + 1) % 3];
    t.b = m.corner_vertex[3 * f + (c + 2) % 3];
    t.corner = int(k);
    t.obtuse = std::uint8_t((m.obtuse[3 * f + (c + 1) % 3] != -1 ? 1 : 0) | (m.obtuse[3 * f + (c + 2) % 3] != -1 ? 2 : 0));
    m.fan[fill[m.corner_vertex[k]]++] = t;
  }
}

/// Position of the third vertex of the triangle (p, q, r) unfolded into the plane of the 2-D points
/// P, Q (p → P, q → Q), on the side opposite `away`.
std::array<double, 2> unfold(const Vec3& p, const Vec3& q, const Vec3& r, std::array<double, 2> P,
                             std::array<double, 2> Q, std::array<double, 2> away) {
  const Vec3 e = q - p, w = r - p;
  const double len2 = e.sqrnorm();
  const double s = (w | e) / len2;                     // coordinate along pq
  const double hgt = (w - e * s).norm();               // distance of r from the line pq
  const std::array<double, 2> E{Q[0] - P[0], Q[1] - P[1]};
  const double len = std::sqrt(E[0] * E[0] + E[1] * E[1]);
  std::array<double, 2> n{-E[1] / len, E[0] / len};
  if ((away[0] - P[0]) * n[0] + (away[1] - P[1]) * n[1] > 0) n = {-n[0], -n[1]};
  return {P[0] + s * E[0] + hgt * n[0], P[1] + s * E[1] + hgt * n[1]};
}

/// Kimmel–Sethian unfolding for the obtuse corner k = 3f + c: walk across the faces beyond the
/// opposite edge, unfolded into the plane of f, until a vertex falls in the section of the angle
/// where both sub-angles are acute.
void split_obtuse_corner(FlatMesh& m, int k) {
  const int f = k / 3, c = k % 3;
  const int xv = m.corner_vertex[k];
  int pv = m.corner_vertex[3 * f + (c + 1) % 3], qv = m.corner_vertex[3 * f + (c + 2) % 3];
  const Vec3& x = m.points[xv];
  const Vec3 ea = m.points[pv] - x, eb = m.points[qv] - x;
  const double la = ea.norm();
  // 2-D frame: x at the origin, a on the first axis.
  const std::array<double, 2> X{0, 0};
  const double bx = (eb | ea) / la;
  const std::array<double, 2> A0{la, 0}, B0{bx, (eb - ea * (bx / la)).norm()};
  auto dot = [](std::array<double, 2> u, std::array<double, 2> v) { return u[0] * v[0] + u[1] * v[1]; };
  std::array<double, 2> P = A0, Q = B0;
  int face = f;
  int far_corner = c;  // corner of `face` opposite the edge (pv, qv)
  for (int step = 0; step < 16; ++step) {
    const int next = m.across[3 * face + far_corner];
    if (next < 0) return;
    int rc = 0;  // the corner of `next` that is neither pv nor qv
    for (int i = 0; i < 3; ++i) {
      const int w = m.corner_vertex[3 * next + i];
      if (w != pv && w != qv) rc = i;
    }
    const int rv = m.corner_vertex[3 * next + rc];
    // The unfolded r lies on the side of pq away from x (x is on the near side for every strip face).
    const std::array<double, 2> R = unfold(m.points[pv], m.points[qv], m.points[rv], P, Q, X);
    // Acute section: r·a > 0 and r·b > 0 (both sub-angles below 90°).
    const bool acute_a = dot(R, A0) > 0, acute_b = dot(R, B0) > 0;
    if (acute_a && acute_b) {
      const Vec3 ea3{A0[0], A0[1], 0}, eb3{B0[0], B0[1], 0}, er3{R[0], R[1], 0};
      ObtuseSplit s;
      s.corner = k;
      s.vertex = rv;
      s.first = corner_geometry(ea3, er3);
      s.second = corner_geometry(er3, eb3);
      m.obtuse[k] = int(m.splits.size());
      m.splits.push_back(s);
      return;
    }
    // Continue across the edge of `next` that the section crosses: if r is on a's side of the
    // section (too close to a: r·b ≤ 0), the section lies between r and q.
    face = next;
    if (!acute_b) {
      pv = rv;
      P = R;
    } else {
      qv = rv;
      Q = R;
    }
    for (int i = 0; i < 3; ++i) {
      const int w = m.corner_vertex[3 * face + i];
      if (w != pv && w != qv) far_corner = i;
    }
  }
}

void find_obtuse_corners(FlatMesh& m) {
  // Found in parallel (obtuse, no split found yet: −2), split in corner order (the splits' indices).
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, 3 * m.nf, 3 * 4096), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t k = range.begin(); k != range.end(); ++k) {
      const int f = int(k / 3), c = int(k % 3);
      const Vec3& x = m.points[m.corner_vertex[3 * f + c]];
      const Vec3& a = m.points[m.corner_vertex[3 * f + (c + 1) % 3]];
      const Vec3& b = m.points[m.corner_vertex[3 * f + (c + 2) % 3]];
      if (((a - x) | (b - x)) < 0) m.obtuse[k] = -2;
    }
  });
  for (std::size_t k = 0; k < 3 * m.nf; ++k)
    if (m.obtuse[k] == -2) split_obtuse_corner(m, int(k));
}

}  // namespace

FlatMesh prepared_mesh(const SurfaceMesh& mesh) {
  FlatMesh m = flatten(mesh);
  find_obtuse_corners(m);
  build_fans(m);
  return m;
}

/// Discrete Gaussian curvature at each vertex: angle defect over a third of the incident area
/// (0 on the boundary, where the defect measures the boundary's turning instead).
double gaussian_curvature(const FlatMesh& m, int v) {
  double angle = 0, area = 0;
  const Vec3& p = m.points[v];
  for (int j = m.fan_start[v]; j < m.fan_start[v + 1]; ++j) {  // the faces around v, in index order
    const int f = m.fan[j].corner / 3, c = m.fan[j].corner % 3;
    const Vec3 u = m.points[m.corner_vertex[3 * f + (c + 1) % 3]] - p, w = m.points[m.corner_vertex[3 * f + (c + 2) % 3]] - p;
    angle += std::atan2((u % w).norm(), u | w);
    area += (u % w).norm() / 6;
    // An edge of v without a face across: v is on the boundary.
    if (m.across[3 * f + (c + 1) % 3] < 0 || m.across[3 * f + (c + 2) % 3] < 0) return 0;
  }
  return area > 0 ? (2 * std::numbers::pi - angle) / area : 0.0;
}

}  // namespace bodyfit::distance_detail
