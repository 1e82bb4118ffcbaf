#include "barriers.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/app/vector_io.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bodyfit::fire {

Barriers Barriers::read(const BarrierOptions& options, const SurfaceSource& surface) {
  VectorLayer layer = read_vector_layer(options.file, options.layer);
  to_surface_crs(layer, options.file, surface.crs, surface.reprojected_from, surface.file);
  Barriers barriers;
  barriers.width_ = options.width;
  for (const auto& feature : layer.features) barriers.add_geometry(feature.geometry);
  if (barriers.empty())
    throw file_error(options.file, "no line, polygon or point in the layer: it holds no barrier");
  spdlog::info("{}: {} barrier segment(s), {} polygon(s), width {} m", options.file.string(), barriers.segments_.size(),
               barriers.polygon_count_, options.width);
  return barriers;
}

void Barriers::add_geometry(const PlanGeometry& geometry) {
  for (const auto& p : geometry.points) segments_.push_back({p, p, -1});
  for (const auto& line : geometry.lines) {
    if (line.size() == 1) segments_.push_back({line[0], line[0], -1});
    for (std::size_t i = 0; i + 1 < line.size(); ++i) segments_.push_back({line[i], line[i + 1], -1});
  }
  for (const auto& polygon : geometry.polygons) {
    const int id = polygon_count_++;
    for (const auto& ring : polygon.rings)
      for (std::size_t i = 0; i < ring.size(); ++i) segments_.push_back({ring[i], ring[(i + 1) % ring.size()], id});
  }
}

// Each segment goes into the cells it passes through (column by column, or row by row when it is
// steeper), not into every cell of its bounding box: a lake's long diagonal edge stays cheap.
void Barriers::build_grid(double cell) const {
  double x1 = -std::numeric_limits<double>::infinity(), y1 = x1;
  x0_ = y0_ = std::numeric_limits<double>::infinity();
  for (const auto& s : segments_)
    for (const PlanPoint& p : {s.a, s.b}) {
      x0_ = std::min(x0_, p[0]), x1 = std::max(x1, p[0]);
      y0_ = std::min(y0_, p[1]), y1 = std::max(y1, p[1]);
    }
  // At most about 4 million cells, whatever the reach.
  cell_ = std::max(cell, std::max(x1 - x0_, y1 - y0_) / 2048);
  if (!(cell_ > 0)) cell_ = 1;
  nx_ = long(std::floor((x1 - x0_) / cell_)) + 1;
  ny_ = long(std::floor((y1 - y0_) / cell_)) + 1;
  cells_.assign(std::size_t(nx_ * ny_), {});
  auto column = [&](double x) { return std::clamp(long(std::floor((x - x0_) / cell_)), 0L, nx_ - 1); };
  auto row = [&](double y) { return std::clamp(long(std::floor((y - y0_) / cell_)), 0L, ny_ - 1); };
  for (std::size_t k = 0; k < segments_.size(); ++k) {
    const auto& s = segments_[k];
    const bool along_x = std::abs(s.b[0] - s.a[0]) >= std::abs(s.b[1] - s.a[1]);
    const int u = along_x ? 0 : 1, w = 1 - u;  // walk along axis u, cover axis w
    PlanPoint a = s.a, b = s.b;
    if (a[u] > b[u]) std::swap(a, b);
    auto index_u = [&](double value) { return u == 0 ? column(value) : row(value); };
    auto index_w = [&](double value) { return w == 0 ? column(value) : row(value); };
    const double origin_u = u == 0 ? x0_ : y0_;
    for (long i = index_u(a[u]); i <= index_u(b[u]); ++i) {
      const double lo = std::max(a[u], origin_u + double(i) * cell_), hi = std::min(b[u], origin_u + double(i + 1) * cell_);
      auto at = [&](double t) { return b[u] > a[u] ? a[w] + (b[w] - a[w]) * (t - a[u]) / (b[u] - a[u]) : a[w]; };
      const long j0 = index_w(std::min(at(lo), at(hi))), j1 = index_w(std::max(at(lo), at(hi)));
      for (long j = j0; j <= j1; ++j) {
        const long cx = u == 0 ? i : j, cy = u == 0 ? j : i;
        cells_[std::size_t(cy * nx_ + cx)].push_back(int(k));
      }
    }
  }
  parity_.assign(std::size_t(polygon_count_), 0);
}

// Even-odd rule per polygon, by a ray towards +x through the grid's row of (x, y): each crossing
// is counted in the cell that contains it, so a segment listed in several cells counts once.
bool Barriers::inside_polygon(double x, double y) const {
  if (polygon_count_ == 0 || y < y0_ || y >= y0_ + double(ny_) * cell_) return false;
  const long j = long(std::floor((y - y0_) / cell_));
  if (j < 0 || j >= ny_) return false;
  std::fill(parity_.begin(), parity_.end(), 0);
  const long first = std::max(0L, long(std::floor((x - x0_) / cell_)));
  for (long i = first; i < nx_; ++i)
    for (int k : cells_[std::size_t(j * nx_ + i)]) {
      const auto& s = segments_[std::size_t(k)];
      if (s.polygon < 0 || (s.a[1] > y) == (s.b[1] > y)) continue;
      const double xc = s.a[0] + (y - s.a[1]) * (s.b[0] - s.a[0]) / (s.b[1] - s.a[1]);
      const long cell = std::clamp(long(std::floor((xc - x0_) / cell_)), 0L, nx_ - 1);
      if (xc > x && cell == i) parity_[std::size_t(s.polygon)] ^= 1;
    }
  return std::find(parity_.begin(), parity_.end(), 1) != parity_.end();
}

bool Barriers::blocks(double x, double y, double reach) const {
  if (segments_.empty()) return false;
  if (cells_.empty() || reach > 4 * cell_ || reach < cell_ / 4) build_grid(reach);
  const long i0 = std::max(0L, long(std::floor((x - reach - x0_) / cell_)));
  const long i1 = std::min(nx_ - 1, long(std::floor((x + reach - x0_) / cell_)));
  const long j0 = std::max(0L, long(std::floor((y - reach - y0_) / cell_)));
  const long j1 = std::min(ny_ - 1, long(std::floor((y + reach - y0_) / cell_)));
  for (long j = j0; j <= j1; ++j)
    for (long i = i0; i <= i1; ++i)
      for (int k : cells_[std::size_t(j * nx_ + i)]) {
        const auto& s = segments_[std::size_t(k)];
        if (distance_to_segment(s.a, s.b, x, y) <= reach) return true;
      }
  return inside_polygon(x, y);
}

// Why 2·ĥ (ĥ the longest plan-view edge). The advection traces each vertex's characteristic
// backwards; the front crosses a barrier only if the trace of a vertex beyond it ends in G on the
// near side.
//  1. Every face the barrier's line passes through has its three corners within ĥ of the line, so
//     with a reach ≥ ĥ, V ≡ 0 (P1) on each of them: they cover the line, and every continuous path
//     across it meets a point where V = 0, which an exact characteristic never passes.
//  2. The discrete trace moves by straight walks, each with the velocity of the face it starts in,
//     and at most 1.25 × max_cells_per_substep (1 by default) mean edge lengths of that face long,
//     whatever max_cfl (which only bounds the whole trace). A walk moves only from a face with a
//     corner outside the band (V ≡ 0 on the others), i.e. from a point farther than reach − ĥ from
//     the line; and it must end in G across it, whose every point lies in a face with a burning
//     corner — outside the band, R = 0 keeps φ > 0 there — so again farther than reach − ĥ. With
//     reach = 2ĥ that is a walk longer than 2ĥ: more than the 1.25 ĥ a walk can move.
// A wider barrier (width / 2 above 2ĥ) widens the band; a narrower one acts with the mesh's width.
double barrier_reach(const Barriers& barriers, double longest_edge) {
  return std::max(0.5 * barriers.width(), 2.0 * longest_edge);
}

double longest_plan_edge(const SurfaceMesh& mesh) {
  double longest = 0;
  for (auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    const Vec3 d = mesh.point(mesh.to_vertex_handle(h)) - mesh.point(mesh.from_vertex_handle(h));
    longest = std::max(longest, std::hypot(d[0], d[1]));
  }
  return longest;
}

void mark_barrier_vertices(const SurfaceMesh& mesh, const Barriers& barriers, double reach,
                           std::span<const int> active, std::vector<char>& stopped) {
  stopped.resize(mesh.n_vertices(), 0);
  auto mark = [&](int v) {
    const Vec3& p = mesh.point(VertexHandle(v));
    stopped[std::size_t(v)] = barriers.blocks(p[0], p[1], reach) ? 1 : 0;
  };
  if (active.empty())
    for (int v = 0; v < int(mesh.n_vertices()); ++v) mark(v);
  else
    for (int v : active) mark(v);
}

}  // namespace bodyfit::fire
