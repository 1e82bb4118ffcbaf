// Interface-preserving adaptive remeshing: split / collapse / flip / relocate driven by a sizing
// field, on a work queue of "active" vertices so that the cost follows the part of the mesh that
// needs change. See docs/validation/remeshing.md for the algorithm and its defaults; the Remesher
// class is in remesher.hpp, its operators, features and repair in remesh_*.cpp.
#include "remesher.hpp"

namespace bodyfit {
namespace remesh_detail {

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

}  // namespace remesh_detail

RemeshReport remesh(SurfaceMesh& mesh, const RemeshOptions& options) {
  bool garbage = false;
  for (auto v : mesh.all_vertices()) garbage |= mesh.status(v).deleted();
  for (auto e : mesh.all_edges()) garbage |= mesh.status(e).deleted();
  for (auto f : mesh.all_faces()) garbage |= mesh.status(f).deleted();
  if (garbage) mesh.garbage_collection();
  remesh_detail::Remesher remesher(mesh, options);
  return remesher.run();
}

}  // namespace bodyfit
