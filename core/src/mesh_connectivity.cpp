// The halfedge connectivity of a triangle mesh from its corners: add_face's arrays without add_face.
#include "mesh_connectivity.hpp"

#include "io_internal.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cstddef>

namespace bodyfit {
namespace {

// Working arrays on huge pages (io_internal.hpp): they are as big as the mesh and freshly touched.
using Array = io_detail::BulkVector<int>;

// Triangle t's side i is the "corner halfedge" k = 3t + i, from corner i to corner i + 1.
constexpr int next_in_triangle(int k) { return k % 3 == 2 ? k - 2 : k + 1; }
constexpr int previous_in_triangle(int k) { return k % 3 == 0 ? k + 2 : k - 1; }

constexpr int kGrain = 4096;  // elements per parallel task

}  // namespace

bool build_connectivity(SurfaceMesh& mesh, std::span<const std::array<std::int64_t, 3>> corners) {
  const int nv = int(mesh.n_vertices());
  const int nk = 3 * int(corners.size());
  auto from = [&](int k) { return int(corners[std::size_t(k / 3)][std::size_t(k % 3)]); };
  Array to(std::size_t(nk), 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, nk, kGrain), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k < r.end(); ++k) to[std::size_t(k)] = from(next_in_triangle(k));
  });

  // Each vertex's outgoing corner halfedges in triangle order, and beside them where each one goes
  // (the twin search below then reads one vertex's sides from two short runs of memory).
  Array first_out(std::size_t(nv) + 1, 0), out(std::size_t(nk), 0), out_to(std::size_t(nk), 0);
  for (int k = 0; k < nk; ++k) ++first_out[std::size_t(from(k)) + 1];
  for (int v = 0; v < nv; ++v) first_out[std::size_t(v) + 1] += first_out[std::size_t(v)];
  {
    Array filled(first_out.begin(), first_out.end() - 1);
    for (int k = 0; k < nk; ++k) {
      const auto i = std::size_t(filled[std::size_t(from(k))]++);
      out[i] = k;
      out_to[i] = to[std::size_t(k)];
    }
  }
  // The checks below run in parallel over the vertices; any one failing fails the whole.
  std::atomic<bool> manifold = true;
  auto over_vertices = [&](auto&& visit) {
    tbb::parallel_for(tbb::blocked_range<int>(0, nv, kGrain), [&](const tbb::blocked_range<int>& r) {
      for (int v = r.begin(); v < r.end() && manifold.load(std::memory_order_relaxed); ++v)
        if (!visit(v)) manifold = false;
    });
  };

  // Twins; a side used twice in one direction, or a triangle repeated the other way round, is not a
  // manifold surface.
  Array twin(std::size_t(nk), -1);
  over_vertices([&](int a) {
    const int end_a = first_out[std::size_t(a) + 1];
    for (int i = first_out[std::size_t(a)]; i < end_a; ++i) {
      const int k = out[std::size_t(i)], b = out_to[std::size_t(i)];
      for (int i2 = i + 1; i2 < end_a; ++i2)
        if (out_to[std::size_t(i2)] == b) return false;
      for (int j_at = first_out[std::size_t(b)]; j_at < first_out[std::size_t(b) + 1]; ++j_at) {
        if (out_to[std::size_t(j_at)] != a) continue;
        const int j = out[std::size_t(j_at)];
        if (from(previous_in_triangle(k)) == from(previous_in_triangle(j))) return false;
        twin[std::size_t(k)] = j;
      }
    }
    return true;
  });
  if (!manifold) return false;

  // Each vertex's triangles one fan: turning around it from one of its sides reaches all of them.
  over_vertices([&](int v) {
    const int degree = first_out[std::size_t(v) + 1] - first_out[std::size_t(v)];
    if (degree == 0) return true;
    const int start = out[std::size_t(first_out[std::size_t(v)])];
    int reached = 1;
    bool open = false;
    for (int k = start;;) {
      const int t = twin[std::size_t(k)];
      if (t < 0) {
        open = true;
        break;
      }
      k = next_in_triangle(t);
      if (k == start) break;
      if (++reached > degree) return false;
    }
    if (open)
      for (int k = start;;) {
        const int t = twin[std::size_t(previous_in_triangle(k))];
        if (t < 0) break;
        k = t;
        if (++reached > degree) return false;
      }
    return reached == degree;
  });
  if (!manifold) return false;

  // Edges numbered as add_face creates them: at a side's first use, in triangle then corner order,
  // the edge's first halfedge along that side.
  Array halfedge(static_cast<std::size_t>(nk), 0);
  int ne = 0;
  for (int k = 0; k < nk; ++k) {
    const int t = twin[std::size_t(k)];
    halfedge[std::size_t(k)] = (t < 0 || t > k) ? 2 * ne++ : halfedge[std::size_t(t)] ^ 1;
  }

  mesh.resize(std::size_t(nv), std::size_t(ne), corners.size());
  // Every write below is to an element of its own (a vertex has at most one boundary side leaving
  // it, the fan check made sure).
  Array boundary_out(std::size_t(nv), -1);
  tbb::parallel_for(tbb::blocked_range<int>(0, nk, kGrain), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k < r.end(); ++k) {
      const HalfedgeHandle h(halfedge[std::size_t(k)]);
      mesh.set_vertex_handle(h, VertexHandle(to[std::size_t(k)]));
      mesh.set_face_handle(h, FaceHandle(k / 3));
      mesh.set_next_halfedge_handle(h, HalfedgeHandle(halfedge[std::size_t(next_in_triangle(k))]));
      if (k % 3 == 2) mesh.set_halfedge_handle(FaceHandle(k / 3), h);
      if (twin[std::size_t(k)] < 0) {
        const HalfedgeHandle b(halfedge[std::size_t(k)] ^ 1);
        mesh.set_vertex_handle(b, VertexHandle(from(k)));
        mesh.set_face_handle(b, FaceHandle());
        boundary_out[std::size_t(to[std::size_t(k)])] = b.idx();
      }
    }
  });
  // A boundary halfedge ends where the next one leaves (one per vertex: each vertex is one fan).
  tbb::parallel_for(tbb::blocked_range<int>(0, nk, kGrain), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k < r.end(); ++k)
      if (twin[std::size_t(k)] < 0)
        mesh.set_next_halfedge_handle(HalfedgeHandle(halfedge[std::size_t(k)] ^ 1),
                                      HalfedgeHandle(boundary_out[std::size_t(from(k))]));
  });
  tbb::parallel_for(tbb::blocked_range<int>(0, nv, kGrain), [&](const tbb::blocked_range<int>& r) {
    for (int v = r.begin(); v < r.end(); ++v) {
      const int last = first_out[std::size_t(v) + 1];
      if (boundary_out[std::size_t(v)] >= 0)
        mesh.set_halfedge_handle(VertexHandle(v), HalfedgeHandle(boundary_out[std::size_t(v)]));
      else if (last > first_out[std::size_t(v)])
        mesh.set_halfedge_handle(VertexHandle(v), HalfedgeHandle(halfedge[std::size_t(out[std::size_t(last - 1)])]));
    }
  });
  return true;
}

}  // namespace bodyfit
