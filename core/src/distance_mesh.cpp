// The flat mesh of the fast marching: faces, fans and the unfolding that splits obtuse corners,
// each built when first read.
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

}  // namespace

FlatMesh::FlatMesh(const SurfaceMesh& mesh)
    : mesh_(mesh), nv_(mesh.n_vertices()), nf_(mesh.n_faces()), points_(mesh.points()),
      faces_(new Face[mesh.n_faces()]),  // left uninitialised: a band touches a small part of it
      face_state_(nf_, 0), split_head_(nv_, -1), split_tail_(nv_, -1), fan_range_(nv_, FanRange{-1, -1}) {}

void FlatMesh::build_topology(int f) const {
  const FaceHandle fh(f);
  if (mesh_.status(fh).deleted()) throw InputError("signed_distance: the mesh must be garbage-collected");
  Face& face = faces_[std::size_t(f)];
  const auto h0 = mesh_.halfedge_handle(fh);
  const auto h1 = mesh_.next_halfedge_handle(h0);
  const auto h2 = mesh_.next_halfedge_handle(h1);
  face.vertex[0] = mesh_.from_vertex_handle(h0).idx();
  face.vertex[1] = mesh_.to_vertex_handle(h0).idx();
  face.vertex[2] = mesh_.to_vertex_handle(h1).idx();
  // corner c is opposite the halfedge from corner c+1 to corner c+2
  face.across[0] = mesh_.opposite_face_handle(h1).idx();
  face.across[1] = mesh_.opposite_face_handle(h2).idx();
  face.across[2] = mesh_.opposite_face_handle(h0).idx();
  face.obtuse[0] = face.obtuse[1] = face.obtuse[2] = -1;
  face_state_[std::size_t(f)] = 1;
}

/// Marks f's obtuse corners −2 (no split found yet).
void FlatMesh::find_obtuse(int f) const {
  Face& face = faces_[std::size_t(f)];
  for (int c = 0; c < 3; ++c) {
    const Vec3& x = points_[face.vertex[c]];
    const Vec3& a = points_[face.vertex[(c + 1) % 3]];
    const Vec3& b = points_[face.vertex[(c + 2) % 3]];
    if (((a - x) | (b - x)) < 0) face.obtuse[c] = -2;
  }
}

void FlatMesh::classify(int f) const {
  topology(f);
  find_obtuse(f);
  for (int c = 0; c < 3; ++c)
    if (faces_[std::size_t(f)].obtuse[c] == -2) split_obtuse_corner(3 * f + c);
  face_state_[std::size_t(f)] = 2;
}

/// Kimmel–Sethian unfolding for the obtuse corner k = 3f + c: walk across the faces beyond the
/// opposite edge, unfolded into the plane of f, until a vertex falls in the section of the angle
/// where both sub-angles are acute.
void FlatMesh::split_obtuse_corner(int k) const {
  const int f = k / 3, c = k % 3;
  const int xv = corner_vertex(k);
  int pv = corner_vertex(3 * f + (c + 1) % 3), qv = corner_vertex(3 * f + (c + 2) % 3);
  const Vec3& x = points_[xv];
  const Vec3 ea = points_[pv] - x, eb = points_[qv] - x;
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
    const int next = across(3 * face + far_corner);
    if (next < 0) return;
    int rc = 0;  // the corner of `next` that is neither pv nor qv
    for (int i = 0; i < 3; ++i) {
      const int w = corner_vertex(3 * next + i);
      if (w != pv && w != qv) rc = i;
    }
    const int rv = corner_vertex(3 * next + rc);
    // The unfolded r lies on the side of pq away from x (x is on the near side for every strip face).
    const std::array<double, 2> R = unfold(points_[pv], points_[qv], points_[rv], P, Q, X);
    // Acute section: r·a > 0 and r·b > 0 (both sub-angles below 90°).
    const bool acute_a = dot(R, A0) > 0, acute_b = dot(R, B0) > 0;
    if (acute_a && acute_b) {
      const Vec3 ea3{A0[0], A0[1], 0}, eb3{B0[0], B0[1], 0}, er3{R[0], R[1], 0};
      ObtuseSplit s;
      s.corner = k;
      s.vertex = rv;
      s.first = corner_geometry(ea3, er3);
      s.second = corner_geometry(er3, eb3);
      const int index = int(splits_.size());
      faces_[std::size_t(f)].obtuse[c] = index;
      splits_.push_back(s);
      // Appended to r's list: its splits are visited in the order they were found.
      split_next_.push_back(-1);
      if (split_head_[std::size_t(rv)] < 0) split_head_[std::size_t(rv)] = index;
      else split_next_[std::size_t(split_tail_[std::size_t(rv)])] = index;
      split_tail_[std::size_t(rv)] = index;
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
      const int w = corner_vertex(3 * face + i);
      if (w != pv && w != qv) far_corner = i;
    }
  }
}

FanRange FlatMesh::fan(int v) const {
  const FanRange range = fan_range_[std::size_t(v)];
  if (range.begin >= 0) return range;
  build_fan(v);
  return fan_range_[std::size_t(v)];
}

/// v's fan in corner order (as a pass over every corner lists it), each face classified first.
void FlatMesh::build_fan(int v) const {
  std::array<int, 32> small;
  std::vector<int> large;
  int count = 0;
  for (auto h : mesh_.voh_range(VertexHandle(v))) {
    const auto fh = mesh_.face_handle(h);
    if (!fh.is_valid()) continue;
    const int f = fh.idx();
    const Face& face = topology(f);
    const int c = face.vertex[0] == v ? 0 : face.vertex[1] == v ? 1 : 2;
    if (count < int(small.size())) small[std::size_t(count)] = 3 * f + c;
    else {
      if (large.empty()) large.assign(small.begin(), small.end());
      large.push_back(3 * f + c);
    }
    ++count;
  }
  int* corners = large.empty() ? small.data() : large.data();
  std::sort(corners, corners + count);
  for (int i = 0; i < count; ++i) classified(corners[i] / 3);
  const int begin = int(fan_.size());
  for (int i = 0; i < count; ++i) {
    const int k = corners[i], f = k / 3, c = k % 3;
    const Face& face = faces_[std::size_t(f)];
    FanTriangle t;
    t.a = face.vertex[(c + 1) % 3];
    t.b = face.vertex[(c + 2) % 3];
    t.corner = k;
    t.obtuse = std::uint8_t((face.obtuse[(c + 1) % 3] != -1 ? 1 : 0) | (face.obtuse[(c + 2) % 3] != -1 ? 2 : 0));
    fan_.push_back(t);
  }
  fan_range_[std::size_t(v)] = {begin, int(fan_.size())};
}

void FlatMesh::build_all() const {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf_, 4096), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t f = range.begin(); f != range.end(); ++f)
    {
      if (face_state_[f] == 0) build_topology(int(f));
      if (face_state_[f] == 1) find_obtuse(int(f));
    }
  });
  // The splits in corner order (their indices), those of faces classified already kept.
  for (std::size_t f = 0; f < nf_; ++f)
    if (face_state_[f] == 1) {
      for (int c = 0; c < 3; ++c)
        if (faces_[f].obtuse[c] == -2) split_obtuse_corner(3 * int(f) + c);
      face_state_[f] = 2;
    }
  if (!fan_.empty()) {
    for (std::size_t v = 0; v < nv_; ++v) fan(int(v));
    return;
  }
  // No fan yet: all of them at once, each in corner order.
  std::vector<int> start(nv_ + 1, 0);
  for (std::size_t f = 0; f < nf_; ++f)
    for (int c = 0; c < 3; ++c) ++start[std::size_t(faces_[f].vertex[c]) + 1];
  for (std::size_t i = 0; i < nv_; ++i) start[i + 1] += start[i];
  fan_.resize(3 * nf_);
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (std::size_t f = 0; f < nf_; ++f)
    for (int c = 0; c < 3; ++c) {
      const Face& face = faces_[f];
      FanTriangle t;
      t.a = face.vertex[(c + 1) % 3];
      t.b = face.vertex[(c + 2) % 3];
      t.corner = int(3 * f) + c;
      t.obtuse = std::uint8_t((face.obtuse[(c + 1) % 3] != -1 ? 1 : 0) | (face.obtuse[(c + 2) % 3] != -1 ? 2 : 0));
      fan_[std::size_t(fill[std::size_t(face.vertex[c])]++)] = t;
    }
  for (std::size_t v = 0; v < nv_; ++v) fan_range_[v] = {start[v], start[v + 1]};
}

/// Discrete Gaussian curvature at each vertex: angle defect over a third of the incident area
/// (0 on the boundary, where the defect measures the boundary's turning instead).
double gaussian_curvature(const FlatMesh& m, int v) {
  double angle = 0, area = 0;
  const Vec3& p = m.point(v);
  const FanRange fan = m.fan(v);
  for (int j = fan.begin; j < fan.end; ++j) {  // the faces around v, in index order
    const FanTriangle t = m.fan_triangle(j);
    const int f = t.corner / 3, c = t.corner % 3;
    const Vec3 u = m.point(t.a) - p, w = m.point(t.b) - p;
    angle += std::atan2((u % w).norm(), u | w);
    area += (u % w).norm() / 6;
    // An edge of v without a face across: v is on the boundary.
    if (m.across(3 * f + (c + 1) % 3) < 0 || m.across(3 * f + (c + 2) % 3) < 0) return 0;
  }
  return area > 0 ? (2 * std::numbers::pi - angle) / area : 0.0;
}

}  // namespace bodyfit::distance_detail
