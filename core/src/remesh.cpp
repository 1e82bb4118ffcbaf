// Interface-preserving adaptive remeshing: split / collapse / flip / relocate driven by a sizing
// field, on a work queue of "active" vertices so that the cost follows the part of the mesh that
// needs change. See docs/validation/remeshing.md for the algorithm and its defaults.
#include <bodyfit/remesh.hpp>

#include <bodyfit/geometry.hpp>
#include <bodyfit/projection.hpp>

#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <queue>
#include <vector>

namespace bodyfit {

namespace {

// Kinds of feature curves an edge can belong to (the label of the reference polyline).
constexpr char kNoCurve = 0, kInterfaceCurve = 1, kRidgeCurve = 2, kBoundaryCurve = 3, kRequiredCurve = 4;
// Vertex kinds: free on S, sliding along one feature curve, a corner of one curve (it turns by
// more than the corner angle there: it does not move, but may merge with a curve neighbour closer
// than hausd), locked (curve ends and junctions, required, isolated).
constexpr char kFreeVertex = 0, kCurveVertex = 1, kLockedVertex = 2, kCornerVertex = 3;

// Edge length window relative to the target size (as MMG's metric lengths): split above √2,
// collapse below 1/√2, so that a mesh whose edges are within ±30 % of the target is left alone.
constexpr double kSplitRatio = 1.41;
constexpr double kCollapseRatio = 0.71;
// Faces of quality below this start the work queue (a geodesic sphere is ≥ 0.7 everywhere).
constexpr double kGoodQuality = 0.6;
// A collapse may create triangles down to this quality (never below the worst one it removes).
constexpr double kAcceptQuality = 0.4;
// Curve vertices are relocated only when one of their triangles is below this quality.
constexpr double kCurveRepairQuality = 0.6;
// Flips are tried only when the worse triangle of the pair is below this quality.
constexpr double kFlipBelow = 0.75;
// Below this quality a triangle's normal says little about S (keeps_facing).
constexpr double kReliableNormal = 0.1;
// A flip's two new triangles must be within 20° of the mean vertex normal (within 45° for repairs,
// the bound of collapses and moves).
constexpr double kFlipFlatness = 0.9396926207859084, kRepairFlatness = 0.7;
// No operation may leave two adjacent triangles whose normals are further apart than 135°
// (validate_mesh reports 160° as a fold).
constexpr double kFoldCos = -0.7071067811865476;
// Triangles still below this quality after the passes go to the sliver repair, for at most
// kRepairRounds sweeps.
constexpr double kRepairBelow = 0.3;
constexpr int kRepairRounds = 5;
// Relocation spreads at most this many rings away from a topological change or a bad element.
constexpr char kSmoothRings = 3;
// A relocation moving a vertex by more than this fraction of its size re-queues its ring.
constexpr double kMoveSpread = 0.05;
// A triangle whose doubled area is at most this fraction of its summed squared edge lengths is
// degenerate: its cross product is rounding noise, so its "normal" may point anywhere (and pass any
// orientation test by chance). It gets no normal and quality 0, which every check refuses.
constexpr double kDegenerateArea = 1e-10;
// No change may create a near-degenerate triangle: the worst triangle it makes stays above this
// quality, or above half the worst one it replaces when that was already below it (the tests of the
// passes and of the repair imply this; splits and the projection of the interface onto S check it).
constexpr double kNearDegenerate = 1e-3;
// A cap (a, b, c) whose apex c lies on its own feature edge ab, within this fraction of |ab|, is
// repaired by flipping ab: the feature then runs a-c-b, through the same points.
constexpr double kOnFeatureEdge = 1e-6;
// After remesh, a triangle of area below this times max(its longest edge, hmin)² is reported.
constexpr double kReportArea = 1e-12;

struct Tri {
  double quality = 0;
  Vec3 normal{0, 0, 0};  // unit, zero if degenerate
};

Tri triangle(const Vec3& a, const Vec3& b, const Vec3& c) {
  Tri t;
  Vec3 n = (b - a) % (c - a);
  double twice_area = n.norm();
  double l2 = (b - a).sqrnorm() + (c - b).sqrnorm() + (a - c).sqrnorm();
  if (l2 > 0 && twice_area > kDegenerateArea * l2) {
    t.normal = n / twice_area;
    t.quality = 2.0 * std::sqrt(3.0) * twice_area / l2;
  }
  return t;
}

// What a candidate local operation does to the triangles it changes: their worst (and summed)
// quality before and after.
struct Change {
  double old_min = 1, new_min = 1, old_sum = 0, new_sum = 0;
};

bool creates_near_degenerate(const Change& change) {
  return change.new_min < std::min(kNearDegenerate, 0.5 * change.old_min);
}

// A changed triangle may turn by up to 45° from its old normal; a poor old triangle's normal says
// little about S, so for one below kReliableNormal, 45° from S's normal there is enough too (folds
// onto neighbours are checked separately).
bool keeps_facing(const Tri& old_tri, const Tri& new_tri, const Vec3& surface_normal) {
  if ((new_tri.normal | old_tri.normal) >= 0.7) return true;
  return old_tri.quality < kReliableNormal && (new_tri.normal | surface_normal) >= 0.7;
}

// Which changes are worth making, judged on their qualities before the costlier fold test: the
// passes' (a collapse keeps every new triangle above min(kAcceptQuality, the worst it replaces); a
// flip improves a pair below kFlipBelow) or the sliver repair's (any strict improvement).
enum class Rule { Pass, Repair };

class Remesher {
 public:
  Remesher(SurfaceMesh& mesh, const RemeshOptions& options) : m_(mesh), opt_(options) {
    m_.add_property(size_);
    m_.add_property(kind_);
    m_.add_property(vcurve_);
    m_.add_property(hint_);
    m_.add_property(vnormal_);
    m_.add_property(in_work_);
    m_.add_property(in_next_);
    m_.add_property(depth_);
    m_.add_property(ecurve_);
    m_.add_property(estamp_);
  }
  ~Remesher() { release(); }
  /// Drop the working properties (before garbage collection, which then has less to compact).
  void release() {
    if (released_) return;
    released_ = true;
    m_.remove_property(size_);
    m_.remove_property(kind_);
    m_.remove_property(vcurve_);
    m_.remove_property(hint_);
    m_.remove_property(vnormal_);
    m_.remove_property(in_work_);
    m_.remove_property(in_next_);
    m_.remove_property(depth_);
    m_.remove_property(ecurve_);
    m_.remove_property(estamp_);
  }
  Remesher(const Remesher&) = delete;
  Remesher& operator=(const Remesher&) = delete;

  RemeshReport run();

 private:
  void setup_sizes();
  void classify_features();
  void compute_sizing();
  void seed_work();

  double target(VertexHandle a, VertexHandle b) const { return std::min(m_.property(size_, a), m_.property(size_, b)); }
  double length(EdgeHandle e) const { return edge_length(m_, e); }
  void mark(VertexHandle v);
  void mark_ring(VertexHandle v);
  void mark_fresh(VertexHandle v) {
    m_.property(depth_, v) = 0;
    mark(v);
  }
  std::vector<EdgeHandle> work_edges();

  bool split(EdgeHandle e);
  bool collapse(EdgeHandle e);
  bool collapse_check(HalfedgeHandle h, Change& change, Rule rule) const;
  bool curve_collapse_within_hausd(HalfedgeHandle h) const;
  void collapse_halfedge(HalfedgeHandle h);
  bool flip(EdgeHandle e);
  bool flip_check(EdgeHandle e, Change& change, Rule rule) const;
  void flip_edge(EdgeHandle e);
  bool feature_flip_check(HalfedgeHandle h, Change& change) const;
  void feature_flip(HalfedgeHandle h);
  void classify_vertex(VertexHandle v);
  double relocate(VertexHandle v);
  bool place(VertexHandle v, const Vec3& target, Vec3& q, SurfacePoint& sp) const;
  bool move_check(VertexHandle v, const Vec3& q, const Vec3& normal, Change& change) const;
  void move_vertex(VertexHandle v, const Vec3& q, const SurfacePoint& sp);
  bool folds(const std::vector<std::array<VertexHandle, 3>>& triangles, const std::vector<FaceHandle>& replaced,
             VertexHandle moved = VertexHandle(), const Vec3& at = Vec3(0, 0, 0)) const;
  void repair_slivers();
  bool repair(FaceHandle f);
  void report_degenerate() const;
  std::optional<std::pair<VertexHandle, VertexHandle>> curve_neighbours(VertexHandle v) const;
  Vec3 ring_centroid(VertexHandle v) const {
    Vec3 sum(0, 0, 0);
    int n = 0;
    for (auto w : m_.vv_range(v)) {
      sum += m_.point(w);
      ++n;
    }
    return n > 0 ? sum / double(n) : m_.point(v);
  }

  Vec3 project_on_curve(const Vec3& p, char curve) const { return curves_.closest(p, curve); }

  SurfaceMesh& m_;
  RemeshOptions opt_;
  std::shared_ptr<const ReferenceSurface> ref_;
  ReferencePolyline curves_;
  double hmin_ = 0, hmax_ = 0, hausd_ = 0, corner_angle_ = 0;
  RemeshReport report_;

  OpenMesh::VPropHandleT<double> size_;
  OpenMesh::VPropHandleT<char> kind_, vcurve_;
  OpenMesh::VPropHandleT<int> hint_;
  OpenMesh::VPropHandleT<Vec3> vnormal_;
  OpenMesh::VPropHandleT<char> in_work_, in_next_;
  // Rings of smoothing since the last split/collapse/flip or bad element: bounds how far
  // relocation spreads into the already-good mesh.
  OpenMesh::VPropHandleT<char> depth_;
  OpenMesh::EPropHandleT<char> ecurve_;
  OpenMesh::EPropHandleT<int> estamp_;
  int stamp_ = 0;
  bool released_ = false;
  std::vector<VertexHandle> work_, next_;
};

void Remesher::setup_sizes() {
  double diag = bounding_box(m_).diagonal();
  if (diag <= 0) diag = 1;
  hmax_ = opt_.hmax > 0 ? opt_.hmax : diag / 20;
  hmin_ = opt_.hmin > 0 ? opt_.hmin : hmax_ / 20;
  hmin_ = std::min(hmin_, hmax_);
  hausd_ = opt_.hausd > 0 ? opt_.hausd : diag / 1000;
  corner_angle_ = (opt_.feature_angle > 0 ? opt_.feature_angle : 45.0) * M_PI / 180.0;
}

void Remesher::classify_features() {
  // Per-face normal and quality, once (every sweep below is parallel and writes only its own element).
  const int nf = int(m_.n_faces()), ne = int(m_.n_edges()), nv = int(m_.n_vertices());
  std::vector<Tri> face_tri(nf);
  tbb::parallel_for(0, nf, [&](int i) {
    auto p = face_points(m_, FaceHandle(i));
    face_tri[i] = triangle(p[0], p[1], p[2]);
  });
  // Ridges by dihedral angle, added to the ridges read from the file; then the curve kind of edges.
  // A ridge of the mesh must be a crease of S too: S's normals at the two faces differ as much. The
  // evolving mesh has sharp dihedral angles where S has none (a triangle standing across a curved
  // wall after cuts and moves); tagged as ridges there, they would lock vertices off S and block
  // the flips and collapses that repair them, for good, since tags are kept from step to step.
  // (When S is the mesh itself this is the dihedral test alone.)
  const bool detect = opt_.feature_angle > 0;
  const double cos_limit = std::cos(opt_.feature_angle * M_PI / 180.0);
  auto s_normal = [&](FaceHandle f) {
    auto p = face_points(m_, f);
    return ref_->closest((p[0] + p[1] + p[2]) / 3.0).normal;
  };
  tbb::parallel_for(0, ne, [&](int i) {
    EdgeHandle e(i);
    if (detect && !m_.is_boundary(e) && !m_.ridge(e)) {
      auto f0 = m_.face_handle(m_.halfedge_handle(e, 0)), f1 = m_.face_handle(m_.halfedge_handle(e, 1));
      const auto& t0 = face_tri[f0.idx()];
      const auto& t1 = face_tri[f1.idx()];
      // Slivers (e.g. fresh from discretize) have unreliable normals: no ridge from them.
      if (t0.quality >= 1e-3 && t1.quality >= 1e-3 && (t0.normal | t1.normal) < cos_limit &&
          (s_normal(f0) | s_normal(f1)) < cos_limit)
        m_.ridge(e) = 1;
    }
    char c = kNoCurve;
    if (m_.required(e)) c = kRequiredCurve;
    else if (m_.interface(e)) c = kInterfaceCurve;
    else if (m_.ridge(e)) c = kRidgeCurve;
    else if (m_.is_boundary(e)) c = kBoundaryCurve;
    m_.property(ecurve_, e) = c;
  });
  tbb::parallel_for(0, nv, [&](int i) {
    VertexHandle v(i);
    classify_vertex(v);
    Vec3 normal(0, 0, 0);
    int hint = -1;
    if (ref_->analytic()) {
      normal = ref_->closest(m_.point(v)).normal;
    } else {
      // Area-weighted face normals (the quality-weighted cross products are proportional to areas).
      for (auto f : m_.vf_range(v)) {
        auto p = face_points(m_, f);
        normal += (p[1] - p[0]) % (p[2] - p[0]);
        if (!opt_.reference) hint = f.idx();
      }
      double len = normal.norm();
      if (len > 0) normal /= len;
    }
    m_.property(vnormal_, v) = normal;
    m_.property(hint_, v) = hint;
  });
  // Cut points lie on chords of S: put the interface on S before it becomes the reference curve
  // (a no-op when S is the input mesh itself). Where the chords sag far from S (a steep terrain at
  // hmax = 400 m: up to 130 m) that move can fold a thin triangle next to the cut; such a point
  // stays where it is, within the sag of S.
  if (opt_.reference)
    for (auto e : m_.edges())
      if (m_.property(ecurve_, e) == kInterfaceCurve)
        for (auto v : {m_.from_vertex_handle(m_.halfedge_handle(e, 0)), m_.to_vertex_handle(m_.halfedge_handle(e, 0))})
          if (!m_.required(v) && !m_.corner(v)) {
            auto sp = ref_->closest(m_.point(v), m_.property(hint_, v));
            Change change;
            if (!move_check(v, sp.point, sp.normal, change)) continue;
            m_.set_point(v, sp.point);
            m_.property(hint_, v) = sp.face;
          }
  for (auto e : m_.edges()) {
    char c = m_.property(ecurve_, e);
    if (c != kNoCurve && c != kRequiredCurve) {
      auto h = m_.halfedge_handle(e, 0);
      curves_.add(m_.point(m_.from_vertex_handle(h)), m_.point(m_.to_vertex_handle(h)), c);
    }
  }
  // The interface samples a smooth curve: split midpoints and relocated vertices go onto a C¹ curve
  // through its vertices, not onto its chords (which would shrink convex regions at every remesh).
  // Ridges and boundaries are real polylines and stay so.
  curves_.smooth(kInterfaceCurve, corner_angle_);
}

// The kind of v (free, curve, corner, locked) and its curve, from the curve kinds of its edges.
void Remesher::classify_vertex(VertexHandle v) {
  int count = 0;
  char type = kNoCurve;
  bool mixed = false, locked = m_.required(v) || m_.corner(v), angle_corner = false;
  Vec3 dir[2];
  for (auto h : m_.voh_range(v)) {
    char c = m_.property(ecurve_, m_.edge_handle(h));
    if (c == kNoCurve) continue;
    if (c == kRequiredCurve) locked = true;
    if (count > 0 && c != type) mixed = true;
    type = c;
    if (count < 2) dir[count] = m_.point(m_.to_vertex_handle(h)) - m_.point(v);
    ++count;
  }
  if (m_.is_isolated(v)) locked = true;
  if (count != 0 && count != 2) locked = true;
  // The interface is the zero set of a sampled φ: its turns at the scale of fresh cuts are noise,
  // so it has no angle corners; collapses along it are bounded by hausd instead (collapse_check).
  if (count == 2 && !locked && !mixed && type != kInterfaceCurve) {
    double n0 = dir[0].norm(), n1 = dir[1].norm();
    // Turning angle between the two curve edges: π − angle(d0, d1).
    double c = n0 > 0 && n1 > 0 ? -(dir[0] | dir[1]) / (n0 * n1) : -1;
    angle_corner = std::acos(std::clamp(c, -1.0, 1.0)) > corner_angle_;
  }
  if (mixed) locked = true;
  m_.property(kind_, v) = locked ? kLockedVertex : angle_corner ? kCornerVertex : (count == 2 ? kCurveVertex : kFreeVertex);
  m_.property(vcurve_, v) = count == 2 ? type : kNoCurve;
}

void Remesher::compute_sizing() {
  // h ≤ sqrt(8 hausd / κ): the sag of a chord of length h on a curve of curvature κ is h²κ/8.
  auto size_for = [&](double kappa) {
    double h = kappa > 0 ? std::sqrt(8 * hausd_ / kappa) : hmax_;
    return std::clamp(h, hmin_, hmax_);
  };
  double kappa_sphere = 0;
  if (ref_->analytic()) kappa_sphere = 1.0 / ref_->sphere_radius();
  std::atomic<bool> uniform = true;
  tbb::parallel_for(0, int(m_.n_vertices()), [&](int i) {
    VertexHandle v(i);
    double kappa = kappa_sphere;
    char kind = m_.property(kind_, v);
    if (!ref_->analytic() && kind == kFreeVertex) {
      // Osculating estimate 2|n·d|/|d|², over neighbours not much closer than the farthest one
      // (tiny edges of fresh cuts give no curvature information).
      double far = 0;
      for (auto w : m_.vv_range(v)) far = std::max(far, (m_.point(w) - m_.point(v)).norm());
      const Vec3& n = m_.property(vnormal_, v);
      for (auto w : m_.vv_range(v)) {
        Vec3 d = m_.point(w) - m_.point(v);
        double l = d.norm();
        if (l < 0.3 * far || l <= 0) continue;
        kappa = std::max(kappa, 2 * std::abs(n | d) / (l * l));
      }
    }
    if (kind == kCurveVertex) {
      // Curve curvature from the circle through points about hmax/2 away along the curve.
      Vec3 ends[2];
      int found = 0;
      for (auto h0 : m_.voh_range(v)) {
        if (m_.property(ecurve_, m_.edge_handle(h0)) != m_.property(vcurve_, v)) continue;
        HalfedgeHandle h = h0;
        double walked = 0;
        for (int step = 0; step < 8; ++step) {
          walked += m_.calc_edge_length(h);
          VertexHandle w = m_.to_vertex_handle(h);
          if (walked >= 0.5 * hmax_ || m_.property(kind_, w) != kCurveVertex) break;
          HalfedgeHandle next;
          for (auto hn : m_.voh_range(w))
            if (m_.property(ecurve_, m_.edge_handle(hn)) == m_.property(vcurve_, v) &&
                m_.to_vertex_handle(hn) != m_.from_vertex_handle(h))
              next = hn;
          if (!next.is_valid()) break;
          h = next;
        }
        if (found < 2) ends[found++] = m_.point(m_.to_vertex_handle(h));
      }
      if (found == 2) {
        Vec3 a = ends[0] - m_.point(v), b = ends[1] - m_.point(v), c = ends[1] - ends[0];
        double denom = a.norm() * b.norm() * c.norm();
        if (denom > 0) kappa = std::max(kappa, 2 * (a % b).norm() / denom);
      }
    }
    double h = size_for(kappa);
    m_.property(size_, v) = h;
    if (h < hmax_) uniform = false;
  });
  if (uniform) return;
  // Gradation: h(w) ≤ h(v) + ln(hgrad)·|vw|, propagated from the small sizes outwards.
  double slope = std::log(std::max(opt_.hgrad, 1.0 + 1e-6));
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  for (auto v : m_.vertices())
    if (m_.property(size_, v) < hmax_) queue.emplace(m_.property(size_, v), v.idx());
  while (!queue.empty()) {
    auto [h, i] = queue.top();
    queue.pop();
    VertexHandle v(i);
    if (h > m_.property(size_, v)) continue;
    for (auto w : m_.vv_range(v)) {
      double limit = h + slope * (m_.point(w) - m_.point(v)).norm();
      if (limit < m_.property(size_, w)) {
        m_.property(size_, w) = limit;
        queue.emplace(limit, w.idx());
      }
    }
  }
}

void Remesher::mark(VertexHandle v) {
  if (!m_.property(in_next_, v)) {
    m_.property(in_next_, v) = 1;
    next_.push_back(v);
  }
  if (!m_.property(in_work_, v)) {
    m_.property(in_work_, v) = 1;
    work_.push_back(v);
  }
}

void Remesher::mark_ring(VertexHandle v) {
  mark_fresh(v);
  for (auto w : m_.vv_range(v)) mark_fresh(w);
}

void Remesher::seed_work() {
  if (!opt_.incremental) {
    for (auto v : m_.vertices()) mark_fresh(v);
    return;
  }
  for (auto f : m_.faces()) {
    auto p = face_points(m_, f);
    if (triangle(p[0], p[1], p[2]).quality < kGoodQuality)
      for (auto v : m_.fv_range(f)) mark_fresh(v);
  }
  for (auto e : m_.edges()) {
    auto h = m_.halfedge_handle(e, 0);
    auto a = m_.from_vertex_handle(h), b = m_.to_vertex_handle(h);
    double l = length(e), t = target(a, b);
    if (l > kSplitRatio * t || l < kCollapseRatio * t) {
      mark_fresh(a);
      mark_fresh(b);
    }
  }
}

std::vector<EdgeHandle> Remesher::work_edges() {
  ++stamp_;
  std::vector<EdgeHandle> edges;
  for (auto v : work_) {
    if (m_.status(v).deleted()) continue;
    for (auto e : m_.ve_range(v)) {
      if (m_.property(estamp_, e) == stamp_) continue;
      m_.property(estamp_, e) = stamp_;
      edges.push_back(e);
    }
  }
  return edges;
}

bool Remesher::split(EdgeHandle e) {
  char curve = m_.property(ecurve_, e);
  if (curve == kRequiredCurve) return false;
  auto h0 = m_.halfedge_handle(e, 0), h1 = m_.halfedge_handle(e, 1);
  auto a = m_.from_vertex_handle(h0), b = m_.to_vertex_handle(h0);
  Vec3 p = (m_.point(a) + m_.point(b)) * 0.5;
  if (curve != kNoCurve) p = project_on_curve(p, curve);
  SurfacePoint sp = ref_->closest(p, m_.property(hint_, a));
  if (curve != kBoundaryCurve || ref_->analytic()) p = sp.point;

  // The two (or one) opposite vertices and their face regions; the new point must not fold them.
  VertexHandle opposite[2];
  int region[2] = {0, 0};
  std::vector<FaceHandle> replaced;
  std::vector<std::array<VertexHandle, 3>> after;  // the new vertex is the invalid handle, at p
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
    replaced.push_back(m_.face_handle(h));
    after.push_back({from, VertexHandle(), opposite[s]});
    after.push_back({VertexHandle(), to, opposite[s]});
  }
  if (creates_near_degenerate(change) || folds(after, replaced, VertexHandle(), p)) return false;
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
    m_.property(estamp_, ee) = 0;
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
// normal, which on a strongly curved S (a steep terrain at 400 m) lets it turn onto a neighbour.
bool Remesher::folds(const std::vector<std::array<VertexHandle, 3>>& triangles, const std::vector<FaceHandle>& replaced,
                     VertexHandle moved, const Vec3& at) const {
  auto position = [&](VertexHandle v) -> const Vec3& { return v == moved ? at : m_.point(v); };
  auto normal_of = [&](const std::array<VertexHandle, 3>& t) {
    return triangle(position(t[0]), position(t[1]), position(t[2])).normal;
  };
  std::vector<Vec3> normals;
  normals.reserve(triangles.size());
  for (const auto& t : triangles) normals.push_back(normal_of(t));
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
        auto h = m_.find_halfedge(w, u);
        if (!h.is_valid() || m_.is_boundary(h)) continue;
        auto f = m_.face_handle(h);
        if (std::find(replaced.begin(), replaced.end(), f) != replaced.end()) continue;
        auto vs = face_vertices(m_, f);
        other = normal_of({vs[0], vs[1], vs[2]});
      }
      if (other.sqrnorm() > 0 && (normals[i] | other) < kFoldCos) return true;
    }
  }
  return false;
}

// Whether the curve stays within hausd of the curve vertex v0 when it collapses along h onto v1:
// the new curve edge (u, v1), u the other curve neighbour of v0, must pass within hausd of v0.
bool Remesher::curve_collapse_within_hausd(HalfedgeHandle h) const {
  auto v0 = m_.from_vertex_handle(h), v1 = m_.to_vertex_handle(h);
  char curve = m_.property(vcurve_, v0);
  for (auto hu : m_.voh_range(v0)) {
    auto u = m_.to_vertex_handle(hu);
    if (u == v1 || m_.property(ecurve_, m_.edge_handle(hu)) != curve) continue;
    const Vec3 &a = m_.point(u), &b = m_.point(v1), &p = m_.point(v0);
    Vec3 ab = b - a;
    double t = ab.sqrnorm() > 0 ? std::clamp(((p - a) | ab) / ab.sqrnorm(), 0.0, 1.0) : 0.0;
    if ((a + ab * t - p).norm() > hausd_) return false;
  }
  return true;
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
    auto vl = m_.to_vertex_handle(m_.next_halfedge_handle(hh));
    auto e0 = m_.edge_handle(m_.find_halfedge(v0, vl)), e1 = m_.edge_handle(m_.find_halfedge(v1, vl));
    if (m_.property(ecurve_, e0) != kNoCurve && m_.property(ecurve_, e1) != kNoCurve) return false;
  }
  if (!const_cast<SurfaceMesh&>(m_).is_collapse_ok(h)) return false;
  if ((kind == kCurveVertex || kind == kCornerVertex) && !curve_collapse_within_hausd(h)) return false;
  const Vec3& p1 = m_.point(v1);
  double old_min = 1, new_min = 1;
  std::vector<FaceHandle> star;
  std::vector<std::array<VertexHandle, 3>> after;
  for (auto f : m_.vf_range(v0)) {
    star.push_back(f);
    auto pts = face_points(m_, f);
    auto old_tri = triangle(pts[0], pts[1], pts[2]);
    old_min = std::min(old_min, old_tri.quality);
    bool has_v1 = false;
    for (auto u : m_.fv_range(f)) has_v1 |= u == v1;
    if (has_v1) continue;
    auto vs = face_vertices(m_, f);
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
  change.old_min = old_min;
  change.new_min = new_min;
  return true;
}

bool Remesher::collapse(EdgeHandle e) {
  auto h0 = m_.halfedge_handle(e, 0), h1 = m_.halfedge_handle(e, 1);
  Change c0, c1;
  bool ok0 = collapse_check(h0, c0, Rule::Pass), ok1 = collapse_check(h1, c1, Rule::Pass);
  if (!ok0 && !ok1) return false;
  collapse_halfedge((ok0 && (!ok1 || c0.new_min >= c1.new_min)) ? h0 : h1);
  return true;
}

void Remesher::collapse_halfedge(HalfedgeHandle h) {
  auto v0 = m_.from_vertex_handle(h), v1 = m_.to_vertex_handle(h);
  // The edges (v0, vl) and (v1, vl) of each removed triangle merge: keep the union of their tags.
  struct Merge {
    VertexHandle vl;
    bool interface, ridge, required;
    int ref;
    char curve;
  };
  std::vector<Merge> merges;
  for (auto hh : {h, m_.opposite_halfedge_handle(h)}) {
    if (m_.is_boundary(hh)) continue;
    auto vl = m_.to_vertex_handle(m_.next_halfedge_handle(hh));
    auto e0 = m_.edge_handle(m_.find_halfedge(v0, vl)), e1 = m_.edge_handle(m_.find_halfedge(v1, vl));
    merges.push_back({vl, m_.interface(e0) || m_.interface(e1), m_.ridge(e0) || m_.ridge(e1),
                      m_.required(e0) || m_.required(e1), std::max(m_.edge_ref(e0), m_.edge_ref(e1)),
                      std::max(m_.property(ecurve_, e0), m_.property(ecurve_, e1))});
  }
  m_.collapse(h);
  for (const auto& mg : merges) {
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

// Whether flipping e keeps the pair flat on S and is worth it by `rule`; `change` receives the
// qualities of the two pairs.
bool Remesher::flip_check(EdgeHandle e, Change& change, Rule rule) const {
  if (m_.property(ecurve_, e) != kNoCurve || m_.is_boundary(e)) return false;
  if (!const_cast<SurfaceMesh&>(m_).is_flip_ok(e)) return false;
  auto h0 = m_.halfedge_handle(e, 0), h1 = m_.halfedge_handle(e, 1);
  auto a = m_.from_vertex_handle(h0), b = m_.to_vertex_handle(h0);
  auto c = m_.to_vertex_handle(m_.next_halfedge_handle(h0));
  auto d = m_.to_vertex_handle(m_.next_halfedge_handle(h1));
  const Vec3 &pa = m_.point(a), &pb = m_.point(b), &pc = m_.point(c), &pd = m_.point(d);
  auto t0 = triangle(pa, pd, pc), t1 = triangle(pb, pc, pd);
  change.old_min = std::min(triangle(pa, pb, pc).quality, triangle(pb, pa, pd).quality);
  change.new_min = std::min(t0.quality, t1.quality);
  // Only pairs with a poor triangle are worth changing in the passes: a good mesh stays as it is.
  if (change.new_min <= change.old_min + 1e-3 || (rule == Rule::Pass && change.old_min >= kFlipBelow)) return false;
  // The new pair must lie flat on S (no fold, no shortcut across curvature).
  Vec3 n = m_.property(vnormal_, a) + m_.property(vnormal_, b) + m_.property(vnormal_, c) + m_.property(vnormal_, d);
  double len = n.norm();
  if (len <= 0) return false;
  n /= len;
  const double min_cos = rule == Rule::Pass ? kFlipFlatness : kRepairFlatness;
  if ((t0.normal | n) < min_cos || (t1.normal | n) < min_cos) return false;
  return !folds({{a, d, c}, {b, c, d}}, {m_.face_handle(h0), m_.face_handle(h1)});
}

void Remesher::flip_edge(EdgeHandle e) {
  auto h0 = m_.halfedge_handle(e, 0), h1 = m_.halfedge_handle(e, 1);
  VertexHandle quad[4] = {m_.from_vertex_handle(h0), m_.to_vertex_handle(h0),
                          m_.to_vertex_handle(m_.next_halfedge_handle(h0)), m_.to_vertex_handle(m_.next_halfedge_handle(h1))};
  m_.flip(e);
  ++report_.flips;
  for (auto v : quad) mark_fresh(v);
}

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
  return !folds({{a, d, c}, {b, c, d}}, {m_.face_handle(h), m_.face_handle(o)});
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
  m_.property(estamp_, e) = 0;
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

double Remesher::relocate(VertexHandle v) {
  char kind = m_.property(kind_, v);
  if (kind == kLockedVertex || kind == kCornerVertex || m_.is_isolated(v)) return 0;
  const Vec3 p = m_.point(v);
  Vec3 target(0, 0, 0);
  if (kind == kFreeVertex) {
    const Vec3& nv = m_.property(vnormal_, v);
    Vec3 d = ring_centroid(v) - p;
    target = p + d - nv * (d | nv);
  } else {
    auto ends = curve_neighbours(v);
    if (!ends) return 0;
    target = project_on_curve((m_.point(ends->first) + m_.point(ends->second)) / 2.0, m_.property(vcurve_, v));
  }
  Vec3 q;
  SurfacePoint sp;
  Change change;
  if (!place(v, target, q, sp) || !move_check(v, q, sp.normal, change)) return 0;
  // Curve vertices move only to repair a poor triangle: a point between the reference curve's
  // vertices lies on a chord, off the true curve by up to h²κ/8.
  if (kind == kCurveVertex && change.old_min >= kCurveRepairQuality) return 0;
  bool better = change.new_min >= change.old_min || (change.new_min >= 0.6 && change.new_sum > change.old_sum);
  if (!better) return 0;
  move_vertex(v, q, sp);
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
  sp = ref_->closest(target, m_.property(hint_, v));
  bool on_polyline = m_.property(kind_, v) == kCurveVertex && m_.property(vcurve_, v) == kBoundaryCurve && !ref_->analytic();
  q = on_polyline ? target : sp.point;
  return (q - m_.point(v)).norm() >= 1e-3 * m_.property(size_, v);
}

// Whether moving v to q folds none of its triangles (normal: S's normal at q); `change` receives
// the qualities of v's star.
bool Remesher::move_check(VertexHandle v, const Vec3& q, const Vec3& normal, Change& change) const {
  change = Change{};
  // The star of v, one spoke per outgoing halfedge h: its face (if any) is (v, w1, w2), w1 = to(h),
  // w2 = to(next(h)); the face across (w2, w1) is unchanged by the move.
  constexpr int kMaxStar = 64;
  Vec3 moved_normal[kMaxStar];
  HalfedgeHandle spoke[kMaxStar];
  int n = 0;
  const Vec3& p = m_.point(v);
  for (auto h : m_.voh_range(v)) {
    if (n == kMaxStar) return false;  // no such valence in a mesh worth relocating in
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
    for (int j = 0; j < n; ++j)
      if (spoke[j] == next_spoke && moved_normal[j].sqrnorm() > 0 && (moved_normal[i] | moved_normal[j]) < kFoldCos)
        return false;
  }
  return true;
}

void Remesher::move_vertex(VertexHandle v, const Vec3& q, const SurfacePoint& sp) {
  m_.set_point(v, q);
  m_.property(hint_, v) = sp.face;
  m_.property(vnormal_, v) = sp.normal;
  ++report_.relocations;
}

// Sliver repair, after the passes: each triangle still below kRepairBelow, worst first, gets the
// local operation that most raises the worst quality around it (a collapse of one of its edges,
// a flip, or a move of one of its vertices to one of a few candidate points). Unlike the passes,
// which keep every new triangle above kAcceptQuality, this accepts any strict improvement: it is
// what untangles clusters of slivers where every single step of the passes would be refused.
void Remesher::repair_slivers() {
  for (int round = 0; round < kRepairRounds; ++round) {
    std::vector<std::pair<double, FaceHandle>> bad;
    for (auto f : m_.faces())
      if (double q = face_quality(m_, f); q < kRepairBelow) bad.emplace_back(q, f);
    std::sort(bad.begin(), bad.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    std::size_t repaired = 0;
    for (auto [q, f] : bad)
      if (!m_.status(f).deleted() && face_quality(m_, f) < kRepairBelow && repair(f)) ++repaired;
    if (repaired == 0) break;
  }
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

// Every operation refuses degenerate triangles and the repair removes those of its input it can: a
// remaining one (a configuration no local operation repairs) is reported, never silently returned.
void Remesher::report_degenerate() const {
  std::size_t count = 0;
  FaceHandle first;
  double first_area = 0;
  for (auto f : m_.faces()) {
    auto p = face_points(m_, f);
    double longest2 = std::max({(p[1] - p[0]).sqrnorm(), (p[2] - p[1]).sqrnorm(), (p[0] - p[2]).sqrnorm(), hmin_ * hmin_});
    double area = 0.5 * ((p[1] - p[0]) % (p[2] - p[0])).norm();
    if (area < kReportArea * longest2) {
      if (count++ == 0) {
        first = f;
        first_area = area;
      }
    }
  }
  if (count > 0)
    spdlog::warn("remesh: {} degenerate triangle(s) left (face {}: area {:.3g}); no local operation could repair them",
                 count, first.idx(), first_area);
}

RemeshReport Remesher::run() {
  auto start = std::chrono::steady_clock::now();
  setup_sizes();
  ref_ = opt_.reference ? opt_.reference : std::make_shared<const ReferenceSurface>(m_);
  auto stamp = [&](const char* what) {
    if (std::getenv("BODYFIT_REMESH_DEBUG"))
      std::fprintf(stderr, "remesh %-10s %8.1f ms work %zu\n", what,
                   std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count(), work_.size());
  };
  classify_features();
  stamp("features");
  compute_sizing();
  stamp("sizing");
  seed_work();
  stamp("seed");

  for (int pass = 0; pass < opt_.max_passes && !work_.empty(); ++pass) {
    report_.passes = pass + 1;
    for (auto v : next_) m_.property(in_next_, v) = 0;
    next_.clear();
    std::size_t ops = report_.splits + report_.collapses + report_.flips;

    // Split the long edges, longest first.
    {
      std::vector<std::pair<double, EdgeHandle>> longs;
      for (auto e : work_edges()) {
        auto h = m_.halfedge_handle(e, 0);
        double l = length(e), t = target(m_.from_vertex_handle(h), m_.to_vertex_handle(h));
        if (l > kSplitRatio * t) longs.emplace_back(l / t, e);
      }
      std::sort(longs.begin(), longs.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
      for (auto& [r, e] : longs) split(e);
    }
    // Collapse the short edges, shortest first.
    {
      std::vector<std::pair<double, EdgeHandle>> shorts;
      for (auto e : work_edges()) {
        auto h = m_.halfedge_handle(e, 0);
        double l = length(e), t = target(m_.from_vertex_handle(h), m_.to_vertex_handle(h));
        if (l < kCollapseRatio * t) shorts.emplace_back(l / t, e);
      }
      std::sort(shorts.begin(), shorts.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
      for (auto& [r, e] : shorts) {
        if (m_.status(e).deleted()) continue;
        auto h = m_.halfedge_handle(e, 0);
        if (length(e) >= kCollapseRatio * target(m_.from_vertex_handle(h), m_.to_vertex_handle(h))) continue;
        collapse(e);
      }
    }
    // Flip towards better triangles.
    for (auto e : work_edges())
      if (!m_.status(e).deleted()) flip(e);
    // Relocate: tangential smoothing, then projection onto S (or the curve).
    bool moved = false;
    std::vector<VertexHandle> to_smooth = work_;
    for (auto v : to_smooth) {
      if (m_.status(v).deleted()) continue;
      double d = relocate(v);
      if (d > kMoveSpread * m_.property(size_, v)) {
        moved = true;
        char depth = m_.property(depth_, v);
        if (depth < kSmoothRings) {
          mark(v);
          for (auto w : m_.vv_range(v)) {
            if (!m_.property(in_next_, w) && !m_.property(in_work_, w)) m_.property(depth_, w) = char(depth + 1);
            else m_.property(depth_, w) = std::min(m_.property(depth_, w), char(depth + 1));
            mark(w);
          }
        }
      }
    }
    stamp("pass");
    if (std::getenv("BODYFIT_REMESH_DEBUG"))
      std::fprintf(stderr, "  splits %zu collapses %zu flips %zu moves %zu\n", report_.splits, report_.collapses, report_.flips, report_.relocations);
    bool changed = report_.splits + report_.collapses + report_.flips > ops;
    for (auto v : work_) m_.property(in_work_, v) = 0;
    work_.clear();
    if (!changed && !moved) break;
    for (auto v : next_) {
      if (m_.status(v).deleted()) continue;
      m_.property(in_work_, v) = 1;
      work_.push_back(v);
    }
  }
  for (auto v : work_) m_.property(in_work_, v) = 0;
  for (auto v : next_) m_.property(in_next_, v) = 0;

  stamp("passes");
  repair_slivers();
  stamp("repair");
  release();
  if (report_.collapses > 0) m_.garbage_collection();
  stamp("gc");
  report_degenerate();
  auto q = quality_stats(m_);
  report_.min_quality = q.min;
  report_.mean_quality = q.mean;
  report_.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return report_;
}

}  // namespace

RemeshReport remesh(SurfaceMesh& mesh, const RemeshOptions& options) {
  bool garbage = false;
  for (auto v : mesh.all_vertices()) garbage |= mesh.status(v).deleted();
  for (auto e : mesh.all_edges()) garbage |= mesh.status(e).deleted();
  for (auto f : mesh.all_faces()) garbage |= mesh.status(f).deleted();
  if (garbage) mesh.garbage_collection();
  Remesher remesher(mesh, options);
  return remesher.run();
}

}  // namespace bodyfit
