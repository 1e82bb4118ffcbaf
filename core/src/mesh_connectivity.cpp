// The halfedge connectivity of a triangle mesh from its corners: add_face's arrays without add_face.
#include "mesh_connectivity.hpp"

#include "io_internal.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <utility>
#include <vector>

namespace bodyfit {
namespace {

// Working arrays on huge pages (io_internal.hpp): they are as big as the mesh and freshly touched.
using Array = io_detail::BulkVector<int>;

// Triangle t's side i is the "corner halfedge" k = 3t + i, from corner i to corner i + 1.
constexpr int next_in_triangle(int k) { return k % 3 == 2 ? k - 2 : k + 1; }
constexpr int previous_in_triangle(int k) { return k % 3 == 0 ? k + 2 : k - 1; }

constexpr int kGrain = 4096;  // elements per parallel task
constexpr int kMaxChunks = 8;  // of the counting sort (each counts over every vertex)

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
  // A counting sort by chunks of sides: each chunk counts its sides per vertex, and places them
  // after those of the chunks before (the same arrays as one pass in side order).
  Array first_out(std::size_t(nv) + 1, 0), out(std::size_t(nk), 0), out_to(std::size_t(nk), 0);
  {
    const int chunks = std::clamp(std::min(nk / (16 * kGrain), tbb::this_task_arena::max_concurrency()), 1, kMaxChunks);
    auto chunk_begin = [&](int c) { return int(std::int64_t(nk) * c / chunks); };
    std::vector<Array> at(std::size_t(chunks), Array(std::size_t(nv), 0));  // count, then next place
    tbb::parallel_for(0, chunks, [&](int c) {
      for (int k = chunk_begin(c); k < chunk_begin(c + 1); ++k) ++at[std::size_t(c)][std::size_t(from(k))];
    });
    for (int v = 0; v < nv; ++v) {
      int place = first_out[std::size_t(v)];
      for (auto& counts : at) place += std::exchange(counts[std::size_t(v)], place);
      first_out[std::size_t(v) + 1] = place;
    }
    tbb::parallel_for(0, chunks, [&](int c) {
      Array& next = at[std::size_t(c)];
      for (int k = chunk_begin(c); k < chunk_begin(c + 1); ++k) {
        const auto i = std::size_t(next[std::size_t(from(k))]++);
        out[i] = k;
        out_to[i] = to[std::size_t(k)];
      }
    });
  }
  // The checks below run in parallel over the vertices; any one failing fails the whole.
  std::atomic<bool> manifold = true;
  auto over_vertices = [&](auto&& visit) {
    tbb::parallel_for(tbb::blocked_range<int>(0, nv, kGrain), [&](const tbb::blocked_range<int>& r) {
      for (int v = r.begin(); v < r.end() && manifold.load(std::memory_order_relaxed); ++v)
        if (!visit(v)) manifold = false;
    });
  };

  // Twins, each pair found once, from its smaller vertex a (which alone writes both sides of it);
  // a side used twice in one direction, or a triangle repeated the other way round, is not a
  // manifold surface.
  Array twin(std::size_t(nk), -1);
  over_vertices([&](int a) {
    const int end_a = first_out[std::size_t(a) + 1];
    for (int i = first_out[std::size_t(a)]; i < end_a; ++i) {
      const int k = out[std::size_t(i)], b = out_to[std::size_t(i)];
      for (int i2 = i + 1; i2 < end_a; ++i2)
        if (out_to[std::size_t(i2)] == b) return false;
      if (b < a) continue;
      for (int j_at = first_out[std::size_t(b)]; j_at < first_out[std::size_t(b) + 1]; ++j_at) {
        if (out_to[std::size_t(j_at)] != a) continue;
        const int j = out[std::size_t(j_at)];
        if (from(previous_in_triangle(k)) == from(previous_in_triangle(j))) return false;
        twin[std::size_t(k)] = j;
        twin[std::size_t(j)] = k;
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
  // The sides that make an edge are counted by blocks, then numbered from their block's first
  // number; the others take their twin's edge, the other way round.
  Array halfedge(static_cast<std::size_t>(nk), 0);
  auto makes_edge = [&](int k) {
    const int t = twin[std::size_t(k)];
    return t < 0 || t > k;
  };
  const int blocks = (nk + kGrain - 1) / kGrain;
  Array first_edge(std::size_t(blocks) + 1, 0);
  tbb::parallel_for(0, blocks, [&](int b) {
    int count = 0;
    for (int k = b * kGrain; k < std::min(nk, (b + 1) * kGrain); ++k) count += makes_edge(k);
    first_edge[std::size_t(b) + 1] = count;
  });
  for (int b = 0; b < blocks; ++b) first_edge[std::size_t(b) + 1] += first_edge[std::size_t(b)];
  const int ne = first_edge[std::size_t(blocks)];
  tbb::parallel_for(0, blocks, [&](int b) {
    int edge = first_edge[std::size_t(b)];
    for (int k = b * kGrain; k < std::min(nk, (b + 1) * kGrain); ++k)
      if (makes_edge(k)) halfedge[std::size_t(k)] = 2 * edge++;
  });
  tbb::parallel_for(0, blocks, [&](int b) {
    for (int k = b * kGrain; k < std::min(nk, (b + 1) * kGrain); ++k)
      if (!makes_edge(k)) halfedge[std::size_t(k)] = halfedge[std::size_t(twin[std::size_t(k)])] ^ 1;
  });

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
