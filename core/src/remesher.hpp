#pragma once
// The Remesher behind remesh() (private to the core): its constants, the triangle measures its
// checks share, and the class whose members live in four files along the algorithm's seams —
//   remesh.cpp           the work queue and the pass loop (run), and remesh() itself;
//   remesh_features.cpp  feature classification (ridges, curves, corners) and the sizing field;
//   remesh_operators.cpp split, collapse, flip and relocation, each with its checks (no fold, no
//                        near-degenerate triangle);
//   remesh_repair.cpp    the sliver repair after the passes (including the flip of a feature edge
//                        under a cap) and the final degenerate-triangle report.
#include <bodyfit/remesh.hpp>

#include "blocks.hpp"

#include <bodyfit/geometry.hpp>
#include <bodyfit/projection.hpp>

#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <limits>
#include <optional>
#include <queue>
#include <span>
#include <utility>
#include <vector>

namespace bodyfit::remesh_detail {


// Kinds of feature curves an edge can belong to (the label of the reference polyline).
inline constexpr char kNoCurve = 0, kInterfaceCurve = 1, kRidgeCurve = 2, kBoundaryCurve = 3, kRequiredCurve = 4;
// Vertex kinds: free on S, sliding along one feature curve, a corner of one curve (it turns by
// more than the corner angle there: it does not move, but may merge with a curve neighbour closer
// than hausd), locked (curve ends and junctions, required, isolated).
inline constexpr char kFreeVertex = 0, kCurveVertex = 1, kLockedVertex = 2, kCornerVertex = 3;

// Edge length window relative to the target size (as MMG's metric lengths): split above √2,
// collapse below 1/√2, so that a mesh whose edges are within ±30 % of the target is left alone.
inline constexpr double kSplitRatio = 1.41;
inline constexpr double kCollapseRatio = 0.71;
// Faces of quality below this start the work queue (a geodesic sphere is ≥ 0.7 everywhere).
inline constexpr double kGoodQuality = 0.6;
// A collapse may create triangles down to this quality (never below the worst one it removes).
inline constexpr double kAcceptQuality = 0.4;
// A relocation may lower a star's worst triangle (for a better sum, staying ≥ 0.6) only while that
// worst triangle is below this quality.
inline constexpr double kSmoothBelow = 0.9;
// Curve vertices are relocated only when one of their triangles is below this quality.
inline constexpr double kCurveRepairQuality = 0.6;
// Flips are tried only when the worse triangle of the pair is below this quality.
inline constexpr double kFlipBelow = 0.75;
// Below this quality a triangle's normal says little about S (keeps_facing).
inline constexpr double kReliableNormal = 0.1;
// A flip's two new triangles must be within 20° of the mean vertex normal (within 45° for repairs,
// the bound of collapses and moves).
inline constexpr double kFlipFlatness = 0.9396926207859084, kRepairFlatness = 0.7;
// No operation may leave two adjacent triangles whose normals are further apart than 135°
// (validate_mesh reports 160° as a fold).
inline constexpr double kFoldCos = -0.7071067811865476;
// Triangles still below this quality after the passes go to the sliver repair, for at most
// kRepairRounds sweeps.
inline constexpr double kRepairBelow = 0.3;
inline constexpr int kRepairRounds = 5;
// Relocation spreads at most this many rings away from a topological change or a bad element.
inline constexpr char kSmoothRings = 3;
// The passes stop as stalled when the work of a pass (operations plus significant moves) has not
// fallen below kProgress times its lowest value so far for kStallPasses passes in a row.
inline constexpr int kStallPasses = 3;
inline constexpr double kProgress = 0.75;
// remesh() renumbers the mesh in spatial order when its spatial_disorder() exceeds this.
inline constexpr double kReorderAbove = 0.1;
// A relocation moving a vertex by more than this fraction of its size re-queues its ring.
inline constexpr double kMoveSpread = 0.05;
// The largest star the checks hold on the stack; a larger one (no remesh makes it) is refused or
// checked the slow way.
inline constexpr int kMaxValence = 64;
// A triangle whose doubled area is at most this fraction of its summed squared edge lengths is
// degenerate: its cross product is rounding noise, so its "normal" may point anywhere (and pass any
// orientation test by chance). It gets no normal and quality 0, which every check refuses.
inline constexpr double kDegenerateArea = 1e-10;
// No change may create a near-degenerate triangle: the worst triangle it makes stays above this
// quality, or above half the worst one it replaces when that was already below it (the tests of the
// passes and of the repair imply this; splits and the projection of the interface onto S check it).
inline constexpr double kNearDegenerate = 1e-3;
// A cap (a, b, c) whose apex c lies on its own feature edge ab, within this fraction of |ab|, is
// repaired by flipping ab: the feature then runs a-c-b, through the same points.
inline constexpr double kOnFeatureEdge = 1e-6;
// After remesh, a triangle of area below this times max(its longest edge, hmin)² is reported.
inline constexpr double kReportArea = 1e-12;

struct Tri {
  double quality = 0;
  Vec3 normal{0, 0, 0};  // unit, zero if degenerate
};

inline Tri triangle(const Vec3& a, const Vec3& b, const Vec3& c) {
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

inline bool creates_near_degenerate(const Change& change) {
  return change.new_min < std::min(kNearDegenerate, 0.5 * change.old_min);
}

// A changed triangle may turn by up to 45° from its old normal; a poor old triangle's normal says
// little about S, so for one below kReliableNormal, 45° from S's normal there is enough too (folds
// onto neighbours are checked separately).
inline bool keeps_facing(const Tri& old_tri, const Tri& new_tri, const Vec3& surface_normal) {
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
    m_.add_property(touched_);
    m_.add_property(ecurve_);
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
    m_.remove_property(touched_);
    m_.remove_property(ecurve_);
    // The scratch buffers and the search trees too (a remesh to a size leaves tens of MB in them):
    // the compaction that follows reuses that memory instead of growing the heap.
    ref_.reset();
    curves_ = ReferencePolyline();
    release_buffers(work_, next_, moved_, listed_, touched_list_, edges_, ranked_, rated_, projected_,
                    worth_flipping_, face_flipped_, flipped_faces_, star_, after_, normals_);
  }
  template <class... Vectors>
  static void release_buffers(Vectors&... vectors) {
    ((void)std::exchange(vectors, Vectors()), ...);
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
  double length(EdgeHandle e) const {
    auto h = m_.halfedge_handle(e, 0);
    return (m_.point(m_.to_vertex_handle(h)) - m_.point(m_.from_vertex_handle(h))).norm();
  }
  /// Length of e over its target size.
  double ratio(EdgeHandle e) const {
    auto h = m_.halfedge_handle(e, 0);
    auto a = m_.from_vertex_handle(h), b = m_.to_vertex_handle(h);
    return (m_.point(b) - m_.point(a)).norm() / target(a, b);
  }
  /// Whether an edge (a, b) of the given new length would be above the split bound while it was not
  /// before (old_length): the changes after the split phase must not undo it.
  bool lengthens_beyond_split(VertexHandle a, VertexHandle b, double new_length, double old_length) const {
    const double bound = kSplitRatio * target(a, b);
    return new_length > bound && new_length > old_length;
  }
  std::array<Vec3, 3> points(FaceHandle f) const {
    auto h = m_.halfedge_handle(f);
    auto h1 = m_.next_halfedge_handle(h);
    return {m_.point(m_.to_vertex_handle(h)), m_.point(m_.to_vertex_handle(h1)),
            m_.point(m_.to_vertex_handle(m_.next_halfedge_handle(h1)))};
  }
  std::array<VertexHandle, 3> vertices(FaceHandle f) const {
    auto h = m_.halfedge_handle(f);
    auto h1 = m_.next_halfedge_handle(h);
    return {m_.to_vertex_handle(h), m_.to_vertex_handle(h1), m_.to_vertex_handle(m_.next_halfedge_handle(h1))};
  }
  void mark(VertexHandle v);
  void mark_ring(VertexHandle v);
  void mark_fresh(VertexHandle v) {
    m_.property(depth_, v) = 0;
    mark(v);
  }
  template <class T, class F>
  void gather_work_edges(std::vector<T>& out, F&& f) const;
  void work_edges(std::vector<EdgeHandle>& edges) const;
  void rated_work_edges(std::vector<std::pair<double, EdgeHandle>>& rated) const;
  void flip_in_order(const std::vector<EdgeHandle>& edges);
  void split_long_edges();
  std::size_t pass();
  bool near_change(FaceHandle f) const;
  void final_sweep();

  // `projected`: the edge's midpoint already projected onto S (ref_->closest from its first end's hint).
  bool split(EdgeHandle e, const SurfacePoint* projected = nullptr);
  bool collapse(EdgeHandle e);
  bool collapse_keeps_topology(HalfedgeHandle v0v1) const;
  bool collapse_check(HalfedgeHandle h, Change& change, Rule rule) const;
  bool curve_collapse_within_hausd(HalfedgeHandle h) const;
  void collapse_halfedge(HalfedgeHandle h);
  bool flip(EdgeHandle e);
  bool may_flip(EdgeHandle e) const;
  bool flip_check(EdgeHandle e, Change& change, Rule rule) const;
  void flip_edge(EdgeHandle e);
  bool feature_flip_check(HalfedgeHandle h, Change& change) const;
  void feature_flip(HalfedgeHandle h);
  void classify_vertex(VertexHandle v);
  void relocate_in_waves(std::size_t count, std::vector<double>& moved);
  double relocate(VertexHandle v);
  bool place(VertexHandle v, const Vec3& target, Vec3& q, SurfacePoint& sp) const;
  bool move_check(VertexHandle v, const Vec3& q, const Vec3& normal, Change& change) const;
  void move_vertex(VertexHandle v, const Vec3& q, const SurfacePoint& sp);
  /// v at q, S's point sp: its place, hint face and normal (what a relocation writes).
  void set_place(VertexHandle v, const Vec3& q, const SurfacePoint& sp) {
    m_.set_point(v, q);
    m_.property(hint_, v) = sp.face;
    m_.property(vnormal_, v) = sp.normal;
  }
  bool folds(std::span<const std::array<VertexHandle, 3>> triangles, std::span<const FaceHandle> replaced,
             VertexHandle moved = VertexHandle(), const Vec3& at = Vec3(0, 0, 0)) const;
  bool move_lengthens(VertexHandle v, const Vec3& q) const;
  bool near_surface(const Vec3& p, std::span<const std::array<VertexHandle, 3>> triangles,
                    VertexHandle moved = VertexHandle(), const Vec3& at = Vec3(0, 0, 0)) const;
  double distance_to(const Vec3& p, std::span<const std::array<VertexHandle, 3>> triangles,
                     VertexHandle moved = VertexHandle(), const Vec3& at = Vec3(0, 0, 0)) const;
  double chord_sag(VertexHandle near, const Vec3& a, const Vec3& b) const;
  bool chord_within_hausd(VertexHandle near, const Vec3& a, const Vec3& b, const Vec3& a_old, const Vec3& b_old,
                          std::initializer_list<int> faces) const;
  std::size_t repair_slivers();
  void repair_self_intersections();
  std::vector<std::pair<double, FaceHandle>> slivers_;  // faces below kRepairBelow (final_sweep)
  bool repair(FaceHandle f);
  void report_degenerate() const;
  std::size_t degenerate_ = 0;  // triangles left with area < kReportArea × longest² (final_sweep)
  double degenerate_area_ = 0;
  Vec3 degenerate_at_{0, 0, 0};
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
  bool check_distance_ = false;  // every change kept within hausd of ref_'s triangles
  ReferencePolyline curves_;
  double hmin_ = 0, hmax_ = 0, hausd_ = 0, interface_hausd_ = 0, corner_angle_ = 0;
  RemeshReport report_;

  OpenMesh::VPropHandleT<double> size_;
  OpenMesh::VPropHandleT<char> kind_, vcurve_;
  OpenMesh::VPropHandleT<int> hint_;
  OpenMesh::VPropHandleT<Vec3> vnormal_;
  OpenMesh::VPropHandleT<char> in_work_, in_next_;
  OpenMesh::VPropHandleT<char> touched_;  // queued or moved by this remesh (touched_list_)
  std::vector<VertexHandle> touched_list_;
  void touch(VertexHandle v) {
    if (!m_.property(touched_, v)) {
      m_.property(touched_, v) = 1;
      touched_list_.push_back(v);
    }
  }
  // Rings of smoothing since the last split/collapse/flip or bad element: bounds how far
  // relocation spreads into the already-good mesh.
  OpenMesh::VPropHandleT<char> depth_;
  OpenMesh::EPropHandleT<char> ecurve_;
  bool released_ = false;
  std::vector<VertexHandle> work_, next_;
  std::vector<double> moved_;  // how far each relocated vertex of a pass went (relocate_in_waves)
  std::vector<int> listed_;    // each vertex's place in the pass's list, −1 (relocate_in_waves)
  // Scratch buffers reused by every pass and check (no allocation per operation).
  std::vector<EdgeHandle> edges_;
  std::vector<std::pair<double, EdgeHandle>> ranked_, rated_;
  struct Projected {
    VertexHandle a, b;  // the edge's ends (invalid: not projected)
    SurfacePoint at;    // the projection of their midpoint
  };
  std::vector<Projected> projected_;
  std::vector<char> worth_flipping_, face_flipped_;
  std::vector<FaceHandle> flipped_faces_;
  mutable std::vector<FaceHandle> star_;
  mutable std::vector<std::array<VertexHandle, 3>> after_;
  mutable std::vector<Vec3> normals_;
};

}  // namespace bodyfit::remesh_detail
