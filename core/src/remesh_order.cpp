// The arrays of a mesh after a remesh: the spatial order (reorder_spatially, a compaction that also
// renumbers) and the compaction alone (collect_garbage), which replace OpenMesh's garbage collection
// at the end of remesh().
//
// Why: a remesh appends its new vertices, edges and faces at the end of the arrays and garbage
// collection fills the holes with the last elements, so after a few steps neighbours lie far apart
// in memory and every sweep that follows (the distance, the advection, the next remesh) misses the
// cache. Vertices are sorted along a Z-order curve of their positions, edges and faces by their
// smallest new vertex index, so that a vertex, its edges and its faces are close in memory.
#include <bodyfit/geometry.hpp>
#include <bodyfit/remesh.hpp>

#include "blocks.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace bodyfit {
namespace {

// The elements (of `count`) ordered by a key in [0, keys) given by key(i), ties by index, skipping
// those with a negative key: a stable counting sort, linear.
template <class Key>
std::vector<int> order_by_key(int count, int keys, Key&& key, std::vector<int>& map) {
  std::vector<int> k(static_cast<std::size_t>(count), -1);
  tbb::parallel_for(0, count, [&](int i) { k[std::size_t(i)] = key(i); });
  std::vector<int> start(static_cast<std::size_t>(keys) + 1, 0);
  for (int i = 0; i < count; ++i)
    if (k[std::size_t(i)] >= 0) ++start[std::size_t(k[std::size_t(i)]) + 1];
  for (int j = 0; j < keys; ++j) start[std::size_t(j) + 1] += start[std::size_t(j)];
  std::vector<int> order(static_cast<std::size_t>(start[static_cast<std::size_t>(keys)]));
  map.assign(std::size_t(count), -1);
  for (int i = 0; i < count; ++i)
    if (k[std::size_t(i)] >= 0) {
      const int at = start[std::size_t(k[std::size_t(i)])]++;
      order[std::size_t(at)] = i;
      map[std::size_t(i)] = at;
    }
  return order;
}

// Each element (of map.size(), times stride) to its new position map[i] (dropped when negative):
// the old array is read in order, the new one written where the elements go.
template <class T>
bool scatter_as(OpenMesh::BaseProperty& property, const std::vector<int>& map, std::size_t live, int stride) {
  auto* typed = dynamic_cast<OpenMesh::PropertyT<T>*>(&property);
  if (typed == nullptr) return false;
  auto& data = typed->data_vector();
  std::vector<T> out(live * std::size_t(stride));
  tbb::parallel_for(0, int(map.size()), [&](int i) {
    if (const int at = map[std::size_t(i)]; at >= 0)
      for (int s = 0; s < stride; ++s)
        out[std::size_t(at) * std::size_t(stride) + std::size_t(s)] = data[std::size_t(i) * std::size_t(stride) + std::size_t(s)];
  });
  data.swap(out);
  return true;
}

// Put element order[i] (times stride: halfedges follow their edge) at position i, for a property of
// any type: the common types by a parallel scatter (OpenMesh's per-element traits data, empty
// structs here, among them), any other by swaps along the permutation's cycles (the deleted
// elements go after the live ones and are cut off by the resize that follows).
void permute(OpenMesh::BaseProperty& property, const std::vector<int>& order, const std::vector<int>& map, int stride) {
  const std::size_t live = order.size();
  if (scatter_as<Vec3>(property, map, live, stride) || scatter_as<double>(property, map, live, stride) ||
      scatter_as<int>(property, map, live, stride) || scatter_as<char>(property, map, live, stride) ||
      scatter_as<OpenMesh::Attributes::StatusInfo>(property, map, live, stride) ||
      scatter_as<SurfaceMesh::VertexData>(property, map, live, stride) ||
      scatter_as<SurfaceMesh::EdgeData>(property, map, live, stride) ||
      scatter_as<SurfaceMesh::HalfedgeData>(property, map, live, stride) ||
      scatter_as<SurfaceMesh::FaceData>(property, map, live, stride))
    return;
  const int n = int(map.size());
  std::vector<int> full(order);
  for (int i = 0; i < n; ++i)
    if (map[std::size_t(i)] < 0) full.push_back(i);
  std::vector<char> visited(full.size(), 0);
  for (int i = 0; i < n; ++i) {
    if (visited[std::size_t(i)]) continue;
    int j = i;
    while (true) {
      visited[std::size_t(j)] = 1;
      const int k = full[std::size_t(j)];
      if (k == i) break;
      for (int s = 0; s < stride; ++s) property.swap(std::size_t(j) * std::size_t(stride) + std::size_t(s), std::size_t(k) * std::size_t(stride) + std::size_t(s));
      j = k;
    }
  }
}

template <class Range>
void swap_properties(Range begin, Range end, std::size_t i0, std::size_t i1) {
  for (auto it = begin; it != end; ++it)
    if (*it) (*it)->swap(i0, i1);
}

}  // namespace

double spatial_disorder(const SurfaceMesh& mesh) {
  // Neighbours far apart in memory: edges whose ends' indices differ by more than a few rows of a
  // well-ordered surface mesh (√n vertices per row), whatever that order is (a generator's rows,
  // a height grid's, the Z-order); elements appended by cuts and splits, and those moved into the
  // holes of collapses, have such edges.
  const int ne = int(mesh.n_edges());
  std::size_t live_v = 0;
  for (auto v : mesh.all_vertices()) live_v += !mesh.status(v).deleted();
  const double window = 16 * std::sqrt(double(live_v));
  std::vector<std::size_t> far(std::size_t((ne + 8191) / 8192), 0), live(far.size(), 0);
  tbb::parallel_for(0, int(far.size()), [&](int b) {
    for (int i = b * 8192; i < std::min(ne, (b + 1) * 8192); ++i) {
      EdgeHandle e(i);
      if (mesh.status(e).deleted()) continue;
      auto h = mesh.halfedge_handle(e, 0);
      ++live[std::size_t(b)];
      far[std::size_t(b)] += std::abs(mesh.from_vertex_handle(h).idx() - mesh.to_vertex_handle(h).idx()) > window;
    }
  });
  std::size_t total_far = 0, total_live = 0;
  for (std::size_t b = 0; b < far.size(); ++b) {
    total_far += far[b];
    total_live += live[b];
  }
  // A hole will be filled by the last vertex: about six far edges once compacted.
  const std::size_t holes = mesh.n_vertices() - live_v;
  return total_live > 0 ? double(total_far + 6 * holes) / double(total_live) : 0.0;
}

std::vector<int> spatial_vertex_order(const SurfaceMesh& mesh) {
  // The Z-order of the live vertices' positions in their bounding box (geometry.hpp), ties by index.
  std::vector<int> live;
  std::vector<Vec3> points;
  live.reserve(mesh.n_vertices());
  points.reserve(mesh.n_vertices());
  for (auto v : mesh.vertices()) {
    live.push_back(v.idx());
    points.push_back(mesh.point(v));
  }
  std::vector<int> order = z_order(points);
  for (int& i : order) i = live[std::size_t(i)];
  return order;
}

double spatial_disorder_after_reorder(const SurfaceMesh& mesh) {
  return spatial_disorder_after_reorder(mesh, spatial_vertex_order(mesh));
}

double spatial_disorder_after_reorder(const SurfaceMesh& mesh, const std::vector<int>& order) {
  std::vector<int> rank(mesh.n_vertices(), -1);
  for (std::size_t i = 0; i < order.size(); ++i) rank[std::size_t(order[i])] = int(i);
  const double window = 16 * std::sqrt(double(order.size()));
  struct Count {
    std::size_t far = 0, live = 0;
  };
  const Count count = reduce(
      int(mesh.n_edges()), Count{},
      [&](int i, Count& c) {
        const EdgeHandle e(i);
        if (mesh.status(e).deleted()) return;
        const auto h = mesh.halfedge_handle(e, 0);
        ++c.live;
        c.far += std::abs(rank[std::size_t(mesh.from_vertex_handle(h).idx())] -
                          rank[std::size_t(mesh.to_vertex_handle(h).idx())]) > window;
      },
      [](Count& total, const Count& c) {
        total.far += c.far;
        total.live += c.live;
      });
  return count.live > 0 ? double(count.far) / double(count.live) : 0.0;
}

bool has_deleted_elements(const SurfaceMesh& mesh) {
  auto any = [](int n, auto&& deleted) {
    return reduce(n, 0, [&](int i, int& found) { found = found || deleted(i); },
                  [](int& total, int part) { total = total || part; }) != 0;
  };
  return any(int(mesh.n_faces()), [&](int i) { return mesh.status(FaceHandle(i)).deleted(); }) ||
         any(int(mesh.n_edges()), [&](int i) { return mesh.status(EdgeHandle(i)).deleted(); }) ||
         any(int(mesh.n_vertices()), [&](int i) { return mesh.status(VertexHandle(i)).deleted(); });
}

void collect_garbage(SurfaceMesh& mesh) {
  // OpenMesh's scheme (the first hole takes the last live element, until they meet), so the arrays
  // are the ones garbage_collection() gives; but where it remaps every handle of the mesh, this
  // updates only those that point to a moved element: linear in the holes, not in the mesh.
  auto first_hole_last_live = [](int& i0, int& i1, auto deleted) {
    while (!deleted(i0) && i0 < i1) ++i0;
    while (deleted(i1) && i0 < i1) --i1;
    return i0 < i1;
  };
  int live_v = int(mesh.n_vertices()), live_e = int(mesh.n_edges()), live_f = int(mesh.n_faces());

  // Vertices: the halfedges that end at the moved one.
  {
    auto deleted = [&](int i) { return mesh.status(VertexHandle(i)).deleted(); };
    int i0 = 0, i1 = live_v - 1;
    while (i1 >= 0 && first_hole_last_live(i0, i1, deleted)) {
      VertexHandle from(i1), to(i0);
      swap_properties(mesh.vprops_begin(), mesh.vprops_end(), std::size_t(i0), std::size_t(i1));
      const auto h0 = mesh.halfedge_handle(from);
      mesh.set_halfedge_handle(to, h0);
      if (h0.is_valid()) {
        auto h = h0;
        do {
          mesh.set_vertex_handle(mesh.opposite_halfedge_handle(h), to);
          h = mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(h));
        } while (h != h0);
      }
    }
    live_v = i1 >= 0 && !deleted(i0) ? i0 + 1 : i0;
  }
  // Edges: both halfedges move; their neighbours' next/prev, their face's and their vertex's
  // halfedge follow.
  {
    auto deleted = [&](int i) { return mesh.status(EdgeHandle(i)).deleted(); };
    int i0 = 0, i1 = live_e - 1;
    while (i1 >= 0 && first_hole_last_live(i0, i1, deleted)) {
      auto moved = [&](HalfedgeHandle h) { return h.idx() >> 1 == i1 ? HalfedgeHandle(2 * i0 + (h.idx() & 1)) : h; };
      struct Half {
        VertexHandle to;
        HalfedgeHandle next, prev;
        FaceHandle face;
        bool face_start, vertex_start;
      } half[2];
      for (int k = 0; k < 2; ++k) {
        HalfedgeHandle h(2 * i1 + k);
        const auto f = mesh.face_handle(h);
        const auto v = mesh.to_vertex_handle(mesh.opposite_halfedge_handle(h));  // from-vertex
        half[k] = {mesh.to_vertex_handle(h), moved(mesh.next_halfedge_handle(h)), moved(mesh.prev_halfedge_handle(h)), f,
                   f.is_valid() && mesh.halfedge_handle(f) == h, mesh.halfedge_handle(v) == h};
      }
      swap_properties(mesh.eprops_begin(), mesh.eprops_end(), std::size_t(i0), std::size_t(i1));
      for (int k = 0; k < 2; ++k)
        swap_properties(mesh.hprops_begin(), mesh.hprops_end(), std::size_t(2 * i0 + k), std::size_t(2 * i1 + k));
      for (int k = 0; k < 2; ++k) {
        HalfedgeHandle h(2 * i0 + k);
        mesh.set_vertex_handle(h, half[k].to);
        mesh.set_face_handle(h, half[k].face);
        mesh.set_next_halfedge_handle(h, half[k].next);  // also the next's prev
        mesh.set_next_halfedge_handle(half[k].prev, h);  // also h's prev
        if (half[k].face_start) mesh.set_halfedge_handle(half[k].face, h);
        if (half[k].vertex_start) mesh.set_halfedge_handle(half[1 - k].to, h);
      }
    }
    live_e = i1 >= 0 && !deleted(i0) ? i0 + 1 : i0;
  }
  // Faces: their three halfedges.
  {
    auto deleted = [&](int i) { return mesh.status(FaceHandle(i)).deleted(); };
    int i0 = 0, i1 = live_f - 1;
    while (i1 >= 0 && first_hole_last_live(i0, i1, deleted)) {
      FaceHandle from(i1), to(i0);
      swap_properties(mesh.fprops_begin(), mesh.fprops_end(), std::size_t(i0), std::size_t(i1));
      const auto h0 = mesh.halfedge_handle(from);
      mesh.set_halfedge_handle(to, h0);
      auto h = h0;
      do {
        mesh.set_face_handle(h, to);
        h = mesh.next_halfedge_handle(h);
      } while (h != h0);
    }
    live_f = i1 >= 0 && !deleted(i0) ? i0 + 1 : i0;
  }
  mesh.resize(std::size_t(live_v), std::size_t(live_e), std::size_t(live_f));
}

void reorder_spatially(SurfaceMesh& mesh) { reorder_spatially(mesh, spatial_vertex_order(mesh)); }

void reorder_spatially(SurfaceMesh& mesh, const std::vector<int>& vorder) {
  const int nv = int(mesh.n_vertices()), ne = int(mesh.n_edges()), nf = int(mesh.n_faces());
  std::vector<int> vmap(static_cast<std::size_t>(nv), -1);
  for (std::size_t i = 0; i < vorder.size(); ++i) vmap[std::size_t(vorder[i])] = int(i);
  const int live_v = int(vorder.size());

  // Edges and faces: by their smallest new vertex index.
  std::vector<int> emap, fmap;
  const auto eorder = order_by_key(ne, live_v, [&](int i) {
    EdgeHandle e(i);
    if (mesh.status(e).deleted()) return -1;
    auto h = mesh.halfedge_handle(e, 0);
    return std::min(vmap[std::size_t(mesh.from_vertex_handle(h).idx())], vmap[std::size_t(mesh.to_vertex_handle(h).idx())]);
  }, emap);
  const auto forder = order_by_key(nf, live_v, [&](int i) {
    FaceHandle f(i);
    if (mesh.status(f).deleted()) return -1;
    const auto h = mesh.halfedge_handle(f), h1 = mesh.next_halfedge_handle(h);
    return std::min({vmap[std::size_t(mesh.to_vertex_handle(h).idx())], vmap[std::size_t(mesh.to_vertex_handle(h1).idx())],
                     vmap[std::size_t(mesh.to_vertex_handle(mesh.next_halfedge_handle(h1)).idx())]});
  }, fmap);
  const int live_e = int(eorder.size()), live_f = int(forder.size());
  auto hmap = [&](HalfedgeHandle h) { return h.is_valid() ? 2 * emap[std::size_t(h.idx() >> 1)] + (h.idx() & 1) : -1; };

  // The connectivity in the new numbering, read before anything moves.
  std::vector<int> v_half(static_cast<std::size_t>(live_v)), f_half(static_cast<std::size_t>(live_f));
  const std::size_t halfedges = 2 * static_cast<std::size_t>(live_e);
  std::vector<int> h_to(halfedges), h_next(halfedges), h_face(halfedges);
  // Each old element writes its new slot: the mesh's arrays are read in order, and only the maps
  // (a few MB) are read at random.
  tbb::parallel_for(0, nv, [&](int v) {
    if (const int at = vmap[std::size_t(v)]; at >= 0) v_half[std::size_t(at)] = hmap(mesh.halfedge_handle(VertexHandle(v)));
  });
  tbb::parallel_for(0, nf, [&](int f) {
    if (const int at = fmap[std::size_t(f)]; at >= 0) f_half[std::size_t(at)] = hmap(mesh.halfedge_handle(FaceHandle(f)));
  });
  tbb::parallel_for(0, ne, [&](int e) {
    const int to_edge = emap[std::size_t(e)];
    if (to_edge < 0) return;
    for (int k = 0; k < 2; ++k) {
      HalfedgeHandle h(2 * e + k);
      const std::size_t at = 2 * std::size_t(to_edge) + std::size_t(k);
      h_to[at] = vmap[std::size_t(mesh.to_vertex_handle(h).idx())];
      h_next[at] = hmap(mesh.next_halfedge_handle(h));
      auto f = mesh.face_handle(h);
      h_face[at] = f.is_valid() ? fmap[std::size_t(f.idx())] : -1;
    }
  });

  // Every property (points, status, the named tags, any other) follows its element.
  for (auto it = mesh.vprops_begin(); it != mesh.vprops_end(); ++it)
    if (*it) permute(**it, vorder, vmap, 1);
  for (auto it = mesh.eprops_begin(); it != mesh.eprops_end(); ++it)
    if (*it) permute(**it, eorder, emap, 1);
  for (auto it = mesh.hprops_begin(); it != mesh.hprops_end(); ++it)
    if (*it) permute(**it, eorder, emap, 2);
  for (auto it = mesh.fprops_begin(); it != mesh.fprops_end(); ++it)
    if (*it) permute(**it, forder, fmap, 1);
  mesh.resize(std::size_t(live_v), std::size_t(live_e), std::size_t(live_f));

  tbb::parallel_for(0, live_v, [&](int i) { mesh.set_halfedge_handle(VertexHandle(i), HalfedgeHandle(v_half[std::size_t(i)])); });
  tbb::parallel_for(0, live_f, [&](int i) { mesh.set_halfedge_handle(FaceHandle(i), HalfedgeHandle(f_half[std::size_t(i)])); });
  // Each halfedge's target, face and next; set_next_halfedge_handle also sets the next's prev, and
  // since next is a permutation every field is written exactly once (no two writes to one field).
  tbb::parallel_for(0, 2 * live_e, [&](int i) {
    HalfedgeHandle h(i);
    mesh.set_vertex_handle(h, VertexHandle(h_to[std::size_t(i)]));
    mesh.set_face_handle(h, FaceHandle(h_face[std::size_t(i)]));
    mesh.set_next_halfedge_handle(h, HalfedgeHandle(h_next[std::size_t(i)]));
  });
}

}  // namespace bodyfit
