#include <bodyfit/projection.hpp>

#include <bodyfit/geometry.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <type_traits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

namespace bodyfit {

namespace detail {

/// Bounding-volume hierarchy over boxes, shared by the surface and the polyline projections.
struct BoxTree {
  struct Node {
    Vec3 lo, hi;
    int left = -1, right = -1;  ///< children; -1 for a leaf
    int begin = 0, end = 0;     ///< leaf range in `order`
  };
  std::vector<Node> nodes;
  std::vector<int> order;  ///< primitive indices, leaves hold contiguous ranges
  /// Over primitives 0..n−1, `box(i, lo, hi)` giving primitive i's bounding box.
  template <class Box>
  void build(int n, const Box& box);
};

namespace {
constexpr int kLeafSize = 4;

/// Nodes of the subtree over n primitives (median splits down to leaves of kLeafSize): fixed by n,
/// so every subtree's node ids are known before it is built and subtrees can be built in parallel.
int subtree_nodes(int n) { return n <= kLeafSize ? 1 : 1 + subtree_nodes(n / 2) + subtree_nodes(n - n / 2); }

/// Median splits along the longest axis of the box centres: tight boxes, so queries visit few
/// nodes (median splits of the Z-order built 3× faster but made the remesher's queries 3× slower).
/// The primitives' centres travel with their indices, so the splits read and swap contiguous
/// memory; the node boxes are the union of the children's, made on the way back up. The two
/// halves are built in parallel.
template <class Box>
struct Builder {
  struct Item {
    Vec3 centre2;  ///< lo + hi (twice the box centre)
    int primitive;
  };
  const Box& box;
  std::vector<Item> items;
  BoxTree& tree;

  /// Build the subtree over items[begin, end) into nodes[id, id + subtree_nodes(end − begin)).
  void build(int id, int begin, int end) {
    BoxTree::Node& node = tree.nodes[std::size_t(id)];
    if (end - begin <= kLeafSize) {
      Vec3 nlo(std::numeric_limits<double>::max()), nhi(-std::numeric_limits<double>::max());
      for (int i = begin; i < end; ++i) {
        const int p = items[std::size_t(i)].primitive;
        tree.order[std::size_t(i)] = p;
        Vec3 lo, hi;
        box(p, lo, hi);
        nlo.minimize(lo);
        nhi.maximize(hi);
      }
      node.lo = nlo;
      node.hi = nhi;
      node.begin = begin;
      node.end = end;
      return;
    }
    Vec3 clo(std::numeric_limits<double>::max()), chi(-std::numeric_limits<double>::max());  // of the centres
    for (int i = begin; i < end; ++i) {
      clo.minimize(items[std::size_t(i)].centre2);
      chi.maximize(items[std::size_t(i)].centre2);
    }
    const Vec3 ext = chi - clo;
    const int axis = ext[0] > ext[1] ? (ext[0] > ext[2] ? 0 : 2) : (ext[1] > ext[2] ? 1 : 2);
    const int mid = (begin + end) / 2;
    auto split = [&]<int k>(std::integral_constant<int, k>) {  // the axis known to the compiler
      std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end,
                       [](const Item& a, const Item& b) { return a.centre2[k] < b.centre2[k]; });
    };
    if (axis == 0) split(std::integral_constant<int, 0>());
    else if (axis == 1) split(std::integral_constant<int, 1>());
    else split(std::integral_constant<int, 2>());
    node.left = id + 1;
    node.right = id + 1 + subtree_nodes(mid - begin);
    if (end - begin > 16384)  // the halves write disjoint ranges of `items`, `order` and `nodes`
      tbb::parallel_invoke([&] { build(node.left, begin, mid); }, [&] { build(node.right, mid, end); });
    else {
      build(node.left, begin, mid);
      build(node.right, mid, end);
    }
    const BoxTree::Node &left = tree.nodes[std::size_t(node.left)], &right = tree.nodes[std::size_t(node.right)];
    node.lo = left.lo;
    node.lo.minimize(right.lo);
    node.hi = left.hi;
    node.hi.maximize(right.hi);
  }
};

double box_distance2(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    double d = std::max({lo[k] - p[k], 0.0, p[k] - hi[k]});
    d2 += d * d;
  }
  return d2;
}

/// Nearest primitive by depth-first traversal, nearer child first; `distance2(i)` gives the
/// squared distance to primitive i and records the best candidate itself.
template <class Distance>
void nearest(const BoxTree& tree, const Vec3& p, double& best2, Distance&& distance2) {
  if (tree.nodes.empty()) return;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const auto& node = tree.nodes[stack[--top]];
    if (box_distance2(p, node.lo, node.hi) >= best2) continue;
    if (node.left < 0) {
      for (int i = node.begin; i < node.end; ++i) distance2(tree.order[i]);
      continue;
    }
    double dl = box_distance2(p, tree.nodes[node.left].lo, tree.nodes[node.left].hi);
    double dr = box_distance2(p, tree.nodes[node.right].lo, tree.nodes[node.right].hi);
    if (dl < dr) {
      if (dr < best2) stack[top++] = node.right;
      stack[top++] = node.left;
    } else {
      if (dl < best2) stack[top++] = node.left;
      stack[top++] = node.right;
    }
  }
}
}  // namespace

template <class Box>
void BoxTree::build(int n, const Box& box) {
  nodes.clear();
  order.clear();
  if (n <= 0) return;
  // The boxes are made again at the leaves rather than kept: two arrays of the primitives' size
  // less at the remesh's memory peak.
  Builder<Box> builder{box, std::vector<typename Builder<Box>::Item>(std::size_t(n)), *this};
  tbb::parallel_for(tbb::blocked_range<int>(0, n, 4096), [&](const tbb::blocked_range<int>& range) {
    for (int i = range.begin(); i < range.end(); ++i) {
      Vec3 lo, hi;
      box(i, lo, hi);
      builder.items[std::size_t(i)] = {lo + hi, i};
    }
  });
  order.resize(std::size_t(n));
  nodes.resize(std::size_t(subtree_nodes(n)));
  builder.build(0, 0, n);
}

}  // namespace detail

Vec3 closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  Vec3 ab = b - a;
  double len2 = ab.sqrnorm();
  if (len2 <= 0) return a;
  double t = std::clamp(((p - a) | ab) / len2, 0.0, 1.0);
  return a + ab * t;
}

Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Voronoi regions of the vertices, edges and face (Ericson, Real-Time Collision Detection 5.1.5).
  Vec3 ab = b - a, ac = c - a, ap = p - a;
  double d1 = ab | ap, d2 = ac | ap;
  if (d1 <= 0 && d2 <= 0) return a;
  Vec3 bp = p - b;
  double d3 = ab | bp, d4 = ac | bp;
  if (d3 >= 0 && d4 <= d3) return b;
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  Vec3 cp = p - c;
  double d5 = ab | cp, d6 = ac | cp;
  if (d6 >= 0 && d5 <= d6) return c;
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  double denom = va + vb + vc;
  if (denom == 0) return a;
  double v = vb / denom, w = vc / denom;
  return a + ab * v + ac * w;
}

ReferenceSurface::ReferenceSurface(const SurfaceMesh& mesh) {
  std::vector<int> index(mesh.n_vertices(), -1);
  points_.reserve(mesh.n_vertices());
  for (auto v : mesh.vertices()) {
    index[v.idx()] = int(points_.size());
    points_.push_back(mesh.point(v));
  }
  // Reference triangle k is the k-th face that is not deleted.
  std::vector<int> faces;
  faces.reserve(mesh.n_faces());
  std::vector<int> face_index(mesh.n_faces(), -1);
  for (auto f : mesh.faces()) {
    face_index[std::size_t(f.idx())] = int(faces.size());
    faces.push_back(f.idx());
  }
  const int nt = int(faces.size());
  tri_.resize(std::size_t(nt));
  normal_.resize(std::size_t(nt));
  auto twice_area_normal = [&](const std::array<int, 3>& t) {
    return (points_[std::size_t(t[1])] - points_[std::size_t(t[0])]) % (points_[std::size_t(t[2])] - points_[std::size_t(t[0])]);
  };
  tbb::parallel_for(tbb::blocked_range<int>(0, nt, 4096), [&](const tbb::blocked_range<int>& range) {
    for (int k = range.begin(); k < range.end(); ++k) {
      std::array<int, 3>& t = tri_[std::size_t(k)];
      int c = 0;
      for (auto v : mesh.fv_range(FaceHandle(faces[std::size_t(k)]))) t[c++] = index[std::size_t(v.idx())];
      const Vec3 n = twice_area_normal(t);
      const double len = n.norm();
      normal_[std::size_t(k)] = len > 0 ? n / len : Vec3(0, 0, 0);
    }
  });
  // Vertex normals weighted by twice the area, summed in triangle order (the bits do not depend on
  // the number of threads).
  vertex_normal_.assign(points_.size(), Vec3(0, 0, 0));
  for (const auto& t : tri_) {
    const Vec3 n = twice_area_normal(t);
    for (int i : t) vertex_normal_[std::size_t(i)] += n;
  }
  // The turn of the normal between two adjacent triangles per distance between their centroids: on
  // a fine tessellation of a sphere of radius R, 1/R; across a crease, the crease's angle over a
  // triangle's size. The largest over the edges, in parallel (a maximum in any order).
  auto centroid = [&](int f) {
    const auto& t = tri_[std::size_t(f)];
    return (points_[std::size_t(t[0])] + points_[std::size_t(t[1])] + points_[std::size_t(t[2])]) / 3.0;
  };
  // An edge whose curvature cannot exceed `most` is not evaluated to the last bit: the angle
  // atan2(s, c) is at most s/c while c > 0 (the margin covers both roundings), which spares most
  // edges the arc tangent and leaves the maximum as it is.
  auto edge_curvature = [&](int e, double most) {
    const EdgeHandle edge(e);
    if (mesh.status(edge).deleted() || mesh.is_boundary(edge)) return 0.0;
    const int f0 = face_index[std::size_t(mesh.face_handle(mesh.halfedge_handle(edge, 0)).idx())];
    const int f1 = face_index[std::size_t(mesh.face_handle(mesh.halfedge_handle(edge, 1)).idx())];
    const Vec3 &n0 = normal_[std::size_t(f0)], &n1 = normal_[std::size_t(f1)];
    if (n0.sqrnorm() == 0 || n1.sqrnorm() == 0) return std::numeric_limits<double>::infinity();
    const double apart = (centroid(f0) - centroid(f1)).norm();
    if (!(apart > 0)) return std::numeric_limits<double>::infinity();
    const double sine = (n0 % n1).norm(), cosine = n0 | n1;
    if (cosine > 0 && sine / cosine * (1 + 1e-12) / apart <= most) return 0.0;
    return std::atan2(sine, cosine) / apart;
  };
  max_curvature_ = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, int(mesh.n_edges()), 4096), 0.0,
      [&](const tbb::blocked_range<int>& range, double most) {
        for (int e = range.begin(); e < range.end(); ++e) most = std::max(most, edge_curvature(e, most));
        return most;
      },
      [](double x, double y) { return std::max(x, y); });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, vertex_normal_.size(), 4096), [&](const auto& range) {
    for (std::size_t i = range.begin(); i < range.end(); ++i) {
      Vec3& n = vertex_normal_[i];
      const double len = n.norm();
      if (len > 0) n /= len;
    }
  });
}

ReferenceSurface::~ReferenceSurface() = default;

std::shared_ptr<ReferenceSurface> ReferenceSurface::sphere(const Vec3& center, double radius) {
  std::shared_ptr<ReferenceSurface> s(new ReferenceSurface());
  s->is_sphere_ = true;
  s->center_ = center;
  s->radius_ = radius;
  return s;
}

void ReferenceSurface::ensure_tree() const {
  std::call_once(tree_once_, [this] {
    tree_ = std::make_unique<detail::BoxTree>();
    auto box = [this](int i, Vec3& lo, Vec3& hi) {
      const auto& t = tri_[std::size_t(i)];
      lo = hi = points_[std::size_t(t[0])];
      for (int k = 1; k < 3; ++k) {
        lo.minimize(points_[std::size_t(t[std::size_t(k)])]);
        hi.maximize(points_[std::size_t(t[std::size_t(k)])]);
      }
    };
    tree_->build(int(tri_.size()), box);
  });
}

SurfacePoint ReferenceSurface::closest(const Vec3& p, int hint) const {
  SurfacePoint out;
  if (is_sphere_) {
    Vec3 d = p - center_;
    double len = d.norm();
    out.normal = len > 0 ? d / len : Vec3(0, 0, 1);
    out.point = center_ + out.normal * radius_;
    return out;
  }
  if (tri_.empty()) {
    out.point = p;
    return out;
  }
  double best2 = std::numeric_limits<double>::max();
  auto consider = [&](int i) {
    const auto& t = tri_[i];
    Vec3 q = closest_point_on_triangle(p, points_[t[0]], points_[t[1]], points_[t[2]]);
    double d2 = (q - p).sqrnorm();
    if (d2 < best2) {
      best2 = d2;
      out.point = q;
      out.face = i;
    }
  };
  if (hint >= 0 && hint < int(tri_.size())) {
    consider(hint);
    best2 *= 1 + 1e-12;  // keep the hint's value as a strict bound
  }
  ensure_tree();
  detail::nearest(*tree_, p, best2, consider);
  out.normal = normal_[out.face];
  return out;
}

double ReferenceSurface::distance_to_triangle(const Vec3& p, int i) const {
  if (is_sphere_ || i < 0 || i >= int(tri_.size())) return std::numeric_limits<double>::infinity();
  const auto& t = tri_[std::size_t(i)];
  return (closest_point_on_triangle(p, points_[t[0]], points_[t[1]], points_[t[2]]) - p).norm();
}

void ReferenceSurface::ensure_neighbours() const {
  std::call_once(neighbours_once_, [this] {
    // Each vertex's triangles (a counting sort), then across each side a triangle that has it the
    // other way round (on a manifold surface the only one).
    const std::size_t nv = points_.size(), nt = tri_.size();
    std::vector<int> first(nv + 1, 0), around(3 * nt);
    for (const auto& t : tri_)
      for (int v : t) ++first[std::size_t(v) + 1];
    for (std::size_t v = 0; v < nv; ++v) first[v + 1] += first[v];
    std::vector<int> next(first.begin(), first.end() - 1);
    for (std::size_t k = 0; k < nt; ++k)
      for (int v : tri_[k]) around[std::size_t(next[std::size_t(v)]++)] = int(k);
    neighbour_.resize(nt);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nt, 4096), [&](const auto& range) {
      for (std::size_t k = range.begin(); k < range.end(); ++k)
        for (int i = 0; i < 3; ++i) {
          const int a = tri_[k][std::size_t(i)], b = tri_[k][std::size_t((i + 1) % 3)];
          int& across = neighbour_[k][std::size_t(i)];
          across = -1;
          for (int at = first[std::size_t(b)]; at < first[std::size_t(b) + 1] && across < 0; ++at) {
            const auto& u = tri_[std::size_t(around[std::size_t(at)])];
            for (int j = 0; j < 3; ++j)
              if (u[std::size_t(j)] == b && u[std::size_t((j + 1) % 3)] == a) across = around[std::size_t(at)];
          }
        }
    });
  });
}

double ReferenceSurface::distance_to_neighbours(const Vec3& p, int i) const {
  double least = std::numeric_limits<double>::infinity();
  if (is_sphere_ || i < 0 || i >= int(tri_.size())) return least;
  ensure_neighbours();
  for (int j : neighbour_[std::size_t(i)])
    if (j >= 0) least = std::min(least, distance_to_triangle(p, j));
  return least;
}

Vec3 ReferenceSurface::smooth_normal(const SurfacePoint& q) const {
  if (q.face < 0) return q.normal;
  const auto& t = tri_[std::size_t(q.face)];
  const auto w = barycentric(q.point, points_[t[0]], points_[t[1]], points_[t[2]]);
  const Vec3 n = w[0] * vertex_normal_[t[0]] + w[1] * vertex_normal_[t[1]] + w[2] * vertex_normal_[t[2]];
  const double len = n.norm();
  return len > 0 ? n / len : q.normal;
}

ReferencePolyline::ReferencePolyline() = default;
ReferencePolyline::~ReferencePolyline() = default;
ReferencePolyline::ReferencePolyline(ReferencePolyline&&) noexcept = default;
ReferencePolyline& ReferencePolyline::operator=(ReferencePolyline&&) noexcept = default;

void ReferencePolyline::add(const Vec3& a, const Vec3& b, int label) {
  a_.push_back(a);
  b_.push_back(b);
  da_.push_back(b - a);
  db_.push_back(b - a);
  smooth_.push_back(0);
  label_.push_back(label);
  built_ = false;
}

void ReferencePolyline::smooth(int label, double corner_angle) {
  // Segment ends meeting at each vertex (end 0 = a, 1 = b), vertices matched by exact coordinates.
  std::map<std::array<double, 3>, std::vector<std::pair<int, int>>> ends;
  auto key = [](const Vec3& p) { return std::array<double, 3>{p[0], p[1], p[2]}; };
  for (std::size_t i = 0; i < a_.size(); ++i)
    if (label_[i] == label) {
      ends[key(a_[i])].emplace_back(int(i), 0);
      ends[key(b_[i])].emplace_back(int(i), 1);
    }
  // Unit tangents at each segment end, oriented a → b; zero = not determined by a smooth vertex.
  std::vector<std::array<Vec3, 2>> unit(a_.size(), {Vec3(0, 0, 0), Vec3(0, 0, 0)});
  const double cos_corner = std::cos(corner_angle);
  for (const auto& [k, list] : ends) {
    if (list.size() != 2) continue;
    Vec3 p(k[0], k[1], k[2]);
    auto other = [&](std::pair<int, int> e) { return e.second == 0 ? b_[e.first] : a_[e.first]; };
    Vec3 d0 = p - other(list[0]), d1 = other(list[1]) - p;  // q0 → p → q1
    double l0 = d0.norm(), l1 = d1.norm();
    if (l0 <= 0 || l1 <= 0) continue;
    if ((d0 | d1) / (l0 * l1) < cos_corner) continue;  // a corner: one-sided tangents
    // Bessel: derivative at p of the parabola through q0, p, q1 parametrised by chord length.
    Vec3 t = d0 * (l1 / (l0 * (l0 + l1))) + d1 * (l0 / (l1 * (l0 + l1)));
    double lt = t.norm();
    if (lt <= 0) continue;
    t /= lt;
    for (auto e : list) {
      Vec3 chord = b_[e.first] - a_[e.first];
      unit[e.first][e.second] = (t | chord) >= 0 ? t : -t;
    }
  }
  for (std::size_t i = 0; i < a_.size(); ++i) {
    if (label_[i] != label) continue;
    Vec3 chord = b_[i] - a_[i];
    double l = chord.norm();
    if (l <= 0) continue;
    Vec3 c = chord / l;
    auto one_sided = [&](const Vec3& known) {
      if (known.sqrnorm() == 0) return c;
      // Mirror of the other end's tangent about the chord: what a circular arc would have.
      Vec3 m = c * (2 * (c | known)) - known;
      return (m | c) > 0.5 ? m : c;
    };
    Vec3 ta = unit[i][0], tb = unit[i][1];
    if (ta.sqrnorm() == 0) ta = one_sided(tb);
    if (tb.sqrnorm() == 0) tb = one_sided(unit[i][0]);
    da_[i] = ta * l;
    db_[i] = tb * l;
    smooth_[i] = 1;
  }
  built_ = false;
}

Vec3 ReferencePolyline::point(std::size_t i, double t) const {
  double t2 = t * t, t3 = t2 * t;
  return a_[i] * (2 * t3 - 3 * t2 + 1) + da_[i] * (t3 - 2 * t2 + t) + b_[i] * (3 * t2 - 2 * t3) + db_[i] * (t3 - t2);
}

Vec3 ReferencePolyline::closest_on(std::size_t i, const Vec3& p) const {
  Vec3 chord = b_[i] - a_[i];
  double l2 = chord.sqrnorm();
  double t = l2 > 0 ? std::clamp(((p - a_[i]) | chord) / l2, 0.0, 1.0) : 0.0;
  if (!smooth_[i]) return a_[i] + chord * t;
  // Newton on |C(t) − p|², started from the chord's parameter (the arc is within the sagitta of it).
  const Vec3 &a = a_[i], &b = b_[i], &da = da_[i], &db = db_[i];
  for (int it = 0; it < 5; ++it) {
    double tt = t * t;
    Vec3 c = point(i, t) - p;
    Vec3 d1 = a * (6 * tt - 6 * t) + da * (3 * tt - 4 * t + 1) + b * (6 * t - 6 * tt) + db * (3 * tt - 2 * t);
    Vec3 d2 = a * (12 * t - 6) + da * (6 * t - 4) + b * (6 - 12 * t) + db * (6 * t - 2);
    double g = c | d1, hess = (d1 | d1) + (c | d2);
    if (hess <= 0) hess = d1 | d1;
    if (hess <= 0) break;
    double next = std::clamp(t - g / hess, 0.0, 1.0);
    if (std::abs(next - t) < 1e-14) break;
    t = next;
  }
  return point(i, t);
}

void ReferencePolyline::ensure_tree() const {
  if (built_) return;
  auto box = [this](int i, Vec3& lo, Vec3& hi) {
    const auto k = std::size_t(i);
    lo = hi = a_[k];
    lo.minimize(b_[k]);
    hi.maximize(b_[k]);
    if (smooth_[k])  // the arc lies in the hull of its Bézier control points
      for (const Vec3& q : {a_[k] + da_[k] / 3.0, b_[k] - db_[k] / 3.0}) {
        lo.minimize(q);
        hi.maximize(q);
      }
  };
  if (!tree_) tree_ = std::make_unique<detail::BoxTree>();
  tree_->build(int(a_.size()), box);
  built_ = true;
}

Vec3 ReferencePolyline::closest(const Vec3& p, int label) const {
  ensure_tree();
  double best2 = std::numeric_limits<double>::max();
  Vec3 best = p;
  detail::nearest(*tree_, p, best2, [&](int i) {
    if (label_[i] != label) return;
    Vec3 q = closest_on(std::size_t(i), p);
    double d2 = (q - p).sqrnorm();
    if (d2 < best2) {
      best2 = d2;
      best = q;
    }
  });
  return best;
}

}  // namespace bodyfit
