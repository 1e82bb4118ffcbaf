// Interface-preserving adaptive remeshing: split / collapse / flip / relocate driven by a sizing
// field, on a work queue of "active" vertices so that the cost follows the part of the mesh that
// needs change. See docs/validation/remeshing.md for the algorithm and its defaults; the Remesher
// class is in remesher.hpp, its operators, features, repair and parallel relocations in remesh_*.cpp.
#include "remesher.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/guards.hpp>

#include <fmt/format.h>
#include <tbb/parallel_sort.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>

#include <ctime>

namespace bodyfit {
namespace remesh_detail {

void Remesher::mark(VertexHandle v) {
  touch(v);
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
  // One parallel sweep over the faces finds both kinds of seeds (each edge looked at from one of its
  // faces; with RemeshOptions::changed, only faces with a changed vertex); they are marked in index order,
  // faces then edges, as serial sweeps would.
  struct Seeds {
    std::vector<FaceHandle> poor;
    std::vector<EdgeHandle> off;
  };
  constexpr int kBlock = 8192;
  const int nf = int(m_.n_faces());
  std::vector<Seeds> blocks(std::size_t((nf + kBlock - 1) / kBlock));
  tbb::parallel_for(0, int(blocks.size()), [&](int b) {
    Seeds& out = blocks[std::size_t(b)];
    for (int i = b * kBlock; i < std::min(nf, (b + 1) * kBlock); ++i) {
      FaceHandle f(i);
      if (opt_.changed) {
        bool changed = false;
        for (auto v : m_.fv_range(f)) changed = changed || opt_.changed(v);
        if (!changed) continue;
      }
      auto p = points(f);
      if (triangle(p[0], p[1], p[2]).quality < kGoodQuality) out.poor.push_back(f);
      for (auto h : m_.fh_range(f)) {
        auto e = m_.edge_handle(h);
        if (h != m_.halfedge_handle(e, 0) && !m_.is_boundary(m_.opposite_halfedge_handle(h))) continue;
        double r = ratio(e);
        if (r > kSplitRatio || r < kCollapseRatio) out.off.push_back(e);
      }
    }
  });
  std::vector<EdgeHandle> off;
  for (const auto& b : blocks) {
    for (auto f : b.poor)
      for (auto v : m_.fv_range(f)) mark_fresh(v);
    off.insert(off.end(), b.off.begin(), b.off.end());
  }
  std::sort(off.begin(), off.end());
  for (auto e : off) {
    auto h = m_.halfedge_handle(e, 0);
    mark_fresh(m_.from_vertex_handle(h));
    mark_fresh(m_.to_vertex_handle(h));
  }
}

// The edges around the work vertices, each once (an edge between two work vertices is taken from
// the one with the smaller index), in the order of the work list: f(e, out) appends what it makes of
// each, by blocks of the list in parallel, joined in order.
template <class T, class F>
void Remesher::gather_work_edges(std::vector<T>& out, F&& f) const {
  append_in_order(int(work_.size()), out, [&](int i, std::vector<T>& part) {
    const VertexHandle v = work_[std::size_t(i)];
    if (m_.status(v).deleted()) return;
    for (auto h : m_.voh_range(v)) {
      auto w = m_.to_vertex_handle(h);
      if (m_.property(in_work_, w) && w.idx() < v.idx()) continue;
      f(m_.edge_handle(h), part);
    }
  });
}

void Remesher::work_edges(std::vector<EdgeHandle>& edges) const {
  gather_work_edges(edges, [](EdgeHandle e, std::vector<EdgeHandle>& out) { out.push_back(e); });
}

void Remesher::rated_work_edges(std::vector<std::pair<double, EdgeHandle>>& rated) const {
  gather_work_edges(rated, [&](EdgeHandle e, std::vector<std::pair<double, EdgeHandle>>& out) { out.emplace_back(ratio(e), e); });
}

namespace {

// Longest first (shortest first for collapses); ties by index, so the order never depends on how the
// list was gathered. The edges of a list are distinct: any sort gives the one order.
void sort_longest_first(std::vector<std::pair<double, EdgeHandle>>& ranked) {
  tbb::parallel_sort(ranked.begin(), ranked.end(), [](const auto& x, const auto& y) {
    return x.first != y.first ? x.first > y.first : x.second.idx() < y.second.idx();
  });
}

void sort_shortest_first(std::vector<std::pair<double, EdgeHandle>>& ranked) {
  tbb::parallel_sort(ranked.begin(), ranked.end(), [](const auto& x, const auto& y) {
    return x.first != y.first ? x.first < y.first : x.second.idx() < y.second.idx();
  });
}

}  // namespace

// Flip each edge in turn where it helps (flip()). Whether an edge's pair is poor enough to be worth
// the check is found for all of them at once, in parallel; a pair that an earlier flip of the sweep
// changed is looked at again, so the flips are those of the serial sweep.
void Remesher::flip_in_order(const std::vector<EdgeHandle>& edges) {
  const int n = int(edges.size());
  worth_flipping_.resize(std::size_t(n));
  for_each_index(n, [&](int i) { worth_flipping_[std::size_t(i)] = may_flip(edges[std::size_t(i)]); });
  face_flipped_.resize(m_.n_faces(), 0);
  flipped_faces_.clear();
  for (int i = 0; i < n; ++i) {
    const EdgeHandle e = edges[std::size_t(i)];
    if (m_.status(e).deleted()) continue;
    const FaceHandle f0 = m_.face_handle(m_.halfedge_handle(e, 0)), f1 = m_.face_handle(m_.halfedge_handle(e, 1));
    auto changed = [&](FaceHandle f) { return f.is_valid() && face_flipped_[std::size_t(f.idx())]; };
    if (!worth_flipping_[std::size_t(i)] && !changed(f0) && !changed(f1)) continue;
    if (!flip(e)) continue;
    for (auto f : {f0, f1}) {
      face_flipped_[std::size_t(f.idx())] = 1;
      flipped_faces_.push_back(f);
    }
  }
  for (auto f : flipped_faces_) face_flipped_[std::size_t(f.idx())] = 0;
}

// First phase: split every edge above the split bound, longest first, in rounds until none is left.
// A split halves an edge, so a mesh refined by a factor r needs about ⌈log2 r⌉ + 1 rounds (the new
// edges to the opposite vertices are ~0.87 of the old ones); each round looks only at the edges of
// the vertices the previous one created, plus the edges it could not split (a split refused
// because it would fold may succeed once its neighbours are split). It stops when nothing is long
// or a round splits nothing.
void Remesher::split_long_edges() {
  work_edges(edges_);
  std::vector<VertexHandle> created;
  // No size is below hmin, so edges of hmin covering the surface bound what splitting can make (4×
  // for the gradation and the rounds' leftovers): beyond, splits no longer bring triangles to size
  // (a needle to a far vertex, split along its length into ever more needles) and would not end.
  // The bound is at least twice the faces: the surface's area, a pass over every face, only once a
  // round would add more faces than the mesh has.
  const double faces_before = double(m_.n_faces());
  double area = -1, bound = 2 * faces_before;
  while (true) {
    append_in_order(int(edges_.size()), ranked_, [&](int i, std::vector<std::pair<double, EdgeHandle>>& out) {
      const EdgeHandle e = edges_[std::size_t(i)];
      if (!m_.status(e).deleted())
        if (double r = ratio(e); r > kSplitRatio) out.emplace_back(r, e);
    });
    if (ranked_.empty()) break;
    if (area < 0 && double(m_.n_faces() + 2 * ranked_.size()) > bound) {
      area = total_area(m_);
      bound += 4 * faces_for_edge_length(area, hmin_);
    }
    sort_longest_first(ranked_);
    ++report_.split_rounds;
    // Room for the round's new elements at once (a split adds a vertex, three edges and two faces),
    // instead of the arrays doubling (and being copied) several times within it.
    const std::size_t k = ranked_.size();
    // The budget checked before the remesh counts faces of hmax; curvature and hausd may ask for
    // far smaller edges (a spike, a tiny hausd): the growth itself is bounded, round by round.
    check_face_budget(double(m_.n_faces() + 2 * k), "remesh: the sizes the curvature and hausd ask for");
    if (double(m_.n_faces() + 2 * k) > bound)
      throw InputError(fmt::format(
          "remesh: splitting to the sizes asked for would make over {:.3g} faces, more than edges of hmin = {:.3g} "
          "cover the surface's area ({:.3g}) with: triangles the splits cannot bring to size (a vertex far from the "
          "others, needles; worst quality {:.3g}) — check the input",
          double(m_.n_faces() + 2 * k), hmin_, area, quality_stats(m_).min));
    m_.reserve(m_.n_vertices() + k, m_.n_edges() + 3 * k, m_.n_faces() + 2 * k);
    // The midpoints' projections onto S, all at once in parallel: a split reads only its own edge's
    // ends, which the round's other splits neither move nor change — unless the edge comes twice in
    // the list and its first split halved it (then split() projects the new midpoint itself). A
    // curve's projection, whose search tree is built on first use, stays in split().
    projected_.resize(k);
    for_each_index(int(k), [&](int i) {
      const EdgeHandle e = ranked_[std::size_t(i)].second;
      Projected& out = projected_[std::size_t(i)];
      out.a = out.b = VertexHandle();
      if (m_.property(ecurve_, e) != kNoCurve) return;
      const auto h = m_.halfedge_handle(e, 0);
      out.a = m_.from_vertex_handle(h);
      out.b = m_.to_vertex_handle(h);
      out.at = ref_->closest((m_.point(out.a) + m_.point(out.b)) * 0.5, m_.property(hint_, out.a));
    });
    const std::size_t before = report_.splits;
    created.clear();
    edges_.clear();
    for (std::size_t i = 0; i < k; ++i) {
      const EdgeHandle e = ranked_[i].second;
      if (ratio(e) <= kSplitRatio) continue;
      const int n = int(m_.n_vertices());
      const auto h = m_.halfedge_handle(e, 0);
      const Projected& mid = projected_[i];
      const bool same = mid.a == m_.from_vertex_handle(h) && mid.b == m_.to_vertex_handle(h);
      if (split(e, same ? &mid.at : nullptr)) created.push_back(VertexHandle(n));
      else edges_.push_back(e);
    }
    if (report_.splits == before) break;
    // Bisection alone leaves, in a triangle whose three sides were split, the spokes from a midpoint
    // to the opposite vertex (0.87 of a side) where the regular 1-to-4 split has the sides' halves:
    // flipping them first saves splitting them (and collapsing the extra vertices afterwards).
    for (auto v : created)
      for (auto h : m_.voh_range(v)) edges_.push_back(m_.edge_handle(h));
    flip_in_order(edges_);
  }
  // The split rounds' projections (tens of MB for a large refinement) are not read by the passes:
  // freed here, their memory serves the passes instead of the heap growing beside it.
  release_buffers(projected_);
}

// One collapse/flip/relocate pass over the work queue (with a split step for edges made long since);
// returns its work: topological operations plus relocations that moved a vertex significantly.
std::size_t Remesher::pass() {
  for (auto v : next_) m_.property(in_next_, v) = 0;
  next_.clear();
  const std::size_t ops = report_.splits + report_.collapses + report_.flips;
  std::size_t significant_moves = 0;

  // The work edges with their ratios, gathered once for the split step's long ones and, when it
  // splits none (a split re-queues its ring), the collapse step's short ones.
  rated_work_edges(rated_);
  // Split the long edges, longest first.
  ranked_.clear();
  for (const auto& [r, e] : rated_)
    if (r > kSplitRatio) ranked_.emplace_back(r, e);
  sort_longest_first(ranked_);
  const std::size_t splits = report_.splits;
  for (auto& [r, e] : ranked_)
    if (!m_.status(e).deleted() && ratio(e) > kSplitRatio) split(e);
  if (report_.splits != splits) rated_work_edges(rated_);
  // Collapse the short edges, shortest first.
  ranked_.clear();
  for (const auto& [r, e] : rated_)
    if (r < kCollapseRatio) ranked_.emplace_back(r, e);
  sort_shortest_first(ranked_);
  for (auto& [r, e] : ranked_) {
    if (m_.status(e).deleted() || ratio(e) >= kCollapseRatio) continue;
    collapse(e);
  }
  // Flip towards better triangles.
  work_edges(edges_);
  flip_in_order(edges_);
  // Relocate: tangential smoothing, then projection onto S (or the curve). The loop may append to
  // work_ (rings of moved vertices), which this pass does not visit.
  const std::size_t to_smooth = work_.size();
  relocate_in_waves(to_smooth, moved_);
  for (std::size_t i = 0; i < to_smooth; ++i) {
    const VertexHandle v = work_[i];
    const double d = moved_[i];
    if (d < 0) continue;
    touch(v);
    ++report_.relocations;
    if (d > kMoveSpread * m_.property(size_, v)) {
      ++significant_moves;
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
  for (auto v : work_) m_.property(in_work_, v) = 0;
  work_.clear();
  for (auto v : next_) {
    if (m_.status(v).deleted()) continue;
    m_.property(in_work_, v) = 1;
    work_.push_back(v);
  }
  return report_.splits + report_.collapses + report_.flips - ops + significant_moves;
}

// After the passes (and again after the repair if it changed anything): the longest edge relative to
// its target, the edges still above the split bound, the quality, the degenerate triangles and the
// faces the repair starts from (one sweep over the faces, in fixed blocks so that the sums and lists
// do not depend on the number of threads).
// Whether a face has a vertex this remesh queued or moved, or one its caller marked changed: with
// RemeshOptions::changed, the slivers elsewhere are those the last remesh could not repair.
bool Remesher::near_change(FaceHandle f) const {
  for (auto v : m_.fv_range(f))
    if (m_.property(touched_, v) || opt_.changed(v)) return true;
  return false;
}

void Remesher::final_sweep() {
  constexpr int kBlock = 4096;
  const int nf = int(m_.n_faces());
  const int blocks = (nf + kBlock - 1) / kBlock;
  struct Partial {
    std::vector<std::pair<double, FaceHandle>> slivers;
    double q_min = 1, q_sum = 0, max_ratio = 0;
    std::size_t faces = 0, long_edges = 0, degenerate = 0;
    double degenerate_area = std::numeric_limits<double>::max();
    Vec3 degenerate_at{0, 0, 0};
  };
  std::vector<Partial> partial(std::size_t(std::max(blocks, 0)));
  tbb::parallel_for(0, blocks, [&](int b) {
    Partial& p = partial[std::size_t(b)];
    for (int i = b * kBlock; i < std::min(nf, (b + 1) * kBlock); ++i) {
      FaceHandle f(i);
      if (m_.status(f).deleted()) continue;
      auto pts = points(f);
      const double e0 = (pts[1] - pts[0]).sqrnorm(), e1 = (pts[2] - pts[1]).sqrnorm(), e2 = (pts[0] - pts[2]).sqrnorm();
      const double area = 0.5 * ((pts[1] - pts[0]) % (pts[2] - pts[0])).norm();
      const double q = e0 + e1 + e2 > 0 ? 4 * std::sqrt(3.0) * area / (e0 + e1 + e2) : 0.0;  // triangle_quality
      p.q_min = std::min(p.q_min, q);
      p.q_sum += q;
      ++p.faces;
      if (q < kRepairBelow && (!(opt_.incremental && opt_.changed) || near_change(f))) p.slivers.emplace_back(q, f);
      // Every operation refuses degenerate triangles and the repair removes those it can: one left
      // (a configuration no local operation repairs) is reported, never silently returned.
      const double longest2 = std::max({e0, e1, e2, hmin_ * hmin_});
      if (area < kReportArea * longest2) {
        ++p.degenerate;
        if (area < p.degenerate_area) {
          p.degenerate_area = area;
          p.degenerate_at = (pts[0] + pts[1] + pts[2]) / 3.0;
        }
      }
      // Each edge once: from the face of its first halfedge, or of the other one on a boundary. The
      // halfedges h2 → h0 → h1 → h2 of the face run along e2 (point 2 to 0), e0 (0 to 1), e1 (1 to 2).
      const auto h0 = m_.next_halfedge_handle(m_.halfedge_handle(f)), h1 = m_.next_halfedge_handle(h0);
      const std::array<std::pair<HalfedgeHandle, double>, 3> sides{{{h0, e0}, {h1, e1}, {m_.next_halfedge_handle(h1), e2}}};
      for (const auto& [h, l2] : sides) {
        auto e = m_.edge_handle(h);
        if (h != m_.halfedge_handle(e, 0) && !m_.is_boundary(m_.opposite_halfedge_handle(h))) continue;
        double r = std::sqrt(l2) / target(m_.from_vertex_handle(h), m_.to_vertex_handle(h));
        p.max_ratio = std::max(p.max_ratio, r);
        p.long_edges += r > kSplitRatio;
      }
    }
  });
  Partial total;
  slivers_.clear();
  for (const auto& p : partial) {
    slivers_.insert(slivers_.end(), p.slivers.begin(), p.slivers.end());
    total.q_min = std::min(total.q_min, p.q_min);
    total.q_sum += p.q_sum;
    total.faces += p.faces;
    total.max_ratio = std::max(total.max_ratio, p.max_ratio);
    total.long_edges += p.long_edges;
    total.degenerate += p.degenerate;
    if (p.degenerate_area < total.degenerate_area) {
      total.degenerate_area = p.degenerate_area;
      total.degenerate_at = p.degenerate_at;
    }
  }
  degenerate_ = total.degenerate;
  degenerate_area_ = total.degenerate_area;
  degenerate_at_ = total.degenerate_at;
  report_.min_quality = total.faces ? total.q_min : 0;
  report_.mean_quality = total.faces ? total.q_sum / double(total.faces) : 0;
  report_.max_edge_ratio = total.max_ratio;
  report_.long_edges = total.long_edges;
}

RemeshReport Remesher::run() {
  auto start = std::chrono::steady_clock::now();
  setup_sizes();
  ref_ = opt_.reference ? opt_.reference : std::make_shared<const ReferenceSurface>(m_);
  ref_->prepare();  // before the sweeps that query it from every thread
  // Not needed where no chord the passes may make (up to twice hmax) can stray beyond hausd/2 from S
  // (a fine tessellation of a smooth surface, a plane): the checks' projections cost a third of a
  // remesh.
  const double longest = 2 * hmax_;
  check_distance_ = opt_.check_distance_to_reference && !ref_->analytic() &&
                    longest * longest * ref_->max_curvature() / 8 > hausd_ / 2;
  const bool debug = spdlog::should_log(spdlog::level::trace);  // bodyfit -vv
  timespec cpu_start{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &cpu_start);
  const double cpu0 = double(cpu_start.tv_sec) * 1e3 + double(cpu_start.tv_nsec) * 1e-6;
  auto stamp = [&](const char* what) {
    if (!debug) return;
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    timespec cpu{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &cpu);
    spdlog::trace("remesh {:<10} {:8.1f} ms (process cpu {:.1f} ms) work {} | splits {} collapses {} flips {} moves {} | "
                  "page faults {}",
                 what, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count(),
                 double(cpu.tv_sec) * 1e3 + double(cpu.tv_nsec) * 1e-6 - cpu0, work_.size(), report_.splits,
                 report_.collapses, report_.flips, report_.relocations, usage.ru_minflt);
  };
  stamp("reference");
  classify_features();
  stamp("features");
  compute_sizing();
  stamp("sizing");
  seed_work();
  stamp("seed");
  split_long_edges();
  stamp("splits");

  // Then collapse/flip/relocate passes until a pass does nothing (converged) or the work per pass
  // stops decreasing (stalled): past that point the passes only shuffle a few short edges around (a
  // collapse makes a neighbouring edge short) while the quality stays the same.
  std::size_t best = std::numeric_limits<std::size_t>::max();
  int since_best = 0;
  report_.stop = RemeshStop::Converged;
  while (!work_.empty()) {
    if (opt_.max_passes > 0 && report_.passes >= opt_.max_passes) {
      report_.stop = RemeshStop::PassLimit;
      break;
    }
    ++report_.passes;
    const std::size_t work = pass();
    stamp("pass");
    if (debug) spdlog::trace("remesh pass work {}", work);
    if (work == 0) break;
    if (double(work) <= kProgress * double(best)) {
      best = work;
      since_best = 0;
    } else if (++since_best >= kStallPasses) {
      report_.stop = RemeshStop::Stalled;
      break;
    }
  }
  for (auto v : work_) m_.property(in_work_, v) = 0;
  for (auto v : next_) m_.property(in_next_, v) = 0;
  work_.clear();
  next_.clear();

  stamp("passes");
  final_sweep();
  stamp("sweep");
  if (!slivers_.empty() && repair_slivers() > 0) final_sweep();
  if (check_distance_) repair_self_intersections();
  stamp("repair");
  release();
  // A full renumbering costs a sort and a pass over every array (~0.1 s at a million faces); an
  // evolution step appends and removes a few thousand elements, so it runs every few steps only,
  // and only when it would at least halve the disorder (on a surface much wider than high the
  // Z-order itself leaves ~11 %: renumbering at every step bought nothing).
  std::vector<int> order;  // the spatial order, sorted once for both the estimate and the renumbering
  bool reorder = false;
  if (opt_.spatial_order && report_.splits + report_.collapses + report_.flips > 0)
    if (const double disorder = spatial_disorder(m_); disorder > kReorderAbove) {
      order = spatial_vertex_order(m_);
      reorder = spatial_disorder_after_reorder(m_, order) < 0.5 * disorder;
    }
  if (reorder)
    reorder_spatially(m_, order);
  else if (report_.collapses > 0)
    collect_garbage(m_);
  stamp("compact");
  report_degenerate();
  report_.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return report_;
}

}  // namespace remesh_detail

const char* to_string(RemeshStop stop) {
  switch (stop) {
    case RemeshStop::Converged: return "converged";
    case RemeshStop::Stalled: return "stalled";
    case RemeshStop::PassLimit: return "pass limit";
  }
  return "?";
}

RemeshReport remesh(SurfaceMesh& mesh, const RemeshOptions& options) {
  if (has_deleted_elements(mesh))
    collect_garbage(mesh);
  remesh_detail::Remesher remesher(mesh, options);
  return remesher.run();
}

}  // namespace bodyfit
