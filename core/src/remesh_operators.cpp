// Remesher: the local operators — split, collapse, flip, relocation — and their checks.
#include "remesher.hpp"

namespace bodyfit::remesh_detail {

bool Remesher::split(EdgeHandle e, const SurfacePoint* projected) {
  char curve = m_.property(ecurve_, e);
  if (curve == kRequiredCurve) return false;
  auto h0 = m_.halfedge_handle(e, 0), h1 = m_.halfedge_handle(e, 1);
  auto a = m_.from_vertex_handle(h0), b = m_.to_vertex_handle(h0);
  Vec3 p = (m_.point(a) + m_.point(b)) * 0.5;
  if (curve != kNoCurve) p = project_on_curve(p, curve);
  const SurfacePoint sp = projected ? *projected : ref_->closest(p, m_.property(hint_, a));
  if (curve != kBoundaryCurve || ref_->analytic()) p = sp.point;

  // The two (or one) opposite vertices and their face regions; the new point must not fold them.
  VertexHandle opposite[2];
  int region[2] = {0, 0};
  std::array<FaceHandle, 2> replaced;
  std::array<std::array<VertexHandle, 3>, 4> after;  // the new vertex is the invalid handle, at p
  std::size_t n_replaced = 0, n_after = 0;
  Change change;
  for (int s = 0; s < 2; ++s) {
    auto h = s == 0 ? h0 : h1;
    if (m_.is_boundary(h)) continue;
    opposite[s] = m_.to_vertex_handle(m_.next_halfedge_handle(h));
    region[s] = m_.region(m_.face_handle(h));
    auto from = m_.from_vertex_handle(h), to = m_.to_vertex_handle(h);
    Vec3 o = m_.point(opposite[s]);
    auto old_tri = triangle(m_.point(from), m_.point(to), o);
    Vec3 n_old = old_tri.normal;
    if (n_old.sqrnorm() == 0) n_old = m_.property(vnormal_, a);
    auto t1 = triangle(m_.point(from), p, o), t2 = triangle(p, m_.point(to), o);
    if ((t1.normal | n_old) < 0.3 || (t2.normal | n_old) < 0.3) return false;
    change.old_min = std::min(change.old_min, old_tri.quality);
    change.new_min = std::min({change.new_min, t1.quality, t2.quality});
    replaced[n_replaced++] = m_.face_handle(h);
    after[n_after++] = {from, VertexHandle(), opposite[s]};
    after[n_after++] = {VertexHandle(), to, opposite[s]};
  }
  if (creates_near_degenerate(change) ||
      folds(std::span(after.data(), n_after), std::span(replaced.data(), n_replaced), VertexHandle(), p))
    return false;
  // Edge attributes carried by the two halves.
  bool interface = m_.interface(e), ridge = m_.ridge(e);
  int ref = m_.edge_ref(e);
  double size = 0.5 * (m_.property(size_, a) + m_.property(size_, b));
  double phi = curve == kInterfaceCurve ? 0.0 : 0.5 * (m_.phi(a) + m_.phi(b));

  auto v = m_.add_vertex(p);
  m_.split(e, v);
  m_.property(size_, v) = size;
  m_.property(kind_, v) = curve == kNoCurve ? kFreeVertex : kCurveVertex;
  m_.property(vcurve_, v) = curve;
  m_.property(hint_, v) = sp.face;
  m_.property(vnormal_, v) = sp.normal;
  m_.property(in_work_, v) = 0;
  m_.property(in_next_, v) = 0;
  m_.property(touched_, v) = 0;
  m_.phi(v) = phi;
  m_.vertex_ref(v) = 0;
  m_.corner(v) = 0;
  m_.required(v) = 0;
  for (auto h : m_.voh_range(v)) {
    auto ee = m_.edge_handle(h);
    auto w = m_.to_vertex_handle(h);
    bool half = w == a || w == b;
    m_.interface(ee) = half && interface;
    m_.ridge(ee) = half && ridge;
    m_.required(ee) = 0;
    m_.edge_ref(ee) = half ? ref : 0;
    m_.property(ecurve_, ee) = half ? curve : kNoCurve;
    if (!m_.is_boundary(h)) {
      auto f = m_.face_handle(h);
      for (auto u : m_.fv_range(f)) {
        if (opposite[0].is_valid() && u == opposite[0]) m_.region(f) = region[0];
        if (opposite[1].is_valid() && u == opposite[1]) m_.region(f) = region[1];
      }
    }
  }
  ++report_.splits;
  mark_ring(v);
  return true;
}

// Whether new triangles (replacing the faces `replaced`, with the vertex `moved` placed at `at`)
// fold onto a neighbour: a dihedral angle beyond 135° with an adjacent new triangle or an unchanged
// face. The per-triangle normal tests only bound how far each triangle turns from its own old
// normal, which on a strongly curved S (a steep height field at 400 m) lets it turn onto a neighbour.
bool Remesher::folds(std::span<const std::array<VertexHandle, 3>> triangles, std::span<const FaceHandle> replaced,
                     VertexHandle moved, const Vec3& at) const {
  auto position = [&](VertexHandle v) -> const Vec3& { return v == moved ? at : m_.point(v); };
  auto normal_of = [&](const std::array<VertexHandle, 3>& t) {
    return triangle(position(t[0]), position(t[1]), position(t[2])).normal;
  };
  std::vector<Vec3>& normals = normals_;
  normals.clear();
  for (const auto& t : triangles) normals.push_back(normal_of(t));
  // The sides of the replaced faces with the face across each: a side of a new triangle that no
  // other new triangle shares is one of them (read here instead of a find_halfedge per side).
  struct Side {
    VertexHandle from, to;
    HalfedgeHandle across;
  };
  constexpr std::size_t kMaxSides = 3 * 64;
  Side sides[kMaxSides];
  std::size_t n_sides = 0;
  for (auto f : replaced)
    for (auto h : m_.fh_range(f))
      if (n_sides < kMaxSides)
        sides[n_sides++] = {m_.from_vertex_handle(h), m_.to_vertex_handle(h), m_.opposite_halfedge_handle(h)};
  auto across = [&](VertexHandle u, VertexHandle w) -> HalfedgeHandle {
    for (std::size_t i = 0; i < n_sides; ++i)
      if (sides[i].from == u && sides[i].to == w) return sides[i].across;
    return m_.find_halfedge(w, u);
  };
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    if (normals[i].sqrnorm() == 0) continue;
    for (int k = 0; k < 3; ++k) {
      // The neighbour across u→w holds w→u: another new triangle, or else an unchanged face.
      VertexHandle u = triangles[i][k], w = triangles[i][(k + 1) % 3];
      Vec3 other(0, 0, 0);
      bool found = false;
      for (std::size_t j = 0; j < triangles.size() && !found; ++j)
        for (int l = 0; l < 3 && j != i; ++l)
          if (triangles[j][l] == w && triangles[j][(l + 1) % 3] == u) {
            other = normals[j];
            found = true;
            break;
          }
      if (!found) {
        if (!u.is_valid() || !w.is_valid()) continue;  // an edge of a vertex not yet in the mesh
        auto h = across(u, w);
        if (!h.is_valid() || m_.is_boundary(h)) continue;
        auto f = m_.face_handle(h);
        if (std::find(replaced.begin(), replaced.end(), f) != replaced.end()) continue;
        other = normal_of(vertices(f));
      }
      if (other.sqrnorm() > 0 && (normals[i] | other) < kFoldCos) return true;
    }
  }
  return false;
}

// Whether the point p of S stays within hausd of the triangles (vertex positions; `moved` at `at`).
// A point the change removes from the mesh (a collapsed vertex, the middle of a flipped diagonal
// projected on S, a relocated vertex's old place) measures how far the new triangles leave S there.
// Asked only against a reference made of triangles (RemeshOptions::check_distance_to_reference): on
// an analytic S the sizes from its exact curvature bound the sag, but the curvature estimated on a
// faceted CAD part or a scan misses the creases below the ridge angle, where triangles would cut
// across (docs/validation/real_meshes.md).
bool Remesher::near_surface(const Vec3& p, std::span<const std::array<VertexHandle, 3>> triangles, VertexHandle moved,
                            const Vec3& at) const {
  return !check_distance_ || distance_to(p, triangles, moved, at) <= hausd_;
}

double Remesher::distance_to(const Vec3& p, std::span<const std::array<VertexHandle, 3>> triangles, VertexHandle moved,
                             const Vec3& at) const {
  auto position = [&](VertexHandle v) -> const Vec3& { return v == moved ? at : m_.point(v); };
  double d2 = std::numeric_limits<double>::infinity();
  for (const auto& t : triangles)
    d2 = std::min(d2, (closest_point_on_triangle(p, position(t[0]), position(t[1]), position(t[2])) - p).sqrnorm());
  return std::sqrt(d2);
}

// How far the middle of the chord (a, b) is from S (0 when not checked): a new edge across a crease
// the sizes do not see would cut through the part.
double Remesher::chord_sag(VertexHandle near, const Vec3& a, const Vec3& b) const {
  if (!check_distance_) return 0;
  const Vec3 mid = (a + b) * 0.5;
  return (ref_->closest(mid, m_.property(hint_, near)).point - mid).norm();
}

// Whether the chord (a, b) replacing the chord (a_old, b_old) stays within hausd of S, or sags no
// more than the one it replaces. `faces`: reference triangles near the chord's ends; its middle
// within hausd of one of them, or of one of their neighbours, proves the first without searching S
// (the search would find no farther point: the margin is far above its rounding). On a 240k-face
// height field the neighbours settle five in six of the chords the faces themselves leave open.
bool Remesher::chord_within_hausd(VertexHandle near, const Vec3& a, const Vec3& b, const Vec3& a_old,
                                  const Vec3& b_old, std::initializer_list<int> faces) const {
  if (!check_distance_) return true;
  const Vec3 mid = (a + b) * 0.5;
  const double proof = hausd_ * (1 - 1e-9);
  for (int face : faces)
    if (ref_->distance_to_triangle(mid, face) <= proof) return true;
  for (int face : faces)
    if (ref_->distance_to_neighbours(mid, face) <= proof) return true;
  const double sag = chord_sag(near, a, b);
  return sag <= hausd_ || sag <= chord_sag(near, a_old, b_old);
}

// Whether the curve stays within hausd (the interface: hausd_interface) of the curve vertex v0 when
// it collapses along h onto v1: the new curve edge (u, v1), u the other curve neighbour of v0, must
// pass within that distance of v0.
bool Remesher::curve_collapse_within_hausd(HalfedgeHandle h) const {
  auto v0 = m_.from_vertex_handle(h), v1 = m_.to_vertex_handle(h);
  char curve = m_.property(vcurve_, v0);
  const double tolerance = curve == kInterfaceCurve ? interface_hausd_ : hausd_;
  for (auto hu : m_.voh_range(v0)) {
    auto u = m_.to_vertex_handle(hu);
    if (u == v1 || m_.property(ecurve_, m_.edge_handle(hu)) != curve) continue;
    const Vec3 &a = m_.point(u), &b = m_.point(v1), &p = m_.point(v0);
    Vec3 ab = b - a;
    double t = ab.sqrnorm() > 0 ? std::clamp(((p - a) | ab) / ab.sqrnorm(), 0.0, 1.0) : 0.0;
    if ((a + ab * t - p).norm() > tolerance) return false;
  }
  return true;
}

// OpenMesh's TriConnectivity::is_collapse_ok, the same tests in the same order, without its heap
// allocations (several per call: most of a collapse check's cost) and without tagging vertices.
bool Remesher::collapse_keeps_topology(HalfedgeHandle v0v1) const {
  if (m_.status(m_.edge_handle(v0v1)).deleted()) return false;
  const auto v1v0 = m_.opposite_halfedge_handle(v0v1);
  const auto v0 = m_.to_vertex_handle(v1v0), v1 = m_.to_vertex_handle(v0v1);
  if (m_.status(v0).deleted() || m_.status(v1).deleted()) return false;
  // Neither triangle on the edge may have its two other sides on the boundary.
  VertexHandle vl, vr;
  if (!m_.is_boundary(v0v1)) {
    const auto h1 = m_.next_halfedge_handle(v0v1), h2 = m_.next_halfedge_handle(h1);
    vl = m_.to_vertex_handle(h1);
    if (m_.is_boundary(m_.opposite_halfedge_handle(h1)) && m_.is_boundary(m_.opposite_halfedge_handle(h2))) return false;
  }
  if (!m_.is_boundary(v1v0)) {
    const auto h1 = m_.next_halfedge_handle(v1v0), h2 = m_.next_halfedge_handle(h1);
    vr = m_.to_vertex_handle(h1);
    if (m_.is_boundary(m_.opposite_halfedge_handle(h1)) && m_.is_boundary(m_.opposite_halfedge_handle(h2))) return false;
  }
  if (vl == vr) return false;
  // The one-rings of v0 and v1 meet only at vl and vr.
  VertexHandle ring[kMaxValence];
  int n = 0;
  for (auto w : m_.vv_range(v1)) {
    if (n == kMaxValence) return const_cast<SurfaceMesh&>(m_).is_collapse_ok(v0v1);  // a valence no remesh makes
    ring[n++] = w;
  }
  for (auto w : m_.vv_range(v0))
    if (w != vl && w != vr && std::find(ring, ring + n, w) != ring + n) return false;
  // An edge between two boundary vertices must be a boundary edge.
  return !(m_.is_boundary(v0) && m_.is_boundary(v1) && !m_.is_boundary(v0v1) && !m_.is_boundary(v1v0));
}

// Whether collapsing h (its from-vertex v0 onto its to-vertex v1) keeps features, topology and
// geometry (no fold, no edge made too long) and is worth it by `rule`; `change` receives the
// qualities of v0's star.
bool Remesher::collapse_check(HalfedgeHandle h, Change& change, Rule rule) const {
  auto v0 = m_.from_vertex_handle(h), v1 = m_.to_vertex_handle(h);
  auto e = m_.edge_handle(h);
  char kind = m_.property(kind_, v0);
  if (kind == kLockedVertex) return false;
  if ((kind == kCurveVertex || kind == kCornerVertex) && m_.property(ecurve_, e) != m_.property(vcurve_, v0)) return false;
  if (kind == kCornerVertex && length(e) > hausd_) return false;
  if (kind == kFreeVertex && m_.property(ecurve_, e) != kNoCurve) return false;
  // Two feature edges of a triangle cannot be merged into one.
  for (auto hh : {h, m_.opposite_halfedge_handle(h)}) {
    if (m_.is_boundary(hh)) continue;
    // The other two sides of the triangle on hh: (v0, vl) and (v1, vl), in either order.
    auto n1 = m_.next_halfedge_handle(hh);
    auto e0 = m_.edge_handle(n1), e1 = m_.edge_handle(m_.next_halfedge_handle(n1));
    if (m_.property(ecurve_, e0) != kNoCurve && m_.property(ecurve_, e1) != kNoCurve) return false;
  }
  if (!collapse_keeps_topology(h)) return false;
  if ((kind == kCurveVertex || kind == kCornerVertex) && !curve_collapse_within_hausd(h)) return false;
  const Vec3& p1 = m_.point(v1);
  double old_min = 1, new_min = 1;
  std::vector<FaceHandle>& star = star_;
  std::vector<std::array<VertexHandle, 3>>& after = after_;
  star.clear();
  after.clear();
  for (auto f : m_.vf_range(v0)) {
    star.push_back(f);
    auto pts = points(f);
    auto vs = vertices(f);
    auto old_tri = triangle(pts[0], pts[1], pts[2]);
    old_min = std::min(old_min, old_tri.quality);
    if (vs[0] == v1 || vs[1] == v1 || vs[2] == v1) continue;
    for (int k = 0; k < 3; ++k)
      if (vs[k] == v0) {
        pts[k] = p1;
        vs[k] = v1;
      }
    auto t = triangle(pts[0], pts[1], pts[2]);
    if (!keeps_facing(old_tri, t, m_.property(vnormal_, v0))) return false;
    new_min = std::min(new_min, t.quality);
    after.push_back({vs[0], vs[1], vs[2]});
  }
  if (rule == Rule::Pass ? new_min < std::min(kAcceptQuality, old_min) : new_min <= old_min + 1e-3) return false;
  for (auto w : m_.vv_range(v0)) {
    if (w == v1) continue;
    // No edge too long, unless it was already (the split pass deals with it).
    double l = (m_.point(w) - p1).norm();
    if (l > kSplitRatio * target(v1, w) && l > (m_.point(w) - m_.point(v0)).norm()) return false;
  }
  if (folds(after, star)) return false;
  if (!near_surface(m_.point(v0), after)) return false;
  for (auto w : m_.vv_range(v0))
    if (w != v1 && !chord_within_hausd(v1, p1, m_.point(w), m_.point(v0), m_.point(w),
                                       {m_.property(hint_, v1), m_.property(hint_, w)}))
      return false;
  change.old_min = old_min;
  change.new_min = new_min;
  return true;
}

bool Remesher::collapse(EdgeHandle e) {
  auto h0 = m_.halfedge_handle(e, 0), h1 = m_.halfedge_handle(e, 1);
  Change c0, c1;
  bool ok0 = collapse_check(h0, c0, Rule::Pass), ok1 = collapse_check(h1, c1, Rule::Pass);
  if (!ok0 && !ok1) return false;
  auto hc = (ok0 && (!ok1 || c0.new_min >= c1.new_min)) ? h0 : h1;
  collapse_halfedge(hc);
  return true;
}

void Remesher::collapse_halfedge(HalfedgeHandle h) {
  auto v1 = m_.to_vertex_handle(h);
  // The edges (v0, vl) and (v1, vl) of each removed triangle merge: keep the union of their tags.
  struct Merge {
    VertexHandle vl;
    bool interface, ridge, required;
    int ref;
    char curve;
  };
  std::array<Merge, 2> merges;
  int n_merges = 0;
  for (auto hh : {h, m_.opposite_halfedge_handle(h)}) {
    if (m_.is_boundary(hh)) continue;
    auto n1 = m_.next_halfedge_handle(hh), n2 = m_.next_halfedge_handle(n1);
    auto vl = m_.to_vertex_handle(n1);
    auto e0 = m_.edge_handle(n1), e1 = m_.edge_handle(n2);  // the two other sides, in either order
    merges[std::size_t(n_merges++)] = {vl, m_.interface(e0) || m_.interface(e1), m_.ridge(e0) || m_.ridge(e1),
                                       m_.required(e0) || m_.required(e1), std::max(m_.edge_ref(e0), m_.edge_ref(e1)),
                                       std::max(m_.property(ecurve_, e0), m_.property(ecurve_, e1))};
  }
  m_.collapse(h);
  for (int i = 0; i < n_merges; ++i) {
    const Merge& mg = merges[std::size_t(i)];
    auto hh = m_.find_halfedge(v1, mg.vl);
    if (!hh.is_valid()) continue;
    auto ee = m_.edge_handle(hh);
    m_.interface(ee) = mg.interface;
    m_.ridge(ee) = mg.ridge;
    m_.required(ee) = mg.required;
    m_.edge_ref(ee) = mg.ref;
    m_.property(ecurve_, ee) = mg.curve;
  }
  ++report_.collapses;
  mark_ring(v1);
}

bool Remesher::flip(EdgeHandle e) {
  Change change;
  if (!flip_check(e, change, Rule::Pass)) return false;
  flip_edge(e);
  return true;
}

namespace {

// The worse of the two triangles on an edge a → b, c and d across it: the pair a flip replaces.
double pair_quality(const Vec3& pa, const Vec3& pb, const Vec3& pc, const Vec3& pd) {
  return std::min(triangle(pa, pb, pc).quality, triangle(pb, pa, pd).quality);
}

}  // namespace

// Whether flip_check (Rule::Pass) looks past its first test: a free edge between two faces whose
// pair has a triangle below kFlipBelow.
bool Remesher::may_flip(EdgeHandle e) const {
  if (m_.status(e).deleted() || m_.property(ecurve_, e) != kNoCurve || m_.is_boundary(e)) return false;
  auto h0 = m_.halfedge_handle(e, 0), h1 = m_.halfedge_handle(e, 1);
  return pair_quality(m_.point(m_.from_vertex_handle(h0)), m_.point(m_.to_vertex_handle(h0)),
                      m_.point(m_.to_vertex_handle(m_.next_halfedge_handle(h0))),
                      m_.point(m_.to_vertex_handle(m_.next_halfedge_handle(h1)))) < kFlipBelow;
}

// Whether flipping e keeps the pair flat on S and is worth it by `rule`; `change` receives the
// qualities of the two pairs.
bool Remesher::flip_check(EdgeHandle e, Change& change, Rule rule) const {
  if (m_.property(ecurve_, e) != kNoCurve || m_.is_boundary(e)) return false;
  auto h0 = m_.halfedge_handle(e, 0), h1 = m_.halfedge_handle(e, 1);
  auto a = m_.from_vertex_handle(h0), b = m_.to_vertex_handle(h0);
  auto c = m_.to_vertex_handle(m_.next_halfedge_handle(h0));
  auto d = m_.to_vertex_handle(m_.next_halfedge_handle(h1));
  const Vec3 &pa = m_.point(a), &pb = m_.point(b), &pc = m_.point(c), &pd = m_.point(d);
  change.old_min = pair_quality(pa, pb, pc, pd);
  // Only pairs with a poor triangle are worth changing in the passes: a good mesh stays as it is
  // (decided before the new pair is computed: most pairs a pass looks at are good).
  if (rule == Rule::Pass && change.old_min >= kFlipBelow) return false;
  auto t0 = triangle(pa, pd, pc), t1 = triangle(pb, pc, pd);
  change.new_min = std::min(t0.quality, t1.quality);
  if (change.new_min <= change.old_min + 1e-3) return false;
  // No new edge above the split bound (unless no longer than the one it replaces).
  if (lengthens_beyond_split(c, d, (pd - pc).norm(), (pb - pa).norm())) return false;
  // The link condition (cd not already an edge) last: it walks a vertex ring.
  if (!const_cast<SurfaceMesh&>(m_).is_flip_ok(e)) return false;
  // The new pair must lie flat on S (no fold, no shortcut across curvature).
  Vec3 n = m_.property(vnormal_, a) + m_.property(vnormal_, b) + m_.property(vnormal_, c) + m_.property(vnormal_, d);
  double len = n.norm();
  if (len <= 0) return false;
  n /= len;
  const double min_cos = rule == Rule::Pass ? kFlipFlatness : kRepairFlatness;
  if ((t0.normal | n) < min_cos || (t1.normal | n) < min_cos) return false;
  const std::array<std::array<VertexHandle, 3>, 2> after{{{a, d, c}, {b, c, d}}};
  const std::array<FaceHandle, 2> replaced{m_.face_handle(h0), m_.face_handle(h1)};
  if (folds(after, replaced)) return false;
  // The diagonal's middle on S: the new pair must pass within hausd of it (or nearer than the old).
  if (check_distance_) {
    const Vec3 q = ref_->closest((pa + pb) * 0.5, m_.property(hint_, a)).point;
    const std::array<std::array<VertexHandle, 3>, 2> before{{{a, b, c}, {b, a, d}}};
    const double now = distance_to(q, after);
    if (now > hausd_ && now > distance_to(q, before)) return false;
    if (!chord_within_hausd(c, pc, pd, pa, pb, {m_.property(hint_, c), m_.property(hint_, d)})) return false;
  }
  return true;
}

void Remesher::flip_edge(EdgeHandle e) {
  auto h0 = m_.halfedge_handle(e, 0), h1 = m_.halfedge_handle(e, 1);
  VertexHandle quad[4] = {m_.from_vertex_handle(h0), m_.to_vertex_handle(h0),
                          m_.to_vertex_handle(m_.next_halfedge_handle(h0)), m_.to_vertex_handle(m_.next_halfedge_handle(h1))};
  m_.flip(e);
  ++report_.flips;
  for (auto v : quad) mark_fresh(v);
}

// Smooth v: its ring's centroid in its tangent plane (a curve vertex: its curve neighbours' middle
// on the curve), projected onto S, when the move is legal and improves v's star. Returns how far v
// went, negative when it stays. Reads the places of v's ring and of the far corners of the triangles
// across the ring's sides, the hint faces of v and its ring, and writes only v's place, hint face
// and normal: relocate_in_waves runs it from several threads on that contract.
double Remesher::relocate(VertexHandle v) {
  constexpr double kStays = -1;
  char kind = m_.property(kind_, v);
  if (kind == kLockedVertex || kind == kCornerVertex || m_.is_isolated(v)) return kStays;
  const Vec3 p = m_.point(v);
  Vec3 target(0, 0, 0);
  if (kind == kFreeVertex) {
    const Vec3& nv = m_.property(vnormal_, v);
    Vec3 d = ring_centroid(v) - p;
    target = p + d - nv * (d | nv);
  } else {
    auto ends = curve_neighbours(v);
    if (!ends) return kStays;
    target = project_on_curve((m_.point(ends->first) + m_.point(ends->second)) / 2.0, m_.property(vcurve_, v));
  }
  Vec3 q;
  SurfacePoint sp;
  Change change;
  if (!place(v, target, q, sp) || !move_check(v, q, sp.normal, change) || move_lengthens(v, q)) return kStays;
  if (check_distance_) {
    std::array<std::array<VertexHandle, 3>, kMaxValence> star;  // move_check refused a larger valence
    std::size_t n = 0;
    for (auto h : m_.voh_range(v))
      if (!m_.is_boundary(h)) star[n++] = {v, m_.to_vertex_handle(h), m_.to_vertex_handle(m_.next_halfedge_handle(h))};
    if (!near_surface(p, std::span(star.data(), n), v, q)) return kStays;
    for (auto w : m_.vv_range(v))
      if (!chord_within_hausd(v, q, m_.point(w), p, m_.point(w), {sp.face, m_.property(hint_, w), m_.property(hint_, v)}))
        return kStays;
  }
  // Curve vertices move only to repair a poor triangle: a point between the reference curve's
  // vertices lies on a chord, off the true curve by up to h²κ/8.
  if (kind == kCurveVertex && change.old_min >= kCurveRepairQuality) return kStays;
  // A better worst triangle, or (trading a little of it for the others) a better sum when every
  // triangle stays ≥ 0.6 — but not for a star already good everywhere: smoothing it would only lower
  // its worst triangle towards the others.
  bool better = change.new_min >= change.old_min ||
                (change.new_min >= 0.6 && change.old_min < kSmoothBelow && change.new_sum > change.old_sum);
  if (!better) return kStays;
  set_place(v, q, sp);
  return (q - p).norm();
}

std::optional<std::pair<VertexHandle, VertexHandle>> Remesher::curve_neighbours(VertexHandle v) const {
  char curve = m_.property(vcurve_, v);
  VertexHandle ends[2];
  int n = 0;
  for (auto h : m_.voh_range(v))
    if (m_.property(ecurve_, m_.edge_handle(h)) == curve) {
      if (n < 2) ends[n] = m_.to_vertex_handle(h);
      ++n;
    }
  if (n != 2) return std::nullopt;
  return std::pair{ends[0], ends[1]};
}

// Where v goes for a target point: its projection onto S (a boundary vertex of a non-analytic
// surface stays on its polyline). False for a move too small to matter.
bool Remesher::place(VertexHandle v, const Vec3& target, Vec3& q, SurfacePoint& sp) const {
  const double small = 1e-3 * m_.property(size_, v);
  const Vec3& p = m_.point(v);
  const bool on_polyline = m_.property(kind_, v) == kCurveVertex && m_.property(vcurve_, v) == kBoundaryCurve && !ref_->analytic();
  // A move too small is often known before the search (a third of the relocations of a remesh to
  // a size): S's closest point to the target is no farther from it than the triangle v lies on,
  // so it is within |target − p| plus that distance of p. The slack is far above the rounding.
  const double reach = (target - p).norm() + (on_polyline ? 0.0 : ref_->distance_to_triangle(target, m_.property(hint_, v)));
  if (reach + 1e-11 * (reach + std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])})) < small) return false;
  sp = ref_->closest(target, m_.property(hint_, v));
  q = on_polyline ? target : sp.point;
  return (q - p).norm() >= small;
}

// Whether moving v to q folds none of its triangles (normal: S's normal at q); `change` receives
// the qualities of v's star.
bool Remesher::move_check(VertexHandle v, const Vec3& q, const Vec3& normal, Change& change) const {
  change = Change{};
  // The star of v, one spoke per outgoing halfedge h: its face (if any) is (v, w1, w2), w1 = to(h),
  // w2 = to(next(h)); the face across (w2, w1) is unchanged by the move.
  Vec3 moved_normal[kMaxValence];
  HalfedgeHandle spoke[kMaxValence];
  int n = 0;
  const Vec3& p = m_.point(v);
  for (auto h : m_.voh_range(v)) {
    if (n == kMaxValence) return false;  // no such valence in a mesh worth relocating in
    spoke[n] = h;
    Vec3& moved = moved_normal[n++];
    moved = Vec3(0, 0, 0);
    if (m_.is_boundary(h)) continue;
    auto h2 = m_.next_halfedge_handle(h);
    const Vec3 &w1 = m_.point(m_.to_vertex_handle(h)), &w2 = m_.point(m_.to_vertex_handle(h2));
    auto old_tri = triangle(p, w1, w2), t = triangle(q, w1, w2);
    if (!keeps_facing(old_tri, t, normal)) return false;
    change.old_min = std::min(change.old_min, old_tri.quality);
    change.new_min = std::min(change.new_min, t.quality);
    change.old_sum += old_tri.quality;
    change.new_sum += t.quality;
    moved = t.normal;
    // No fold (folds(), specialised to a star): against the unchanged face across (w2, w1)...
    auto outer = m_.opposite_halfedge_handle(h2);
    if (moved.sqrnorm() > 0 && !m_.is_boundary(outer)) {
      const Vec3& x = m_.point(m_.to_vertex_handle(m_.next_halfedge_handle(outer)));
      Vec3 other = (w1 - w2) % (x - w2);
      double len = other.norm();
      if (len > 0 && (moved | other) < kFoldCos * len) return false;
    }
  }
  if (creates_near_degenerate(change)) return false;
  // ... and against the moved face across (v, w1), the one whose spoke follows the opposite halfedge.
  for (int i = 0; i < n; ++i) {
    if (moved_normal[i].sqrnorm() == 0) continue;
    auto across = m_.opposite_halfedge_handle(spoke[i]);
    if (m_.is_boundary(across)) continue;
    auto next_spoke = m_.next_halfedge_handle(across);
    // The circulator visits the spokes in that order: the next one is usually at i + 1.
    int j = (i + 1) % n;
    if (spoke[j] != next_spoke)
      for (j = 0; j < n && spoke[j] != next_spoke; ++j) {
      }
    if (j < n && moved_normal[j].sqrnorm() > 0 && (moved_normal[i] | moved_normal[j]) < kFoldCos) return false;
  }
  return true;
}

// Whether moving v to q would take one of its edges above the split bound (when it was not longer
// before): the passes after the split phase keep every edge below it.
bool Remesher::move_lengthens(VertexHandle v, const Vec3& q) const {
  const Vec3& p = m_.point(v);
  for (auto w : m_.vv_range(v)) {
    const Vec3& pw = m_.point(w);
    if (lengthens_beyond_split(v, w, (pw - q).norm(), (pw - p).norm())) return true;
  }
  return false;
}

void Remesher::move_vertex(VertexHandle v, const Vec3& q, const SurfacePoint& sp) {
  touch(v);
  set_place(v, q, sp);
  ++report_.relocations;
}

}  // namespace bodyfit::remesh_detail
