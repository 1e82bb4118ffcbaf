// The surface walker's per-face records (surface_walker.hpp), built once per advection call.
#include "surface_walker.hpp"

#include <bodyfit/geometry.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace bodyfit::walker {

Surface build_surface(const SurfaceMesh& mesh, std::span<const int> subset) {
  Surface s;
  const bool partial = !subset.empty();
  const int nf = partial ? int(subset.size()) : int(mesh.n_faces());  // faces built
  const int nv = int(mesh.n_vertices());
  auto face_at = [&](int k) { return partial ? subset[std::size_t(k)] : k; };
  s.points.resize(nv);
  for (int v = 0; v < nv; ++v) s.points[v] = mesh.point(VertexHandle(v));
  // Connectivity as flat arrays, read once from the halfedges: corner i of a face is the target of
  // its halfedge h_i, and the edge opposite corner i is that of h_{i+2} (mesh face indices).
  std::vector<std::array<int, 3>> corners(nf), across(nf);
  tbb::parallel_for(tbb::blocked_range<int>(0, nf, 4096), [&](const tbb::blocked_range<int>& range) {
    for (int k = range.begin(); k != range.end(); ++k) {
      HalfedgeHandle h = mesh.halfedge_handle(FaceHandle(face_at(k)));
      for (int i = 0; i < 3; ++i) {
        corners[k][i] = mesh.to_vertex_handle(h).idx();
        const HalfedgeHandle o = mesh.opposite_halfedge_handle(h);
        across[k][(i + 1) % 3] = mesh.is_boundary(o) ? -1 : mesh.face_handle(o).idx();
        h = mesh.next_halfedge_handle(h);
      }
    }
  });
  // Vertices in Z-order, faces in the order of their first corner in it (a counting sort): a walk's
  // next face is then usually close in memory, and so are the faces of neighbouring vertices. A
  // partial surface orders its vertices as the whole one would (codes in the whole mesh's box), so
  // its faces are stored alike and a trace starts in the same face of its vertex: the same values.
  std::vector<int>& rank = s.vertex_rank;
  if (partial) {
    rank.assign(nv, nv);  // the vertices not built come last
    std::vector<char> used(nv, 0);
    for (const auto& c : corners) used[c[0]] = used[c[1]] = used[c[2]] = 1;
    std::vector<int> built;
    std::vector<Vec3> points;
    for (int v = 0; v < nv; ++v)
      if (used[v]) built.push_back(v), points.push_back(s.points[v]);
    for (int k : z_order(points, bounding_box(s.points))) s.vertex_order.push_back(built[std::size_t(k)]);
    for (int k = 0; k < int(s.vertex_order.size()); ++k) rank[s.vertex_order[std::size_t(k)]] = k;
  } else {
    rank.resize(nv);
    s.vertex_order = z_order(s.points);
    for (int k = 0; k < nv; ++k) rank[s.vertex_order[k]] = k;
  }
  std::vector<int> start(std::size_t(nv) + 1, 0);
  for (int k = 0; k < nf; ++k) ++start[1 + std::min({rank[corners[k][0]], rank[corners[k][1]], rank[corners[k][2]]})];
  for (int k = 0; k < nv; ++k) start[k + 1] += start[k];
  // Mesh face → its slot (−1: not built), and → its row in corners.
  std::vector<int> slot_of(mesh.n_faces(), -1), row_of(partial ? mesh.n_faces() : 0, -1), face_order(nf);
  for (int k = 0; k < nf; ++k) {
    const int key = std::min({rank[corners[k][0]], rank[corners[k][1]], rank[corners[k][2]]});
    slot_of[face_at(k)] = start[key]++;
    face_order[slot_of[face_at(k)]] = k;
    if (partial) row_of[face_at(k)] = k;
  }
  auto row = [&](int face) { return partial ? row_of[face] : face; };
  s.faces.resize(nf);
  s.motion.resize(nf);
  s.corners.resize(nf);
  s.face_length.resize(nf);
  tbb::parallel_for(tbb::blocked_range<int>(0, nf, 4096), [&](const tbb::blocked_range<int>& range) {
    for (int slot = range.begin(); slot != range.end(); ++slot) {
      const int fi = face_order[slot];
      Face& f = s.faces[slot];
      FaceMotion& m = s.motion[slot];
      const std::array<int, 3>& corner = s.corners[slot] = corners[fi];
      const Vec3 p[3] = {s.points[corner[0]], s.points[corner[1]], s.points[corner[2]]};
      const auto grad = p1_basis_gradients(p[0], p[1], p[2]);
      m.epoch = 0;
      double mean = 0;
      for (int k = 0; k < 3; ++k) mean += (p[(k + 2) % 3] - p[(k + 1) % 3]).norm() / 3.0;
      s.face_length[slot] = float(mean);
      for (int k = 0; k < 3; ++k)
        m.edge2[k] = mean > 0 ? float((p[(k + 2) % 3] - p[(k + 1) % 3]).sqrnorm() / (mean * mean)) : 0.0f;
      for (int i = 0; i < 3; ++i) {
        const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
        f.neighbour[i] = -1;
        f.across[i] = 0;
        f.unfold_far[i] = 0;
        f.unfold_next[i] = 0;
        const int g_face = across[fi][i];
        if (g_face < 0) continue;
        if (slot_of[g_face] < 0) {  // a face of the mesh that is not built
          f.neighbour[i] = kNotBuilt;
          continue;
        }
        const int g = row(g_face);
        // Slots in g: the corner that is not on the shared edge, and this face's corner i + 1.
        int slot_far = 0, slot_next = 0;
        for (int j = 0; j < 3; ++j) {
          const int vj = corners[g][j];
          if (vj != corner[i1] && vj != corner[i2]) slot_far = j;
          if (vj == corner[i1]) slot_next = j;
        }
        // Unfold the far corner q into this face's plane: keep its offset along the edge and its
        // distance from the edge line, turned to point out of this face (−∇λ_i).
        const Vec3 q = s.points[corners[g][slot_far]];
        Vec3 e = p[i2] - p[i1];
        const double len = e.norm();
        const double gi = grad[i].norm();
        if (len == 0 || gi == 0) continue;  // degenerate: leave the edge closed
        e /= len;
        const Vec3 rel = q - p[i1];
        const double along = OpenMesh::dot(rel, e);
        const double away = (rel - along * e).norm();
        const double alpha = -away * gi;  // λ_i at the unfolded corner
        if (!(alpha < 0)) continue;       // the neighbour is degenerate: leave the edge closed
        const Vec3 unfolded_rel = along * e - (away / gi) * grad[i];
        f.neighbour[i] = slot_of[g_face];
        f.across[i] = static_cast<unsigned char>(slot_far | (slot_next << 2));
        f.unfold_far[i] = 1.0 / alpha;
        f.unfold_next[i] = 1.0 + OpenMesh::dot(grad[i1], unfolded_rel);
      }
    }
  });
  s.shortest_face = nf ? double(*std::min_element(s.face_length.begin(), s.face_length.end())) : 0.0;
  // One incident face per vertex, chosen deterministically (the first in storage order).
  s.vertex_face.assign(nv, -1);
  s.vertex_slot.assign(nv, 0);
  for (int slot = 0; slot < nf; ++slot)
    for (int i = 0; i < 3; ++i) {
      const int v = s.corners[slot][i];
      if (s.vertex_face[v] < 0) {
        s.vertex_face[v] = slot;
        s.vertex_slot[v] = static_cast<signed char>(i);
      }
    }
  return s;
}


void build_fans(Surface& s) {
  const std::size_t nv = s.points.size();
  s.fan_start.assign(nv + 1, 0);
  for (const auto& c : s.corners)
    for (int v : c) ++s.fan_start[v + 1];
  for (std::size_t v = 0; v < nv; ++v) s.fan_start[v + 1] += s.fan_start[v];
  s.fan.resize(s.fan_start[nv]);
  std::vector<int> fill(s.fan_start.begin(), s.fan_start.end() - 1);
  for (int slot = 0; slot < int(s.corners.size()); ++slot)
    for (int v : s.corners[slot]) s.fan[fill[v]++] = slot;
}

Location vertex_location(const Surface& s, int v) {
  Location at;
  at.face = s.vertex_face[v];
  at.b[0] = at.b[1] = at.b[2] = 0.0;
  at.b[s.vertex_slot[v]] = 1.0;
  return at;
}

Vec3 position(const Surface& s, const Location& at) {
  const std::array<int, 3>& c = s.corners[at.face];
  return at.b[0] * s.points[c[0]] + at.b[1] * s.points[c[1]] + at.b[2] * s.points[c[2]];
}

WalkEnd walk_by(const Surface& s, Location& at, const Vec3& displacement) {
  const std::array<int, 3>& c = s.corners[at.face];
  const auto grad = p1_basis_gradients(s.points[c[0]], s.points[c[1]], s.points[c[2]]);
  Delta d;
  d.d[0] = OpenMesh::dot(grad[0], displacement);
  d.d[1] = OpenMesh::dot(grad[1], displacement);
  d.d[2] = -(d.d[0] + d.d[1]);
  return walk(s, at, d, nullptr);
}

}  // namespace bodyfit::walker
