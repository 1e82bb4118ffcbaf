// Remesher: feature classification (ridges, curves, corners, kinds of vertices) and the sizing field.
#include "remesher.hpp"

#include <bodyfit/error.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <atomic>

namespace bodyfit::remesh_detail {

void Remesher::setup_sizes() {
  double diag = bounding_box(m_).diagonal();
  if (diag <= 0) diag = 1;
  hmax_ = opt_.hmax > 0 ? opt_.hmax : resolution_length(m_);
  if (hmax_ <= 0) hmax_ = diag / 20;
  if (hmax_ > diag) {
    // An edge longer than the surface itself means nothing, and hmin, derived from hmax, would then
    // override hausd (a unit sphere at hmax = 1e300 collapsed to 6 faces, area 4.8 against 12.6).
    static std::atomic<bool> said{false};
    if (!said.exchange(true))
      spdlog::warn("remesh: hmax {:.6g} is above the surface's extent (its bounding box's diagonal, {:.6g}): hmax = "
                   "{:.6g}{}",
                   hmax_, diag, diag, opt_.hmin > 0 ? "" : fmt::format(", hmin = {:.6g}", diag / 20));
    hmax_ = diag;
  }
  hmin_ = opt_.hmin > 0 ? opt_.hmin : hmax_ / 20;
  if (hmin_ > hmax_) {  // only an hmin given: it asks for coarser than the input's resolution
    if (opt_.hmax > 0)
      throw InputError(fmt::format("remesh: hmin {:.6g} exceeds hmax {:.6g}", opt_.hmin, opt_.hmax));
    spdlog::warn("remesh: hmin {:.6g} is above the default hmax {:.6g} (the input's resolution): hmax raised to {:.6g}",
                 hmin_, hmax_, hmin_);
    hmax_ = hmin_;
  }
  hausd_ = opt_.hausd > 0 ? opt_.hausd : diag / 1000;
  interface_hausd_ = opt_.hausd_interface > 0 ? opt_.hausd_interface : hausd_;
  corner_angle_ = (opt_.feature_angle > 0 ? opt_.feature_angle : 45.0) * M_PI / 180.0;
}

void Remesher::classify_features() {
  // Every sweep below is parallel and writes only its own element. (The faces' triangles are
  // recomputed per edge rather than stored: an array of them was the largest allocation of a remesh.)
  const int ne = int(m_.n_edges()), nv = int(m_.n_vertices());
  // Ridges by dihedral angle, added to the ridges read from the file; then the curve kind of edges.
  // A ridge of the mesh must be a crease of S too: S's normals at the two faces differ as much. The
  // evolving mesh has sharp dihedral angles where S has none (a triangle standing across a curved
  // wall after cuts and moves); tagged as ridges there, they would lock vertices off S and block
  // the flips and collapses that repair them, for good, since tags are kept from step to step.
  // (When S is the mesh itself this is the dihedral test alone.)
  const bool detect = opt_.feature_angle > 0;
  const double cos_limit = std::cos(opt_.feature_angle * M_PI / 180.0);
  auto fan_normal = [&](VertexHandle v) {  // area-weighted normal of the faces around v
    Vec3 n(0, 0, 0);
    for (auto f : m_.vf_range(v)) {
      auto p = points(f);
      n += (p[1] - p[0]) % (p[2] - p[0]);
    }
    return n;
  };
  auto s_normal = [&](FaceHandle f) {
    auto p = points(f);
    return ref_->closest((p[0] + p[1] + p[2]) / 3.0).normal;
  };
  tbb::parallel_for(0, ne, [&](int i) {
    EdgeHandle e(i);
    if (detect && !m_.is_boundary(e) && !m_.ridge(e)) {
      // The faces (a, b, c) and (b, a, d) on either side of a→b, from their four points (this sweep
      // runs over every edge at every remesh: no normalisation unless needed).
      const auto h0 = m_.halfedge_handle(e, 0), h1 = m_.halfedge_handle(e, 1);
      const Vec3& a = m_.point(m_.from_vertex_handle(h0));
      const Vec3& b = m_.point(m_.to_vertex_handle(h0));
      const Vec3& c = m_.point(m_.to_vertex_handle(m_.next_halfedge_handle(h0)));
      const Vec3& d = m_.point(m_.to_vertex_handle(m_.next_halfedge_handle(h1)));
      const Vec3 n0 = (b - a) % (c - a), n1 = (a - b) % (d - b);
      const double ab2 = (b - a).sqrnorm();
      const double l0 = ab2 + (c - b).sqrnorm() + (a - c).sqrnorm(), l1 = ab2 + (d - a).sqrnorm() + (b - d).sqrnorm();
      // Slivers (e.g. fresh from discretize) have unreliable normals: no ridge from them (quality
      // 2√3·|n|/Σl² below 1e-3).
      constexpr double kSliver = 1e-3 / (2 * 1.7320508075688772);
      const double m0 = n0.sqrnorm(), m1 = n1.sqrnorm();
      if (m0 >= kSliver * kSliver * l0 * l0 && m1 >= kSliver * kSliver * l1 * l1 &&
          (n0 | n1) < cos_limit * std::sqrt(m0 * m1) &&
          (s_normal(m_.face_handle(h0)) | s_normal(m_.face_handle(h1))) < cos_limit) {
        // A crease, not noise: it must still be there one ring out, between the fans around c and d
        // (a scan's or a coarse curved mesh's noisy dihedral angles average out over a fan, a
        // crease's flanks do not: on a sphere with radial noise of ±0.3 of an edge, 1,164 edges
        // passed the dihedral test and none passes this one; the bracket's creases all do).
        const Vec3 fc = fan_normal(m_.to_vertex_handle(m_.next_halfedge_handle(h0)));
        const Vec3 fd = fan_normal(m_.to_vertex_handle(m_.next_halfedge_handle(h1)));
        if ((fc | fd) < cos_limit * fc.norm() * fd.norm()) m_.ridge(e) = 1;
      }
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
        auto p = points(f);
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
  // (a no-op when S is the input mesh itself). Where the chords sag far from S (a steep height field
  // at hmax = 400 m: up to 130 m) that move can fold a thin triangle next to the cut; such a point
  // stays where it is, within the sag of S.
  // (The feature edges are few: found in parallel, then visited in index order.)
  const auto features = collect<EdgeHandle>(ne, [&](int i, EdgeHandle& e) {
    e = EdgeHandle(i);
    const char c = m_.property(ecurve_, e);
    return c != kNoCurve && c != kRequiredCurve;
  });
  if (opt_.reference)
    for (auto e : features)
      if (m_.property(ecurve_, e) == kInterfaceCurve)
        for (auto v : {m_.from_vertex_handle(m_.halfedge_handle(e, 0)), m_.to_vertex_handle(m_.halfedge_handle(e, 0))})
          if (!m_.required(v) && !m_.corner(v)) {
            auto sp = ref_->closest(m_.point(v), m_.property(hint_, v));
            Change change;
            if (!move_check(v, sp.point, sp.normal, change)) continue;
            touch(v);
            m_.set_point(v, sp.point);
            m_.property(hint_, v) = sp.face;
          }
  for (auto e : features) {
    auto h = m_.halfedge_handle(e, 0);
    curves_.add(m_.point(m_.from_vertex_handle(h)), m_.point(m_.to_vertex_handle(h)), m_.property(ecurve_, e));
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
  auto size_for = [&](double kappa, double tolerance) {
    double h = kappa > 0 ? std::sqrt(8 * tolerance / kappa) : hmax_;
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
    const bool on_interface = kind == kCurveVertex && m_.property(vcurve_, v) == kInterfaceCurve;
    double h = size_for(kappa, on_interface ? interface_hausd_ : hausd_);
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

}  // namespace bodyfit::remesh_detail
