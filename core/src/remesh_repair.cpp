// Remesher: the sliver repair after the passes, and the report of degenerate triangles.
#include "remesher.hpp"

#include <bodyfit/height_field.hpp>
#include <bodyfit/self_intersections.hpp>

namespace bodyfit::remesh_detail {

// Whether the cap (a, b, c) of the halfedge h = a→b, whose apex c lies on its own feature edge ab,
// is repaired by flipping ab. Nothing else can repair such a cap when c cannot move (an interface
// vertex on a ridge, a required vertex: no collapse, no relocation) and a, b slide only along ab.
// The flip to cd (d opposite ab in the other face) splits that face at c into (a, d, c) and
// (c, d, b), in its own plane; the feature runs a-c-b, through the same points (feature_flip).
bool Remesher::feature_flip_check(HalfedgeHandle h, Change& change) const {
  auto e = m_.edge_handle(h);
  if (m_.is_boundary(h) || m_.is_boundary(e) || m_.property(ecurve_, e) == kNoCurve) return false;
  auto o = m_.opposite_halfedge_handle(h);
  auto hn = m_.next_halfedge_handle(h);
  // The cap's other sides become the two halves of ab: they must carry no feature of their own.
  if (m_.property(ecurve_, m_.edge_handle(hn)) != kNoCurve ||
      m_.property(ecurve_, m_.edge_handle(m_.next_halfedge_handle(hn))) != kNoCurve)
    return false;
  auto a = m_.from_vertex_handle(h), b = m_.to_vertex_handle(h);
  auto c = m_.to_vertex_handle(hn), d = m_.to_vertex_handle(m_.next_halfedge_handle(o));
  const Vec3 &pa = m_.point(a), &pb = m_.point(b), &pc = m_.point(c), &pd = m_.point(d);
  const Vec3 ab = pb - pa;
  const double l2 = ab.sqrnorm();
  if (l2 <= 0) return false;
  const double t = ((pc - pa) | ab) / l2;
  if (!(t > 0 && t < 1) || (pa + ab * t - pc).norm() > kOnFeatureEdge * std::sqrt(l2)) return false;
  if (!const_cast<SurfaceMesh&>(m_).is_flip_ok(e)) return false;
  auto other = triangle(pb, pa, pd), t0 = triangle(pa, pd, pc), t1 = triangle(pb, pc, pd);
  change.old_min = std::min(triangle(pa, pb, pc).quality, other.quality);
  change.new_min = std::min(t0.quality, t1.quality);
  if (change.new_min <= change.old_min + 1e-3) return false;
  // The halves lie in the plane of the face they split (c is on its side ab).
  if ((t0.normal | other.normal) < kFlipFlatness || (t1.normal | other.normal) < kFlipFlatness) return false;
  const std::array<std::array<VertexHandle, 3>, 2> after{{{a, d, c}, {b, c, d}}};
  const std::array<FaceHandle, 2> replaced{m_.face_handle(h), m_.face_handle(o)};
  return !folds(after, replaced);
}

void Remesher::feature_flip(HalfedgeHandle h) {
  auto e = m_.edge_handle(h);
  auto o = m_.opposite_halfedge_handle(h);
  auto a = m_.from_vertex_handle(h), b = m_.to_vertex_handle(h);
  auto c = m_.to_vertex_handle(m_.next_halfedge_handle(h)), d = m_.to_vertex_handle(m_.next_halfedge_handle(o));
  const bool interface = m_.interface(e), ridge = m_.ridge(e), required = m_.required(e);
  const int ref = m_.edge_ref(e);
  const char curve = m_.property(ecurve_, e);
  const int region = m_.region(m_.face_handle(o));  // both new faces lie in the face (b, a, d)
  m_.flip(e);  // e now joins c and d
  m_.interface(e) = 0;
  m_.ridge(e) = 0;
  m_.required(e) = 0;
  m_.edge_ref(e) = 0;
  m_.property(ecurve_, e) = kNoCurve;
  for (auto w : {a, b}) {
    auto half = m_.edge_handle(m_.find_halfedge(c, w));
    m_.interface(half) = interface;
    m_.ridge(half) = ridge;
    m_.required(half) = required;
    m_.edge_ref(half) = ref;
    m_.property(ecurve_, half) = curve;
  }
  for (auto hh : {m_.halfedge_handle(e, 0), m_.halfedge_handle(e, 1)}) m_.region(m_.face_handle(hh)) = region;
  if (curve == kInterfaceCurve) m_.phi(c) = 0;
  classify_vertex(c);  // a vertex of the curve now (or locked, where it already had other features)
  ++report_.flips;
  for (auto v : {a, b, c, d}) mark_fresh(v);
}


// Sliver repair, after the passes: each triangle still below kRepairBelow, worst first, gets the
// local operation that most raises the worst quality around it (a collapse of one of its edges,
// a flip, or a move of one of its vertices to one of a few candidate points). Unlike the passes,
// which keep every new triangle above kAcceptQuality, this accepts any strict improvement: it is
// what untangles clusters of slivers where every single step of the passes would be refused.
// Returns the number of repairs; the first round starts from the faces final_sweep() found.
std::size_t Remesher::repair_slivers() {
  std::size_t total = 0;
  std::vector<std::pair<double, FaceHandle>> bad = std::move(slivers_);
  for (int round = 0; round < kRepairRounds; ++round) {
    if (round > 0)
      bad = collect<std::pair<double, FaceHandle>>(int(m_.n_faces()), [&](int i, auto& item) {
        FaceHandle f(i);
        if (m_.status(f).deleted()) return false;
        auto p = points(f);
        item = {triangle_quality(p[0], p[1], p[2]), f};
        return item.first < kRepairBelow;
      });
    std::sort(bad.begin(), bad.end(),
              [](const auto& x, const auto& y) { return x.first != y.first ? x.first < y.first : x.second.idx() < y.second.idx(); });
    std::size_t repaired = 0;
    for (auto [q, f] : bad)
      if (!m_.status(f).deleted() && face_quality(m_, f) < kRepairBelow && repair(f)) ++repaired;
    total += repaired;
    if (repaired == 0) break;
  }
  return total;
}

bool Remesher::repair(FaceHandle f) {
  enum class Op { None, Collapse, Flip, FeatureFlip, Move } best_op = Op::None;
  double best = 0;
  HalfedgeHandle best_h;
  VertexHandle best_v;
  Vec3 best_q;
  SurfacePoint best_sp;
  auto consider = [&](const Change& c) { return c.new_min > c.old_min + 1e-3 && c.new_min > best; };
  for (auto h : m_.fh_range(f)) {
    for (auto hh : {h, m_.opposite_halfedge_handle(h)}) {
      Change c;
      if (collapse_check(hh, c, Rule::Repair) && consider(c)) {
        best = c.new_min;
        best_op = Op::Collapse;
        best_h = hh;
      }
    }
    Change c;
    if (flip_check(m_.edge_handle(h), c, Rule::Repair) && consider(c)) {
      best = c.new_min;
      best_op = Op::Flip;
      best_h = h;
    }
    Change cf;
    if (feature_flip_check(h, cf) && consider(cf)) {
      best = cf.new_min;
      best_op = Op::FeatureFlip;
      best_h = h;
    }
  }
  for (auto v : m_.fv_range(f)) {
    char kind = m_.property(kind_, v);
    std::vector<Vec3> targets;
    if (kind == kFreeVertex) {
      // The centroid of the ring, and the apex of the equilateral triangle on the opposite edge.
      targets.push_back(ring_centroid(v));
      auto h = m_.next_halfedge_handle(m_.halfedge_handle(f));
      while (m_.from_vertex_handle(h) == v || m_.to_vertex_handle(h) == v) h = m_.next_halfedge_handle(h);
      const Vec3 &a = m_.point(m_.from_vertex_handle(h)), &b = m_.point(m_.to_vertex_handle(h));
      Vec3 side = m_.property(vnormal_, v) % (b - a);
      targets.push_back((a + b) * 0.5 + side * (std::sqrt(3.0) / 2));
    } else if (kind == kCurveVertex) {
      // Points along the curve between its two neighbours.
      auto ends = curve_neighbours(v);
      if (!ends) continue;
      const Vec3 &a = m_.point(ends->first), &b = m_.point(ends->second);
      for (double t : {0.2, 0.35, 0.5, 0.65, 0.8}) targets.push_back(project_on_curve(a + (b - a) * t, m_.property(vcurve_, v)));
    }
    for (const auto& target : targets) {
      Vec3 q;
      SurfacePoint sp;
      Change c;
      if (place(v, target, q, sp) && move_check(v, q, sp.normal, c) && consider(c)) {
        best = c.new_min;
        best_op = Op::Move;
        best_v = v;
        best_q = q;
        best_sp = sp;
      }
    }
  }
  switch (best_op) {
    case Op::Collapse: collapse_halfedge(best_h); return true;
    case Op::Flip: flip_edge(m_.edge_handle(best_h)); return true;
    case Op::FeatureFlip: feature_flip(best_h); return true;
    case Op::Move: move_vertex(best_v, best_q, best_sp); return true;
    case Op::None: return false;
  }
  return false;
}

// Triangles on the two sides of a sharp crease of a triangle reference may cross where a vertex
// sits next to the crease (no check of the passes looks beyond a triangle's neighbours), and an
// input may cross itself. Each crossing pair near a vertex this remesh queued or moved gets the sliver repair's best operation on either
// triangle, for a few rounds; the pairs left are reported (RemeshReport::self_intersections), never
// silently returned.
void Remesher::repair_self_intersections() {
  // A height field (a landscape, a shallow cap) cannot cross itself: a sweep of its faces and of its
  // boundary settles it, where the search costs a tenth of the remesh.
  if (is_height_field(m_)) return;
  // Only near what this remesh changed: a sweep of the whole surface's grid would cost more than an
  // evolution step's whole remesh (175 ms on a 240k-face height field against 50).
  std::vector<int> changed;
  auto near_changes = [&] {
    changed.clear();  // a face may come several times: self_intersections_near takes it once
    for (auto v : touched_list_)
      if (!m_.status(v).deleted())
        for (auto f : m_.vf_range(v)) changed.push_back(f.idx());
    return self_intersections_near(m_, changed);
  };
  std::vector<std::pair<int, int>> pairs = near_changes();
  for (int round = 0; round < kRepairRounds && !pairs.empty(); ++round) {
    std::size_t repaired = 0;
    for (auto [f, g] : pairs)
      for (int face : {f, g})
        if (!m_.status(FaceHandle(face)).deleted() && repair(FaceHandle(face))) ++repaired;
    if (repaired == 0) break;
    final_sweep();
    pairs = near_changes();

  }
  report_.self_intersections = pairs.size();
  if (!pairs.empty()) {
    const auto p = points(FaceHandle(pairs.front().first));
    const Vec3 at = (p[0] + p[1] + p[2]) / 3.0;
    spdlog::warn("remesh: {} pair(s) of triangles intersect (faces {} and {}, near ({:.6g}, {:.6g}, {:.6g})); no local "
                 "operation could separate them",
                 pairs.size(), pairs.front().first, pairs.front().second, at[0], at[1], at[2]);
  }
}

// Every operation refuses degenerate triangles and the repair removes those of its input it can: a
// remaining one (a configuration no local operation repairs) is reported, never silently returned.
void Remesher::report_degenerate() const {
  if (degenerate_ > 0)
    spdlog::warn("remesh: {} degenerate triangle(s) left (smallest area {:.3g}, near ({:.6g}, {:.6g}, {:.6g})); no local "
                 "operation could repair them",
                 degenerate_, degenerate_area_, degenerate_at_[0], degenerate_at_[1], degenerate_at_[2]);
}

}  // namespace bodyfit::remesh_detail
