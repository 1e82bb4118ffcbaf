// Marching triangles on a surface mesh: snap, split the crossed edges, pick the better diagonals,
// label. Work is proportional to the crossed faces plus one pass over the elements.
#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/levelset_mesher.hpp>
#include <bodyfit/remesh.hpp>

#include "blocks.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

namespace bodyfit {

namespace {

bool opposite_signs(double a, double b) { return (a < 0 && b > 0) || (a > 0 && b < 0); }

/// Position along (a, b) of the zero of the linear interpolant, as a fraction of |ab| from a.
double zero_fraction(double a, double b) { return a / (a - b); }

/// Zero of the cubic Hermite interpolant of values fa, fb and slopes ma, mb (per unit t) on [0, 1],
/// by Newton's method from the linear zero; the linear zero when the cubic is not trustworthy
/// there (see DiscretizeOptions::hermite_crossings).
double hermite_zero_fraction(double fa, double fb, double ma, double mb) {
  const double linear = zero_fraction(fa, fb);
  const double secant = fb - fa;
  // A slope at rounding level (a fitted gradient where the exact one is 0) says nothing: linear.
  const double tiny = 1e-12 * secant * secant;
  if (ma * secant <= tiny || mb * secant <= tiny) return linear;
  double t = linear;
  for (int iteration = 0; iteration < 8; ++iteration) {
    const double t2 = t * t, t3 = t2 * t;
    const double value = (2 * t3 - 3 * t2 + 1) * fa + (t3 - 2 * t2 + t) * ma + (-2 * t3 + 3 * t2) * fb + (t3 - t2) * mb;
    const double slope = (6 * t2 - 6 * t) * fa + (3 * t2 - 4 * t + 1) * ma + (-6 * t2 + 6 * t) * fb + (3 * t2 - 2 * t) * mb;
    if (slope * secant <= 0) return linear;
    const double step = value / slope;
    t -= step;
    if (!(t > 0 && t < 1) || std::abs(t - linear) > 0.25) return linear;
    if (std::abs(step) < 1e-14) break;
  }
  return t;
}

/// The tangential gradient of φ at v from a least-squares quadratic through the values of its two
/// rings (in the tangent plane at v, weighted by 1/distance²), for the Hermite slopes. The
/// averaged face gradients (vertex_gradient) carry an O(h) error on an irregular mesh — a remeshed
/// one next to the front — which scattered the cubic zeros by ~3e-5 rad at h = 0.06 (5e-4 h) about
/// the front; the remesher, keeping some cut points and collapsing others, kept the inner ones
/// more often, and an oscillating cap lost 0.5-1 % of its area per period (docs/validation/drift.md).
/// The fit is exact for quadratics: the error is O(h²) where φ is smooth over the rings. Nothing
/// with fewer than 8 neighbours, an ill-conditioned fit, or a residual above residual_limit (see
/// DiscretizeOptions::fit_residual_limit): across a kink of φ the quadratic averages the slopes of
/// the two sides, worse than the face gradients, which at least stay within one ring.
std::optional<Vec3> fitted_gradient(const SurfaceMesh& mesh, VertexHandle v, const ScalarField& phi,
                                    double residual_limit) {
  const Vec3 normal = vertex_normal(mesh, v);
  Vec3 e1 = std::abs(normal[0]) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  e1 = (e1 - normal * OpenMesh::dot(e1, normal)).normalized();
  const Vec3 e2 = OpenMesh::cross(normal, e1);
  std::vector<VertexHandle> ring;
  for (auto w : mesh.vv_range(v)) ring.push_back(w);
  const std::size_t first = ring.size();
  for (std::size_t i = 0; i < first; ++i)
    for (auto w : mesh.vv_range(ring[i]))
      if (w != v && std::find(ring.begin(), ring.end(), w) == ring.end()) ring.push_back(w);
  if (ring.size() < 8) return std::nullopt;
  const Vec3& p = mesh.point(v);
  double scale = 0;
  for (auto w : ring) scale += (mesh.point(w) - p).norm();
  scale /= double(ring.size());  // coordinates in units of the rings' mean radius: a well-scaled system
  std::vector<Eigen::Matrix<double, 5, 1>> rows(ring.size());
  std::vector<double> weights(ring.size()), values(ring.size());
  Eigen::Matrix<double, 5, 5> normal_matrix = Eigen::Matrix<double, 5, 5>::Zero();
  Eigen::Matrix<double, 5, 1> rhs = Eigen::Matrix<double, 5, 1>::Zero();
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const Vec3 d = (mesh.point(ring[i]) - p) / scale;
    const double x = OpenMesh::dot(d, e1), y = OpenMesh::dot(d, e2);
    weights[i] = 1 / (x * x + y * y);
    values[i] = phi[ring[i].idx()] - phi[v.idx()];
    rows[i] << x, y, 0.5 * x * x, x * y, 0.5 * y * y;
    normal_matrix += weights[i] * rows[i] * rows[i].transpose();
    rhs += weights[i] * values[i] * rows[i];
  }
  const Eigen::LDLT<Eigen::Matrix<double, 5, 5>> ldlt(normal_matrix);
  if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-8)) return std::nullopt;
  const Eigen::Matrix<double, 5, 1> c = ldlt.solve(rhs);
  double squared = 0, total = 0;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const double r = values[i] - rows[i].dot(c);
    squared += weights[i] * r * r, total += weights[i];
  }
  // Both sides in units of φ: the slope per mean radius is |(c0, c1)|.
  if (!(std::sqrt(squared / total) <= residual_limit * std::hypot(c[0], c[1]))) return std::nullopt;
  return (c[0] * e1 + c[1] * e2) / scale;
}

/// The cut as it will be once every crossed edge is split, seen from one vertex where φ = 0:
/// its number of interface edges. A face (v, w, x) whose w and x have strict opposite signs adds
/// the segment from v to the crossing on wx; an edge (v, w) with φ(w) = 0 is interface when exactly
/// one of its two faces has a negative third vertex (faces with only zeros and positives are outside).
int predicted_interface_degree(const SurfaceMesh& mesh, const ScalarField& value, VertexHandle v) {
  int degree = 0;
  for (auto h : mesh.voh_range(v)) {
    auto w = mesh.to_vertex_handle(h);
    double vw = value[w.idx()];
    bool has_face = !mesh.is_boundary(h);
    double x = has_face ? value[mesh.to_vertex_handle(mesh.next_halfedge_handle(h)).idx()] : 0.0;
    if (has_face && opposite_signs(vw, x)) ++degree;
    auto o = mesh.opposite_halfedge_handle(h);
    if (vw == 0 && has_face && !mesh.is_boundary(o)) {
      double y = value[mesh.to_vertex_handle(mesh.next_halfedge_handle(o)).idx()];
      if ((x < 0) != (y < 0)) ++degree;
    }
  }
  return degree;
}

/// A simple interface curve passes through an interior vertex (degree 2) or misses it (0); on the
/// boundary it may end there (1); more means the inside region touches itself at the vertex.
bool acceptable_degree(const SurfaceMesh& mesh, VertexHandle v, int degree) {
  return mesh.is_boundary(v) ? degree <= 1 : (degree == 0 || degree == 2);
}

/// Tags an edge carries that its two halves must keep after a split.
struct EdgeTags {
  int ref = 0;
  SurfaceMesh::Flag ridge = 0, required = 0;
};

/// A face with two crossed edges: `lone` is the vertex alone on its side, (lone, b, c) in the face's
/// orientation; the crossings p on (lone, b) and q on (c, lone) are found after the splits.
struct QuadCut {
  VertexHandle lone, b, c;
  int edge_ab = -1, edge_ca = -1;
};

/// Snap the vertices whose crossing lies within their snap ratio of them (in index order, so the result
/// does not depend on anything but the input), keeping every φ = 0 vertex a simple interface point.
void snap(const SurfaceMesh& mesh, const std::vector<EdgeHandle>& crossed, ScalarField& value,
          const DiscretizeOptions& options, DiscretizeReport& report) {
  const double fixed_ratio = std::max(options.snap_ratio, options.fixed_snap_ratio);
  if (fixed_ratio <= 0) return;
  // The remesher cannot move these vertices away from a cut next to them.
  auto ratio = [&](VertexHandle v) {
    bool fixed = mesh.is_boundary(v) || mesh.corner(v) || mesh.required(v);
    for (auto e : mesh.ve_range(v)) fixed = fixed || mesh.ridge(e) || mesh.required(e);
    return fixed ? fixed_ratio : options.snap_ratio;
  };
  std::vector<int> candidates;
  for (auto e : crossed) {
    auto h = mesh.halfedge_handle(e, 0);
    auto a = mesh.from_vertex_handle(h), b = mesh.to_vertex_handle(h);
    double t = zero_fraction(value[a.idx()], value[b.idx()]);
    if (t < fixed_ratio && t < ratio(a)) candidates.push_back(a.idx());
    if (1 - t < fixed_ratio && 1 - t < ratio(b)) candidates.push_back(b.idx());
  }
  std::sort(candidates.begin(), candidates.end());
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());

  std::vector<std::pair<VertexHandle, int>> zero_neighbours;
  for (int index : candidates) {
    VertexHandle v(index);
    double old = value[index];
    // A neighbour snapped earlier may have removed the close crossing.
    bool still_close = false;
    const double snap_ratio = ratio(v);
    for (auto w : mesh.vv_range(v)) {
      double vw = value[w.idx()];
      if (opposite_signs(old, vw) && zero_fraction(old, vw) < snap_ratio) still_close = true;
    }
    if (!still_close) continue;
    zero_neighbours.clear();
    for (auto w : mesh.vv_range(v))
      if (value[w.idx()] == 0) zero_neighbours.emplace_back(w, predicted_interface_degree(mesh, value, w));
    value[index] = 0;
    bool ok = acceptable_degree(mesh, v, predicted_interface_degree(mesh, value, v));
    for (auto [w, before] : zero_neighbours) {
      if (!ok) break;
      int after = predicted_interface_degree(mesh, value, w);
      ok = acceptable_degree(mesh, w, after) || after <= before;
    }
    if (ok) {
      ++report.snapped_vertices;
    } else {
      value[index] = old;
      ++report.rejected_snaps;
    }
  }
}

/// The vertices where `value` is exactly 0, in index order.
std::vector<VertexHandle> zeros(const SurfaceMesh& mesh, const ScalarField& value) {
  return collect<VertexHandle>(int(mesh.n_vertices()), [&](int i, VertexHandle& v) {
    v = VertexHandle(i);
    return value[std::size_t(i)] == 0 && !mesh.status(v).deleted();
  });
}

/// Where the input φ is exactly 0 at a vertex around which the cut would not be a simple curve
/// (a saddle: inside parts meeting at the vertex), put the vertex on the outside: φ = δ > 0, the
/// geometric mean of |φ| over its negative neighbours, so the new crossings sit at comparable
/// fractions of their edges. This may spoil a zero neighbour in turn: repeat until none is left
/// (each vertex moves at most once, since only vertices with φ = 0 can be spoiled).
std::vector<VertexHandle> separate_pinches(const SurfaceMesh& mesh, ScalarField& value, DiscretizeReport& report) {
  std::vector<VertexHandle> work, separated;
  for (auto v : zeros(mesh, value))
    if (!acceptable_degree(mesh, v, predicted_interface_degree(mesh, value, v))) work.push_back(v);
  std::reverse(work.begin(), work.end());  // pop in index order
  while (!work.empty()) {
    auto v = work.back();
    work.pop_back();
    if (value[v.idx()] != 0 || acceptable_degree(mesh, v, predicted_interface_degree(mesh, value, v))) continue;
    double smallest = 0, largest = 0;
    for (auto w : mesh.vv_range(v)) {
      double magnitude = -value[w.idx()];
      if (magnitude <= 0) continue;
      smallest = smallest == 0 ? magnitude : std::min(smallest, magnitude);
      largest = std::max(largest, magnitude);
    }
    if (largest == 0) continue;  // cannot happen: an interface vertex has a negative neighbour
    value[v.idx()] = std::sqrt(smallest * largest);
    ++report.separated_vertices;
    separated.push_back(v);
    for (auto w : mesh.vv_range(v))
      if (value[w.idx()] == 0 && !acceptable_degree(mesh, w, predicted_interface_degree(mesh, value, w)))
        work.push_back(w);
  }
  return separated;
}

bool crossed_edge(const SurfaceMesh& mesh, const ScalarField& value, EdgeHandle e) {
  auto h = mesh.halfedge_handle(e, 0);
  return opposite_signs(value[mesh.from_vertex_handle(h).idx()], value[mesh.to_vertex_handle(h).idx()]);
}

void set_edge_tags(SurfaceMesh& mesh, EdgeHandle e, const EdgeTags& tags) {
  mesh.edge_ref(e) = tags.ref;
  mesh.ridge(e) = tags.ridge;
  mesh.required(e) = tags.required;
  mesh.interface(e) = 0;
}

/// Of the two triangulations of the quad (p, b, c, q), keep the one whose worse triangle is better.
bool improve_diagonal(SurfaceMesh& mesh, VertexHandle p, VertexHandle b, VertexHandle c, VertexHandle q) {
  const Vec3 &P = mesh.point(p), &B = mesh.point(b), &C = mesh.point(c), &Q = mesh.point(q);
  double with_pc = std::min(triangle_quality(P, B, C), triangle_quality(P, C, Q));
  double with_bq = std::min(triangle_quality(P, B, Q), triangle_quality(B, C, Q));
  // The diagonal to remove, if it is the one present; a tie keeps what the splits made.
  HalfedgeHandle current = with_bq > with_pc ? mesh.find_halfedge(p, c)
                           : with_pc > with_bq ? mesh.find_halfedge(b, q)
                                               : HalfedgeHandle();
  if (!current.is_valid()) return false;
  auto e = mesh.edge_handle(current);
  if (!mesh.is_flip_ok(e)) return false;
  mesh.flip(e);
  return true;
}

/// Give every part of a region with area below `min_area` to the region around it (smallest
/// first; a part next to one given away in the same round waits for the next round, so that a
/// speck's hole is judged after the speck is gone). Returns how many parts were given away.
///
/// Local to the interface: every part of a region that is not a whole component of the surface
/// has an interface edge, so the parts are grown from `seeds` (every face with a corner where
/// φ = 0, which includes the faces on both sides of every interface edge), and a part's growth
/// stops as soon as its area reaches `min_area`: the cost follows the interface, not the mesh.
/// Giving a part away only removes interface edges, so the seeds of the first round serve all.
std::size_t remove_specks(SurfaceMesh& mesh, ScalarField& value, double min_area, std::vector<FaceHandle> seeds) {
  constexpr int kUnseen = -1, kLarge = -2;  // mark of a face: a small part's id, or one of these
  std::sort(seeds.begin(), seeds.end());
  seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
  std::vector<int> mark(mesh.n_faces(), kUnseen);
  std::vector<FaceHandle> touched, stack, part_faces;
  std::size_t removed = 0;
  for (bool changed = true; changed;) {
    changed = false;
    for (auto f : touched) mark[std::size_t(f.idx())] = kUnseen;
    touched.clear();
    struct Part {
      double area = 0;
      std::vector<FaceHandle> faces;
    };
    std::vector<Part> parts;
    for (auto seed : seeds) {
      if (mark[std::size_t(seed.idx())] != kUnseen) continue;
      const int id = int(parts.size());
      const int region = mesh.region(seed);
      double area = 0;
      bool large = false, bordered = false;
      part_faces.clear();
      stack.assign(1, seed);
      mark[std::size_t(seed.idx())] = id;
      part_faces.push_back(seed);
      while (!stack.empty() && !large) {
        auto f = stack.back();
        stack.pop_back();
        area += face_area(mesh, f);
        large = area >= min_area;
        for (auto g : mesh.ff_range(f)) {
          if (mesh.region(g) != region) {
            bordered = true;
            continue;
          }
          int& m = mark[std::size_t(g.idx())];
          if (m == kLarge) large = true;  // joined to a part already known to be large
          if (m != kUnseen) continue;
          m = id;
          part_faces.push_back(g);
          stack.push_back(g);
        }
      }
      touched.insert(touched.end(), part_faces.begin(), part_faces.end());
      // A part with no other region around it is a whole component of the surface: there is nothing
      // to give it to (with a speck area above the surface's, giving G away and then the whole
      // surface back would never end).
      large = large || !bordered;
      if (large) {
        for (auto f : part_faces) mark[std::size_t(f.idx())] = kLarge;
      } else {
        parts.push_back({area, part_faces});
      }
    }
    if (parts.empty()) break;
    std::vector<int> order(parts.size());
    for (int id = 0; id < int(parts.size()); ++id) order[std::size_t(id)] = id;
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      return parts[std::size_t(a)].area < parts[std::size_t(b)].area ||
             (parts[std::size_t(a)].area == parts[std::size_t(b)].area && a < b);
    });
    std::vector<char> blocked(parts.size(), 0);
    std::vector<int> flipped;
    for (int id : order) {
      if (blocked[std::size_t(id)]) continue;
      flipped.push_back(id);
      for (auto f : parts[std::size_t(id)].faces)
        for (auto g : mesh.ff_range(f))
          if (int m = mark[std::size_t(g.idx())]; m >= 0) blocked[std::size_t(m)] = 1;
      ++removed;
      changed = true;
    }
    for (int id : flipped) {
      const bool to_inside = mesh.region(parts[std::size_t(id)].faces.front()) != kInside;
      for (auto f : parts[std::size_t(id)].faces) mesh.region(f) = to_inside ? kInside : kOutside;
    }
    // φ takes the sign of its new side (its zeros become a hair off zero), once every part of the
    // round has changed sides.
    for (int id : flipped) {
      const bool to_inside = mesh.region(parts[std::size_t(id)].faces.front()) == kInside;
      for (auto f : parts[std::size_t(id)].faces)
        for (auto v : mesh.fv_range(f)) {
          double& x = value[std::size_t(v.idx())];
          double magnitude = std::max(std::abs(x), 1e-12 * std::sqrt(min_area));
          bool all_same = true;
          for (auto g : mesh.vf_range(v)) all_same = all_same && (mesh.region(g) == kInside) == to_inside;
          if (all_same) x = to_inside ? -magnitude : magnitude;
        }
    }
  }
  return removed;
}

/// Give to the outside every part of the inside region with no face that has a corner among the
/// input's vertices where `grown_from` ≤ 0 (DiscretizeOptions::grown_from). The parts are grown from
/// `seeds` (faces around the zeros of φ: every inside part that is not a whole component of S has
/// one); a part's growth stops at its first face that meets the old region, and a part reaching a
/// face already known to do so stops too. Returns how many parts were given away.
std::size_t remove_detached(SurfaceMesh& mesh, ScalarField& value, std::span<const double> grown_from,
                            const std::vector<FaceHandle>& seeds, double tiny) {
  constexpr int kUnseen = -1, kRooted = -2;
  auto meets_old_region = [&](FaceHandle f) {
    for (auto v : mesh.fv_range(f))
      if (std::size_t(v.idx()) < grown_from.size() && grown_from[std::size_t(v.idx())] <= 0) return true;
    return false;
  };
  std::vector<int> mark(mesh.n_faces(), kUnseen);
  std::vector<FaceHandle> stack, part;
  std::vector<std::vector<FaceHandle>> detached;
  for (auto seed : seeds) {
    if (mesh.region(seed) != kInside || mark[std::size_t(seed.idx())] != kUnseen) continue;
    const int id = int(detached.size());
    bool rooted = false;
    part.assign(1, seed);
    stack.assign(1, seed);
    mark[std::size_t(seed.idx())] = id;
    while (!stack.empty() && !rooted) {
      auto f = stack.back();
      stack.pop_back();
      rooted = meets_old_region(f);
      for (auto g : mesh.ff_range(f)) {
        if (mesh.region(g) != kInside) continue;
        int& m = mark[std::size_t(g.idx())];
        if (m == kRooted) rooted = true;
        if (m != kUnseen) continue;
        m = id;
        part.push_back(g);
        stack.push_back(g);
      }
    }
    if (rooted) {
      for (auto f : part) mark[std::size_t(f.idx())] = kRooted;
    } else {
      detached.push_back(part);
    }
  }
  for (const auto& faces : detached)
    for (auto f : faces) mesh.region(f) = kOutside;
  // φ takes the outside's sign where every face around a vertex is now outside (a zero becomes a
  // hair above zero).
  for (const auto& faces : detached)
    for (auto f : faces)
      for (auto v : mesh.fv_range(f)) {
        double& x = value[std::size_t(v.idx())];
        bool all_outside = true;
        for (auto g : mesh.vf_range(v)) all_outside = all_outside && mesh.region(g) != kInside;
        if (all_outside && x <= 0) x = std::max(-x, tiny);
      }
  return detached.size();
}

/// The edges the zero level set crosses, once the crossings that nearly touch a vertex are snapped
/// and pinched vertices separated. With `find_parts`, the ends of the input's crossed edges join
/// `may_be_zero` (a snap may put them on the level set).
std::vector<EdgeHandle> crossed_edges(SurfaceMesh& mesh, ScalarField& value, const DiscretizeOptions& options,
                                      bool find_parts, std::vector<VertexHandle>& may_be_zero,
                                      DiscretizeReport& report) {
  std::vector<EdgeHandle> crossed = collect<EdgeHandle>(int(mesh.n_edges()), [&](int i, EdgeHandle& e) {
    e = EdgeHandle(i);
    return !mesh.status(e).deleted() && crossed_edge(mesh, value, e);
  });
  if (find_parts)
    for (auto e : crossed)
      for (int side = 0; side < 2; ++side) may_be_zero.push_back(mesh.to_vertex_handle(mesh.halfedge_handle(e, side)));
  snap(mesh, crossed, value, options, report);
  auto separated = separate_pinches(mesh, value, report);
  // The input's, less those a snap removed, plus those around separated vertices.
  std::erase_if(crossed, [&](EdgeHandle e) { return !crossed_edge(mesh, value, e); });
  if (!separated.empty()) {
    for (auto v : separated)
      for (auto e : mesh.ve_range(v))
        if (crossed_edge(mesh, value, e)) crossed.push_back(e);
    std::sort(crossed.begin(), crossed.end());
    crossed.erase(std::unique(crossed.begin(), crossed.end()), crossed.end());
  }
  return crossed;
}

/// The faces the level set cuts into a triangle and a quad, found on the unsplit mesh (and every
/// cut face counted).
std::vector<QuadCut> cut_quads(const SurfaceMesh& mesh, const ScalarField& value, const std::vector<EdgeHandle>& crossed,
                               DiscretizeReport& report) {
  std::vector<QuadCut> quads;
  for (auto e : crossed)
    for (int side = 0; side < 2; ++side) {
      // Each cut face is visited from each of its crossed edges: count it (and record its quad)
      // from the halfedge leaving its lone vertex only, or from its single crossed edge.
      auto h = mesh.halfedge_handle(e, side);
      if (mesh.is_boundary(h)) continue;
      auto a = mesh.from_vertex_handle(h), b = mesh.to_vertex_handle(h);
      auto hc = mesh.next_halfedge_handle(h);
      auto c = mesh.to_vertex_handle(hc);
      double va = value[a.idx()], vc = value[c.idx()];
      if (vc == 0) {
        ++report.split_faces;
      } else if (opposite_signs(va, vc)) {  // a is the lone vertex: (a, b) and (c, a) are crossed
        ++report.split_faces;
        quads.push_back({a, b, c, e.idx(), mesh.edge_handle(mesh.next_halfedge_handle(hc)).idx()});
      }
    }
  return quads;
}

/// The gradients of the input φ at the ends of the crossed edges (computed before any split): the
/// slopes of the Hermite zeros, fitted on two rings where φ is smooth there.
class CrossingSlopes {
 public:
  CrossingSlopes(const SurfaceMesh& mesh, const ScalarField& phi, const std::vector<EdgeHandle>& crossed,
                 const DiscretizeOptions& options, DiscretizeReport& report) {
    if (!options.hermite_crossings) return;
    for (auto e : crossed)
      for (int side = 0; side < 2; ++side) at_.emplace_back(mesh.to_vertex_handle(mesh.halfedge_handle(e, side)).idx(), Vec3());
    std::sort(at_.begin(), at_.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    at_.erase(std::unique(at_.begin(), at_.end(), [](const auto& x, const auto& y) { return x.first == y.first; }),
              at_.end());
    for (auto& [v, g] : at_) {
      std::optional<Vec3> fitted;
      if (options.fitted_slopes) {
        fitted = fitted_gradient(mesh, VertexHandle(v), phi, options.fit_residual_limit);
        ++(fitted ? report.fitted_slopes : report.refused_fits);
      }
      g = fitted ? *fitted : vertex_gradient(mesh, VertexHandle(v), phi);
    }
  }
  const Vec3& operator()(VertexHandle v) const {
    auto it = std::lower_bound(at_.begin(), at_.end(), v.idx(), [](const auto& x, int key) { return x.first < key; });
    return it->second;
  }

 private:
  std::vector<std::pair<int, Vec3>> at_;
};

/// Split every crossed edge at the zero of φ on it (Hermite or linear): the i-th crossed edge (in
/// index order) gets the vertex n_vertices + i, with φ = 0.
void split_crossed_edges(SurfaceMesh& mesh, ScalarField& value, const std::vector<EdgeHandle>& crossed,
                         const CrossingSlopes& slope_of, const DiscretizeOptions& options) {
  value.reserve(value.size() + crossed.size());
  // Each split adds a vertex, three edges and two faces: reserved at once, or the arrays double
  // their capacity on the way (at a million faces, the peak of the whole run).
  const std::size_t k = crossed.size();
  mesh.reserve(mesh.n_vertices() + k, mesh.n_edges() + 3 * k, mesh.n_faces() + 2 * k);
  for (auto e : crossed) {
    auto h = mesh.halfedge_handle(e, 0);
    auto a = mesh.from_vertex_handle(h), b = mesh.to_vertex_handle(h);
    const Vec3 ab = mesh.point(b) - mesh.point(a);
    const double t = options.hermite_crossings
                         ? hermite_zero_fraction(value[a.idx()], value[b.idx()], OpenMesh::dot(slope_of(a), ab),
                                                 OpenMesh::dot(slope_of(b), ab))
                         : zero_fraction(value[a.idx()], value[b.idx()]);
    Vec3 point = mesh.point(a) + t * ab;
    EdgeTags tags{mesh.edge_ref(e) == kInterfaceRef ? 0 : mesh.edge_ref(e), mesh.ridge(e), mesh.required(e)};
    auto p = mesh.add_vertex(point);
    mesh.vertex_ref(p) = 0;
    mesh.corner(p) = 0;
    mesh.required(p) = 0;
    value.push_back(0);
    mesh.split(e, p);
    // OpenMesh leaves the properties of the new edges undefined: the halves of e keep its tags,
    // the edges to the opposite vertices start untagged.
    for (auto ph : mesh.voh_range(p)) {
      auto w = mesh.to_vertex_handle(ph);
      set_edge_tags(mesh, mesh.edge_handle(ph), w == a || w == b ? tags : EdgeTags{});
    }
  }
}

/// Every face lies on one side once the crossed edges are split: inside when a vertex is negative.
void label_faces(SurfaceMesh& mesh, const ScalarField& value) {
  for_each_index(int(mesh.n_faces()), [&](int i) {
    const FaceHandle f(i);
    if (mesh.status(f).deleted()) return;
    auto h = mesh.halfedge_handle(f);
    auto h1 = mesh.next_halfedge_handle(h);
    bool inside = value[mesh.to_vertex_handle(h).idx()] < 0 || value[mesh.to_vertex_handle(h1).idx()] < 0 ||
                  value[mesh.from_vertex_handle(h).idx()] < 0;
    mesh.region(f) = inside ? kInside : kOutside;
  });
}

/// The interface: exactly the edges between faces of different labels (as
/// update_interface_from_regions), counting interface edges per vertex as a self-check.
void tag_interface(SurfaceMesh& mesh, DiscretizeReport& report) {
  // Each edge's tags set in parallel; the interface's edges gathered in index order.
  const auto interface = collect<EdgeHandle>(int(mesh.n_edges()), [&](int i, EdgeHandle& e) {
    e = EdgeHandle(i);
    if (mesh.status(e).deleted()) return false;
    auto f0 = mesh.face_handle(mesh.halfedge_handle(e, 0)), f1 = mesh.face_handle(mesh.halfedge_handle(e, 1));
    const bool is_interface = f0.is_valid() && f1.is_valid() && mesh.region(f0) != mesh.region(f1);
    mesh.interface(e) = is_interface;
    if (is_interface) mesh.edge_ref(e) = kInterfaceRef;
    else if (mesh.edge_ref(e) == kInterfaceRef) mesh.edge_ref(e) = 0;
    return is_interface;
  });
  std::vector<VertexHandle> interface_vertices;
  std::vector<unsigned char> degree;
  if (!interface.empty()) degree.assign(mesh.n_vertices(), 0);
  report.interface_edges += interface.size();
  for (auto e : interface)
    for (int side = 0; side < 2; ++side) {
      const auto v = mesh.to_vertex_handle(mesh.halfedge_handle(e, side));
      if (degree[v.idx()]++ == 0) interface_vertices.push_back(v);
    }
  for (auto v : interface_vertices)
    if (!acceptable_degree(mesh, v, degree[v.idx()])) ++report.pinched_vertices;
}

/// Garbage-collect the elements the snaps and the separations deleted, if any.
void collect_deleted(SurfaceMesh& mesh) {
  if (has_deleted_elements(mesh))
    mesh.garbage_collection();
}

}  // namespace

DiscretizeReport discretize(SurfaceMesh& mesh, const ScalarField& phi, const DiscretizeOptions& options) {
  DiscretizeReport report;
  if (phi.size() != mesh.n_vertices())
    throw InputError("discretize: the level set has " + std::to_string(phi.size()) + " values for " +
                     std::to_string(mesh.n_vertices()) + " vertices");
  ScalarField value = phi;
  if (!options.grown_from.empty() && options.grown_from.size() != mesh.n_vertices())
    throw InputError("discretize: grown_from has " + std::to_string(options.grown_from.size()) + " values for " +
                     std::to_string(mesh.n_vertices()) + " vertices");
  const double h_input = options.speck_area > 0 || !options.grown_from.empty() ? edge_length_stats(mesh).mean : 0;
  // Vertices that may end up on the level set: the input's zeros and the ends of crossed edges
  // (snapped); the cut adds its new vertices. The faces around them are the speck search's seeds.
  const int not_finite = reduce(
      int(mesh.n_vertices()), std::numeric_limits<int>::max(),
      [&](int v, int& first) {
        if (first > v && !std::isfinite(value[std::size_t(v)]) && !mesh.status(VertexHandle(v)).deleted()) first = v;
      },
      [](int& total, int part) { total = std::min(total, part); });
  if (not_finite != std::numeric_limits<int>::max())
    throw InputError("discretize: the level set is not finite at vertex " + std::to_string(not_finite));
  std::vector<VertexHandle> may_be_zero = zeros(mesh, value);

  const bool find_parts = options.speck_area > 0 || !options.grown_from.empty();
  const std::vector<EdgeHandle> crossed = crossed_edges(mesh, value, options, find_parts, may_be_zero, report);
  const std::vector<QuadCut> quads = cut_quads(mesh, value, crossed, report);
  report.crossed_edges = crossed.size();

  const int first_crossing = int(mesh.n_vertices());
  split_crossed_edges(mesh, value, crossed, CrossingSlopes(mesh, phi, crossed, options, report), options);
  report.inserted_vertices = crossed.size();
  auto crossing = [&](int edge_index) {
    auto it = std::lower_bound(crossed.begin(), crossed.end(), EdgeHandle(edge_index));
    return VertexHandle(first_crossing + int(it - crossed.begin()));
  };
  for (const auto& quad : quads)
    if (improve_diagonal(mesh, crossing(quad.edge_ab), quad.b, quad.c, crossing(quad.edge_ca)))
      ++report.flipped_diagonals;

  label_faces(mesh, value);
  if (find_parts) {
    std::vector<FaceHandle> seeds;
    auto seed_around = [&](VertexHandle v) {
      if (value[v.idx()] == 0)
        for (auto f : mesh.vf_range(v)) seeds.push_back(f);
    };
    for (auto v : may_be_zero) seed_around(v);
    for (int v = first_crossing; v < int(mesh.n_vertices()); ++v) seed_around(VertexHandle(v));
    if (!options.grown_from.empty()) report.removed_detached = remove_detached(mesh, value, options.grown_from, seeds, 1e-12 * h_input);
    if (options.speck_area > 0)
      report.removed_specks = remove_specks(mesh, value, options.speck_area * h_input * h_input, std::move(seeds));
  }
  report.inside_faces = reduce(
      int(mesh.n_faces()), std::size_t(0),
      [&](int f, std::size_t& count) { count += !mesh.status(FaceHandle(f)).deleted() && mesh.region(FaceHandle(f)) == kInside; },
      [](std::size_t& total, std::size_t part) { total += part; });
  for_each_index(int(mesh.n_vertices()), [&](int v) { mesh.phi(VertexHandle(v)) = value[std::size_t(v)]; });
  tag_interface(mesh, report);
  collect_deleted(mesh);
  return report;
}

}  // namespace bodyfit
