// The halfedge connectivity of a triangle mesh from its corners: add_face's arrays without add_face.
#include <bodyfit/mesh_connectivity.hpp>

#include "io_internal.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace bodyfit {
namespace {

// Working arrays on huge pages (io_internal.hpp): they are as big as the mesh and freshly touched.
// Sized without a value, their elements are not zeroed.
template <class T>
using Array = io_detail::BulkVector<T>;

using Corners = std::span<const std::array<std::int64_t, 3>>;

// Triangle t's side i is the "corner halfedge" k = 3t + i, from corner i to corner i + 1; the
// triangle's third corner, i + 2, is the side's opposite corner.
constexpr int next_in_triangle(int k) { return k % 3 == 2 ? k - 2 : k + 1; }
constexpr int previous_in_triangle(int k) { return k % 3 == 0 ? k + 2 : k - 1; }

constexpr int kGrain = 4096;  // elements per parallel task
constexpr int kMaxChunks = 8;  // of the counting sort (each counts over every vertex)

template <class Body>
void in_blocks(int n, Body&& body) {
  tbb::parallel_for(tbb::blocked_range<int>(0, n, kGrain), [&](const tbb::blocked_range<int>& r) { body(r.begin(), r.end()); });
}

// A side as its first vertex lists it: which side, where it goes, and the opposite corner.
struct Side {
  int k, to, opposite;
};

/// Each vertex's sides, in side order: vertex v's are sides[first[v], first[v + 1]).
struct SidesByVertex {
  Array<int> first;
  Array<Side> sides;
};

/// A counting sort by chunks of triangles: each chunk counts its sides per vertex, and places
/// them after those of the chunks before (the arrays one pass in side order would give).
SidesByVertex sides_by_vertex(Corners corners, int nv) {
  const int nt = int(corners.size()), nk = 3 * nt;
  auto corner = [&](int t, int i) { return int(corners[std::size_t(t)][std::size_t(i)]); };
  SidesByVertex s{Array<int>(std::size_t(nv) + 1, 0), Array<Side>(std::size_t(nk))};  // sides: written below
  const int chunks = std::clamp(std::min(nk / (16 * kGrain), tbb::this_task_arena::max_concurrency()), 1, kMaxChunks);
  auto chunk_begin = [&](int c) { return int(std::int64_t(nt) * c / chunks); };
  std::vector<Array<int>> at(std::size_t(chunks), Array<int>(std::size_t(nv), 0));  // count, then next place
  tbb::parallel_for(0, chunks, [&](int c) {
    int* count = at[std::size_t(c)].data();
    for (int t = chunk_begin(c); t < chunk_begin(c + 1); ++t)
      for (int i = 0; i < 3; ++i) ++count[corner(t, i)];
  });
  // The places, by blocks of vertices: each block's total, then each vertex's from its block's start.
  const int blocks = (nv + kGrain - 1) / kGrain;
  Array<int> block_first(std::size_t(blocks) + 1, 0);
  tbb::parallel_for(0, blocks, [&](int b) {
    int total = 0;
    for (int v = b * kGrain; v < std::min(nv, (b + 1) * kGrain); ++v)
      for (const auto& count : at) total += count[std::size_t(v)];
    block_first[std::size_t(b) + 1] = total;
  });
  for (int b = 0; b < blocks; ++b) block_first[std::size_t(b) + 1] += block_first[std::size_t(b)];
  tbb::parallel_for(0, blocks, [&](int b) {
    int place = block_first[std::size_t(b)];
    for (int v = b * kGrain; v < std::min(nv, (b + 1) * kGrain); ++v) {
      s.first[std::size_t(v)] = place;
      for (auto& count : at) place += std::exchange(count[std::size_t(v)], place);
    }
  });
  s.first[std::size_t(nv)] = nk;
  tbb::parallel_for(0, chunks, [&](int c) {
    int* next = at[std::size_t(c)].data();
    Side* out = s.sides.data();
    for (int t = chunk_begin(c); t < chunk_begin(c + 1); ++t) {
      const int a = corner(t, 0), b = corner(t, 1), o = corner(t, 2);
      out[next[a]++] = {3 * t, b, o};
      out[next[b]++] = {3 * t + 1, o, a};
      out[next[o]++] = {3 * t + 2, a, b};
    }
  });
  return s;
}

/// Whether a vertex's sides, each followed by the one to its opposite corner, make one fan: a
/// cycle of three or more sides, or a single chain. The sides are `side[0, n)`; `next[i]` is set to
/// the side after side i, or -1. Returns the index of the chain's last side (the side into the
/// vertex of its triangle has no twin: the vertex is on the boundary), n for a cycle, or -1 when the
/// sides are not one fan.
/// An edge used twice in one direction, a→b by triangles (a, b, c) and (a, b, d), leaves vertex b
/// two sides to c and d that the same side b→a follows, or none: not one fan at b.
int one_fan(const Side* side, int n, int* next) {
  for (int i = 0; i < n; ++i) {
    int after = 0;
    while (after < n && side[after].to != side[i].opposite) ++after;
    next[i] = after < n ? after : -1;
  }
  // A chain starts at a side that follows none (there is one: n sides, at most n - 1 followed;
  // a side two others lead to leaves the walk below short of n or looping past it).
  int ends = 0, start = 0;
  for (int i = 0; i < n; ++i) ends += next[i] < 0;
  if (ends > 1) return -1;
  if (ends == 1)
    while (std::find(next, next + n, start) != next + n) ++start;
  // Walk from the start: a chain or a cycle through all n sides is one fan.
  int reached = 1, last = start;
  for (int i = next[start]; i >= 0 && i != start; i = next[i]) {
    if (++reached > n) return -1;
    last = i;
  }
  if (reached != n) return -1;
  if (ends == 1) return last;
  return n >= 3 ? n : -1;  // two sides followed by each other: a triangle repeated the other way round
}

constexpr int kIsolated = std::numeric_limits<int>::max();

/// Around each vertex a: its sides one fan (which also refuses an edge used twice in one direction
/// or by three triangles, and a triangle repeated either way round), the side its halfedge comes
/// from, and twins. Side a→b of triangle (a, b, c) is followed by side a→c, the twin of the
/// triangle's side c→a: each pair is found once, from the smaller of a and c, which writes both
/// sides of it; a side into a that no side follows has none (-1). Every side is into one vertex,
/// so every twin is written, and nothing is read but a's own sides.
/// vertex_side[v]: v's side in its last triangle (an inner vertex), ~k for a boundary vertex whose
/// boundary halfedge is side k the other way round, or kIsolated. False when any vertex is not one
/// fan.
bool pair_twins_around_vertices(const SidesByVertex& s, Array<int>& twin, Array<int>& vertex_side) {
  const int nv = int(vertex_side.size());
  std::atomic<bool> manifold = true;
  in_blocks(nv, [&](int begin, int end) {
    std::vector<int> next;
    for (int a = begin; a < end && manifold.load(std::memory_order_relaxed); ++a) {
      const Side* around = s.sides.data() + s.first[std::size_t(a)];
      const int n = s.first[std::size_t(a) + 1] - s.first[std::size_t(a)];
      if (n == 0) {
        vertex_side[std::size_t(a)] = kIsolated;
        continue;
      }
      if (next.size() < std::size_t(n)) next.resize(std::size_t(n));
      const int last = one_fan(around, n, next.data());
      if (last < 0) {
        manifold = false;
        break;
      }
      vertex_side[std::size_t(a)] = last == n ? around[n - 1].k : ~previous_in_triangle(around[last].k);
      for (int i = 0; i < n; ++i) {
        const int into = previous_in_triangle(around[i].k);
        if (next[std::size_t(i)] < 0) {
          twin[std::size_t(into)] = -1;  // a boundary side
        } else if (a < around[i].opposite) {
          const int out = around[next[std::size_t(i)]].k;
          twin[std::size_t(into)] = out;
          twin[std::size_t(out)] = into;
        }
      }
    }
  });
  return manifold;
}

/// Edges numbered as add_face creates them: at a side's first use, in triangle then corner order,
/// the edge's first halfedge along that side. A side makes an edge when its twin, if any, comes
/// after it: counted by blocks of sides, then numbered from their block's first number, their
/// twins given the same edge the other way round.
struct Numbering {
  Array<int> halfedge;  // by side
  int edges = 0;
};
Numbering number_halfedges(const Array<int>& twin) {
  const int nk = int(twin.size());
  auto makes_edge = [&](int k) {
    const int t = twin[std::size_t(k)];
    return t < 0 || t > k;
  };
  const int blocks = (nk + kGrain - 1) / kGrain;
  Array<int> first_edge(std::size_t(blocks) + 1, 0);
  tbb::parallel_for(0, blocks, [&](int b) {
    int count = 0;
    for (int k = b * kGrain; k < std::min(nk, (b + 1) * kGrain); ++k) count += makes_edge(k);
    first_edge[std::size_t(b) + 1] = count;
  });
  for (int b = 0; b < blocks; ++b) first_edge[std::size_t(b) + 1] += first_edge[std::size_t(b)];
  Numbering numbering{Array<int>(std::size_t(nk)), first_edge[std::size_t(blocks)]};  // each side's written below
  Array<int>& halfedge = numbering.halfedge;
  tbb::parallel_for(0, blocks, [&](int b) {
    int edge = first_edge[std::size_t(b)];
    for (int k = b * kGrain; k < std::min(nk, (b + 1) * kGrain); ++k)
      if (makes_edge(k)) {
        halfedge[std::size_t(k)] = 2 * edge;
        if (const int t = twin[std::size_t(k)]; t >= 0) halfedge[std::size_t(t)] = 2 * edge + 1;
        ++edge;
      }
  });
  return numbering;
}

}  // namespace

bool build_connectivity(SurfaceMesh& mesh, Corners corners) {
  const int nv = int(mesh.n_vertices());
  const int nt = int(corners.size()), nk = 3 * nt;
  auto from = [&](int k) { return int(corners[std::size_t(k / 3)][std::size_t(k % 3)]); };

  Array<int> twin(static_cast<std::size_t>(nk)), vertex_side(static_cast<std::size_t>(nv));  // each written below
  if (!pair_twins_around_vertices(sides_by_vertex(corners, nv), twin, vertex_side)) return false;
  // (The sides are freed: what follows reuses their memory rather than fresh pages.)
  const Numbering numbering = number_halfedges(twin);
  auto halfedge = [&](int k) { return HalfedgeHandle(numbering.halfedge[std::size_t(k)]); };
  auto opposite = [](HalfedgeHandle h) { return HalfedgeHandle(h.idx() ^ 1); };
  auto vertex_halfedge = [&](int v) {
    const int s = vertex_side[std::size_t(v)];
    return s >= 0 ? halfedge(s) : opposite(halfedge(~s));
  };

  mesh.resize(std::size_t(nv), std::size_t(numbering.edges), corners.size());
  // Every write below is to an element of its own: a halfedge's `next` sets its next one's `prev`,
  // and a vertex has at most one boundary halfedge leaving it (one fan).
  in_blocks(nt, [&](int begin, int end) {
    for (int t = begin; t < end; ++t) {
      const HalfedgeHandle h[3] = {halfedge(3 * t), halfedge(3 * t + 1), halfedge(3 * t + 2)};
      for (int i = 0; i < 3; ++i) {
        const int k = 3 * t + i;
        mesh.set_vertex_handle(h[i], VertexHandle(from(next_in_triangle(k))));
        mesh.set_face_handle(h[i], FaceHandle(t));
        mesh.set_next_halfedge_handle(h[i], h[(i + 1) % 3]);
        if (twin[std::size_t(k)] < 0) {
          // The boundary halfedge the other way round, and the boundary halfedge leaving its end.
          const HalfedgeHandle b = opposite(h[i]);
          mesh.set_vertex_handle(b, VertexHandle(from(k)));
          mesh.set_face_handle(b, FaceHandle());
          mesh.set_next_halfedge_handle(b, vertex_halfedge(from(k)));
        }
      }
      mesh.set_halfedge_handle(FaceHandle(t), h[2]);
    }
  });
  in_blocks(nv, [&](int begin, int end) {
    for (int v = begin; v < end; ++v)
      if (vertex_side[std::size_t(v)] != kIsolated) mesh.set_halfedge_handle(VertexHandle(v), vertex_halfedge(v));
  });
  return true;
}

}  // namespace bodyfit
