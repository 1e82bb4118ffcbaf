// Advection of a level set on a triangulated surface by the method of characteristics.
//
// Each vertex's characteristic is traced backwards, dX/dτ = −V(X), X(0) = x, over τ ∈ (0, T), and
// φ(T, x) = φ0(X(T)) is the P1 interpolation of φ0 at the foot. Points on the surface are (face,
// barycentric coordinates), never 3-D points off the surface. A displacement is applied by walking:
// inside a face the point moves along a straight line until it reaches an edge; the remaining
// displacement is then unfolded into the next face's plane (rotated about the shared edge) and the
// walk continues there. A path that reaches a vertex or runs along an edge is handled by the same
// rule (a zero-length step crosses to the next face), so no characteristic is ever dropped.
//
// Tangent vectors are moved between faces by the same unfoldings: RK4 carries each stage's
// velocity back to the start face along the crossed edges; RK2 takes the midpoint velocity from
// the affine field of the current face, so each of its sub-steps is a single walk.
//
// Vertices are traced in Z-order and faces stored in the order of their first corner in it, so
// that neighbouring characteristics read neighbouring memory; each trace is independent, so the
// result does not depend on the threads.
#include <bodyfit/advection.hpp>

#include "surface_walker.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/guards.hpp>

#include <fmt/format.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>

namespace bodyfit {
namespace {

using namespace walker;

struct TraceResult {
  Location foot;
  std::size_t substeps = 0;
  bool boundary = false;
  bool stalled = false;
  bool outside = false;  ///< reached a face where V is not known (a band call)
};

/// What one thread's share of a tracing call did (AdvectionReport's counts).
struct TraceCounts {
  std::size_t traced = 0, substeps = 0, boundary = 0, lost = 0, outside = 0;
  void add(const TraceResult& r) {
    ++traced;
    substeps += r.substeps;
    boundary += r.boundary;
    lost += r.stalled;
    outside += r.outside;
  }
};

/// The sum over the threads of a tracing call.
struct TraceTotals {
  std::atomic<std::size_t> traced{0}, substeps{0}, boundary{0}, lost{0}, outside{0};
  void add(const TraceCounts& c) {
    traced += c.traced;
    substeps += c.substeps;
    boundary += c.boundary;
    lost += c.lost;
    outside += c.outside;
  }
  void report_to(AdvectionReport* report) const {
    if (!report) return;
    report->traced = traced;
    report->substeps = substeps;
    report->hit_boundary = boundary;
    report->lost = lost;
    report->outside_band = outside;
  }
};

/// Trace the characteristic through `start` backwards over a time T, reading V on the faces whose
/// motion was filled by the call `epoch`.
TraceResult trace(const Surface& s, Location start, double T, const AdvectionOptions& opt, std::uint32_t epoch,
                  std::size_t max_substeps, std::vector<Crossed>& path) {
  TraceResult r;
  auto known = [&](int face) { return s.motion[face].epoch == epoch; };
  Location x = start;
  const int outer = std::max(1, opt.steps);
  const double outer_dt = T / outer;
  auto stage = [&](const Location& from, Delta d, Delta& k) -> bool {
    // V at the point reached from `from` by walking d, carried back into from's face along the
    // same edges in reverse (each crossing undone by the entered face's own map).
    Location y = from;
    path.clear();
    const WalkEnd end = walk(s, y, d, &path);
    if (end == WalkEnd::stalled) return false;
    if (end == WalkEnd::left || !known(y.face)) {
      r.outside = true;
      return false;
    }
    k = velocity_at(s, y);
    for (auto c = path.rbegin(); c != path.rend(); ++c) k = carry(s.faces[c->face], c->far_slot, k);
    return true;
  };
  const double cells = opt.max_cells_per_substep;
  for (int o = 0; o < outer; ++o) {
    double remaining = outer_dt;
    // Kept from one sub-step to the next while it still fits (no square root, no division), and
    // resized when it is too long or under half the local reach: a trace through a few tiny faces
    // must not keep their tiny sub-steps for the rest of its time.
    double dt = 0;
    while (remaining > 0) {
      if (!known(x.face)) {
        r.outside = true;
        break;
      }
      const Delta k1 = velocity_at(s, x);
      const double speed2 = cells2(s, x.face, k1);  // in cells per unit time, squared
      const double reach2 = speed2 * dt * dt;
      if (dt == 0 || reach2 > 1.5625 * cells * cells || (reach2 < 0.25 * cells * cells && dt < remaining)) {
        // Equal sub-steps over what remains, each crossing about `cells` cells.
        dt = speed2 * remaining * remaining > cells * cells ? remaining / std::ceil(std::sqrt(speed2) * remaining / cells)
                                                            : remaining;
      }
      if (dt >= remaining * (1 - 1e-12)) dt = remaining;  // no sliver of a last step
      // The bound of every trace (trace_vertices): a speed that overflows (dt = 0) or a trace
      // that took more sub-steps than its fastest crossing of the smallest face allows is lost.
      if (!(dt > 0) || r.substeps >= max_substeps) {
        r.stalled = true;
        break;
      }
      remaining = dt == remaining ? 0.0 : remaining - dt;
      ++r.substeps;
      if (opt.rk_order == 4) {
        Delta k2, k3, k4;
        if (!stage(x, (-0.5 * dt) * k1, k2) || !stage(x, (-0.5 * dt) * k2, k3) || !stage(x, (-dt) * k3, k4)) {
          r.stalled = !r.outside;
          break;
        }
        const WalkEnd end = walk(s, x, (-dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4), nullptr);
        if (end != WalkEnd::arrived) {
          (end == WalkEnd::boundary ? r.boundary : end == WalkEnd::left ? r.outside : r.stalled) = true;
          break;
        }
      } else {
        // Midpoint rule, x ← x − dt·V(x − dt/2·V(x)). V at the midpoint from x's face while the
        // midpoint lies in it; beyond its edges, from the face the midpoint lies in. Extending x's
        // affine V there instead under-estimates a speed that grows along the path (the rate of
        // spread up a steepening slope), and the feet of a sub-step crossing a few cells fell
        // short: a front lagged first order in the sub-step (docs/validation/advection.md).
        Location mid = x;
        for (int i = 0; i < 3; ++i) mid.b[i] = x.b[i] - 0.5 * dt * k1.d[i];
        Delta k2;
        if (mid.b[0] >= 0 && mid.b[1] >= 0 && mid.b[2] >= 0) {
          k2 = velocity_at(s, mid);
        } else if (!stage(x, (-0.5 * dt) * k1, k2)) {
          r.stalled = !r.outside;
          break;
        }
        const WalkEnd end = walk(s, x, (-dt) * k2, nullptr);
        if (end != WalkEnd::arrived) {
          (end == WalkEnd::boundary ? r.boundary : end == WalkEnd::left ? r.outside : r.stalled) = true;
          break;
        }
      }
    }
    if (r.boundary || r.stalled || r.outside) break;
  }
  if (!known(x.face)) r.outside = true;
  r.foot = x;
  return r;
}


/// φ at a location: P1, or with `gradients` the mean of P1 and of the corners' Taylor planes,
/// clamped to the face's range (AdvectionOptions::gradient_correction).
double value_at(const Surface& s, const ScalarField& phi, const VectorField* gradients, const Location& at) {
  const std::array<int, 3>& c = s.corners[at.face];
  const double value = at.b[0] * phi[c[0]] + at.b[1] * phi[c[1]] + at.b[2] * phi[c[2]];
  if (!gradients) return value;
  const Vec3 x = position(s, at);
  double taylor = 0, lo = phi[c[0]], hi = phi[c[0]];
  for (int j = 0; j < 3; ++j) {
    taylor += at.b[j] * (phi[c[j]] + OpenMesh::dot((*gradients)[c[j]], x - s.points[c[j]]));
    lo = std::min(lo, phi[c[j]]);
    hi = std::max(hi, phi[c[j]]);
  }
  return std::clamp(0.5 * (value + taylor), lo, hi);
}

void check_inputs(const SurfaceMesh& mesh, std::size_t phi_size, std::size_t other_size, double T,
                  const AdvectionOptions& options, const char* what) {
  if (phi_size != mesh.n_vertices())
    throw InputError("advect: phi has " + std::to_string(phi_size) + " values, the mesh " +
                     std::to_string(mesh.n_vertices()) + " vertices");
  if (other_size != mesh.n_vertices())
    throw InputError(std::string("advect: ") + what + " has " + std::to_string(other_size) + " values, the mesh " +
                     std::to_string(mesh.n_vertices()) + " vertices");
  if (!std::isfinite(T) || T < 0) throw InputError("advect: the time must be finite and non-negative");
  if (options.rk_order != 2 && options.rk_order != 4) throw InputError("advect: rk_order must be 2 or 4");
  if (!(options.max_cells_per_substep > 0)) throw InputError("advect: max_cells_per_substep must be positive");
  if (options.steps < 1) throw InputError("advect: steps must be at least 1");
  if (!(options.max_substeps >= 0)) throw InputError("advect: max_substeps must be ≥ 0 (0: no limit)");
}

/// |v| without overflow of the squares (|V| = 1e200 is finite, its square is not).
double length_of(const Vec3& v) {
  const double scale = std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
  if (!(scale > 0) || !std::isfinite(scale)) return scale;
  return scale * (v / scale).norm();
}

/// Largest |V| over `vertices` (all when empty); InputError at a non-finite V.
double largest_speed(const VectorField& velocity, std::span<const int> vertices) {
  auto speed = [&](std::size_t v) {
    const double value = length_of(velocity[v]);
    if (!std::isfinite(value))
      throw InputError(fmt::format("advect: the velocity at vertex {} is not finite ({}, {}, {})", v + 1,
                                   velocity[v][0], velocity[v][1], velocity[v][2]));
    return value;
  };
  const std::size_t n = vertices.empty() ? velocity.size() : vertices.size();
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, 4096), 0.0,
      [&](const tbb::blocked_range<std::size_t>& range, double largest) {
        for (std::size_t k = range.begin(); k != range.end(); ++k)
          largest = std::max(largest, speed(vertices.empty() ? k : std::size_t(vertices[k])));
        return largest;
      },
      [](double a, double b) { return std::max(a, b); });
}

/// The sub-steps one trace may take: its fastest possible crossing of the smallest face, with the
/// margin of the step sizing (a step is kept while it crosses more than half the cells asked for).
std::size_t substep_bound(const Surface& s, double vmax, double T, const AdvectionOptions& options) {
  const double cells = s.shortest_face > 0 ? vmax * T / (options.max_cells_per_substep * s.shortest_face)
                                           : std::numeric_limits<double>::infinity();
  const double bound = 4 * cells + 4.0 * options.steps + 16;
  return bound < 1e18 ? std::size_t(bound) : std::size_t(1e18);
}

/// Refuse a call whose estimated sub-steps (each traced vertex's |V|·T in cells of its face, at
/// least `steps`) exceed options.max_substeps, before any tracing.
void check_substep_budget(const Surface& s, const VectorField& velocity, std::span<const int> order, double T,
                          const AdvectionOptions& options) {
  if (options.max_substeps == 0) return;
  const double cells = options.max_cells_per_substep;
  const double total = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, order.size(), 4096), 0.0,
      [&](const tbb::blocked_range<std::size_t>& range, double sum) {
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
          const int v = order[k];
          const int f = s.vertex_face[v];
          if (f < 0) continue;
          const double length = double(s.face_length[f]);
          const double reach = length > 0 ? length_of(velocity[v]) * T / (cells * length) : 0.0;
          sum += std::max(double(options.steps), std::ceil(reach));
        }
        return sum;
      },
      [](double a, double b) { return a + b; });
  if (total > options.max_substeps)
    throw InputError(fmt::format(
        "advect: about {:.3g} sub-steps for {} characteristics (T = {}, {} edge length(s) per sub-step), above the "
        "limit of {:.3g}; shorten the time or the velocity, or raise the limit (advect --max-substeps, "
        "[advection] max_substeps; 0: no limit)",
        total, order.size(), T, cells, options.max_substeps));
}

/// Trace the vertices of `order` and write φ(T) at them into out (φ at the foot, P1 or corrected
/// with the vertex `gradients` of φ).
void trace_vertices(const Surface& s, const ScalarField& phi, const VectorField* gradients, std::span<const int> order,
                    double T, const AdvectionOptions& options, std::uint32_t epoch, double vmax, ScalarField& out,
                    AdvectionReport* report) {
  const std::size_t max_substeps = substep_bound(s, vmax, T, options);
  TraceTotals totals;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), 256), [&](const tbb::blocked_range<std::size_t>& range) {
    TraceCounts counts;
    std::vector<Crossed> path;  // scratch for RK4 stages
    for (std::size_t k = range.begin(); k != range.end(); ++k) {
      const int v = order[k];
      if (s.vertex_face[v] < 0) {  // isolated vertex: nothing carries it
        out[v] = phi[v];
        continue;
      }
      const Location start = vertex_location(s, v);
      const TraceResult r = trace(s, start, T, options, epoch, max_substeps, path);
      out[v] = value_at(s, phi, r.outside ? nullptr : gradients, r.foot);
      counts.add(r);
    }
    totals.add(counts);
  });
  totals.report_to(report);
}

/// The composed characteristics of one step's CFL sub-steps (Advector::start_composition): each
/// vertex's foot, on the step's initial level set φ0, of its characteristic over the sub-steps so
/// far. φ0 is interpolated once per value, at the composed foot; what is interpolated every
/// sub-step is the foot map, which is smooth where the characteristics do not meet.
struct Composition {
  bool started = false;
  ScalarField base;             ///< φ0
  VectorField base_gradients;   ///< its vertex gradients (correction, and placing new feet)
  std::vector<Location> feet;   ///< valid where `carried` is the previous call
  std::vector<Location> fresh;  ///< this call's feet of the traced vertices
  std::vector<unsigned char> composed;  ///< this call: the traced vertex's foot was composed
  std::vector<std::uint32_t> carried;   ///< the call that set the vertex's foot
  std::uint32_t calls = 0;
};

/// Never a previous call: the foot must be placed again.
constexpr std::uint32_t kNoFoot = std::numeric_limits<std::uint32_t>::max();

/// Feet spread this many times more than the corners they come from: characteristics that meet
/// (two fronts merging), where the foot map is not smooth and its interpolation lands between
/// them; there φ is interpolated as without composition.
constexpr double kMeetingSpread = 4.0;

/// A foot for a vertex that no previous call carried (it just entered the band or the traced
/// set): where φ0 has its current value, walking from it along −∇φ0 (a distance, so by the
/// difference); far from the front, where the characteristics are the normals of φ0.
Location place_foot(const Surface& s, const Composition& c, const ScalarField& phi, int v) {
  Location at = vertex_location(s, v);
  const Vec3& g = c.base_gradients[v];
  const double length = g.norm();
  const double travel = c.base[v] - phi[v];
  if (length > 1e-12 && travel != 0) walk_by(s, at, (-travel / length) * g);
  return at;
}

/// Trace the vertices of `order` over T and write φ0 at their composed feet into out (composition
/// fresh/composed filled); where the feet cannot be composed, φ at the foot as trace_vertices does.
void trace_composed(const Surface& s, Composition& c, const ScalarField& phi, const VectorField* gradients,
                    std::span<const int> order, double T, const AdvectionOptions& options, std::uint32_t epoch,
                    double vmax, ScalarField& out, AdvectionReport* report) {
  const std::size_t max_substeps = substep_bound(s, vmax, T, options);
  const std::uint32_t previous = c.calls - 1;
  const VectorField* base_gradients = gradients ? &c.base_gradients : nullptr;
  TraceTotals totals;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), 256), [&](const tbb::blocked_range<std::size_t>& range) {
    TraceCounts counts;
    std::vector<Crossed> path;
    for (std::size_t k = range.begin(); k != range.end(); ++k) {
      const int v = order[k];
      c.composed[v] = 0;
      if (s.vertex_face[v] < 0) {
        out[v] = phi[v];
        continue;
      }
      const TraceResult r = trace(s, vertex_location(s, v), T, options, epoch, max_substeps, path);
      const std::array<int, 3>& corner = s.corners[r.foot.face];
      bool composable = !r.outside && !r.stalled && c.carried[corner[0]] == previous &&
                        c.carried[corner[1]] == previous && c.carried[corner[2]] == previous;
      if (composable) {
        // The foot map interpolated at this sub-step's foot: the 3-D mean of the corners' feet,
        // reached by walking from the foot of the nearest corner.
        const Vec3 y = position(s, r.foot);
        Vec3 target(0, 0, 0);
        Vec3 foot_of[3];
        int nearest = 0;
        for (int j = 0; j < 3; ++j) {
          foot_of[j] = position(s, c.feet[corner[j]]);
          target += r.foot.b[j] * foot_of[j];
          if (r.foot.b[j] > r.foot.b[nearest]) nearest = j;
        }
        double spread = 0, reach = 0;
        for (int j = 0; j < 3; ++j) {
          spread = std::max(spread, (foot_of[j] - target).norm());
          reach = std::max(reach, (s.points[corner[j]] - y).norm());
        }
        Location foot = c.feet[corner[nearest]];
        composable = spread <= kMeetingSpread * reach && walk_by(s, foot, target - foot_of[nearest]) == WalkEnd::arrived;
        if (composable) {
          c.fresh[v] = foot;
          c.composed[v] = 1;
          out[v] = value_at(s, c.base, base_gradients, foot);
        }
      }
      if (!composable) out[v] = value_at(s, phi, r.outside ? nullptr : gradients, r.foot);
      counts.add(r);
    }
    totals.add(counts);
  });
  totals.report_to(report);
}

}  // namespace

struct Advector::Impl {
  Impl(const SurfaceMesh& m, std::span<const int> faces)
      : mesh(m), surface(build_surface(m, faces)), partial(!faces.empty()) {}
  const SurfaceMesh& mesh;
  Surface surface;
  bool partial;                           ///< built on some faces only: band calls only
  std::uint32_t epoch = 0;
  VectorField gradients;                  ///< of φ, where the current call needs them
  std::vector<std::uint32_t> vertex_seen;  ///< band calls: = epoch for the vertices where V is known
  std::vector<int> faces, order;          ///< band calls: faces with V known at 3 corners; traced in Z-order
  Composition composition;                ///< composed band calls

  /// What a band call needs before tracing: V on the faces with three known corners, φ's gradients
  /// at the known vertices; the traced vertices in Z-order. Returns the call's epoch and max |V|.
  std::pair<std::uint32_t, double> prepare_band(const ScalarField& phi, const VectorField& velocity, double T,
                                                std::span<const int> traced, std::span<const int> known,
                                                const ScalarField& out, const AdvectionOptions& options);
};

Advector::Advector(const SurfaceMesh& mesh) : impl_(std::make_unique<Impl>(mesh, std::span<const int>())) {}
Advector::Advector(const SurfaceMesh& mesh, std::span<const int> faces) : impl_(std::make_unique<Impl>(mesh, faces)) {}
Advector::~Advector() = default;
Advector::Advector(Advector&&) noexcept = default;

ScalarField Advector::advect(const ScalarField& phi, const VectorField& velocity, double T,
                             const AdvectionOptions& options, AdvectionReport* report) {
  Impl& a = *impl_;
  if (a.partial) throw std::logic_error("Advector::advect: built on part of the mesh, it advects bands only");
  check_inputs(a.mesh, phi.size(), velocity.size(), T, options, "the velocity");
  Surface& s = a.surface;
  const double vmax = largest_speed(velocity, {});
  check_substep_budget(s, velocity, s.vertex_order, T, options);
  const std::uint32_t epoch = ++a.epoch;
  tbb::parallel_for(tbb::blocked_range<int>(0, int(s.faces.size()), 4096), [&](const tbb::blocked_range<int>& range) {
    for (int slot = range.begin(); slot != range.end(); ++slot) fill_motion(s, slot, velocity, epoch);
  });
  if (options.gradient_correction) a.gradients = vertex_gradients(a.mesh, phi);
  ScalarField out(phi.size(), 0.0);
  trace_vertices(s, phi, options.gradient_correction ? &a.gradients : nullptr, s.vertex_order, T, options, epoch, vmax,
                 out, report);
  return out;
}

std::pair<std::uint32_t, double> Advector::Impl::prepare_band(const ScalarField& phi, const VectorField& velocity,
                                                             double T, std::span<const int> traced,
                                                             std::span<const int> known, const ScalarField& out,
                                                             const AdvectionOptions& options) {
  check_inputs(mesh, phi.size(), velocity.size(), T, options, "the velocity");
  if (out.size() != phi.size()) throw InputError("advect_band: the output has one value per vertex");
  Surface& s = surface;
  const std::size_t nv = s.points.size();
  const double vmax = largest_speed(velocity, known);
  check_substep_budget(s, velocity, traced, T, options);
  const std::uint32_t call = ++epoch;
  if (s.fan_start.empty()) build_fans(s);
  vertex_seen.resize(nv, 0);
  for (int v : known) vertex_seen[v] = call;
  // The faces whose three corners have V: each once, found from its lowest known corner.
  faces.clear();
  for (int v : known)
    for (int j = s.fan_start[v]; j < s.fan_start[v + 1]; ++j) {
      const std::array<int, 3>& c = s.corners[s.fan[j]];
      if (vertex_seen[c[0]] == call && vertex_seen[c[1]] == call && vertex_seen[c[2]] == call &&
          v == std::min({c[0], c[1], c[2]}))
        faces.push_back(s.fan[j]);
    }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, faces.size(), 1024), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t k = range.begin(); k != range.end(); ++k) fill_motion(s, faces[k], velocity, call);
  });
  if (options.gradient_correction) {
    gradients.resize(nv);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, known.size(), 512), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t k = range.begin(); k != range.end(); ++k)
        gradients[known[k]] = vertex_gradient(mesh, VertexHandle(known[k]), phi);
    });
  }
  // Z-order for the traces, as in a full call.
  order.assign(traced.begin(), traced.end());
  std::sort(order.begin(), order.end(), [&](int u, int w) { return s.vertex_rank[u] < s.vertex_rank[w]; });
  return {call, vmax};
}

void Advector::advect_band(const ScalarField& phi, const VectorField& velocity, double T, std::span<const int> traced,
                           std::span<const int> known, ScalarField& out, const AdvectionOptions& options,
                           AdvectionReport* report) {
  Impl& a = *impl_;
  const auto [epoch, vmax] = a.prepare_band(phi, velocity, T, traced, known, out, options);
  trace_vertices(a.surface, phi, options.gradient_correction ? &a.gradients : nullptr, a.order, T, options, epoch, vmax,
                 out, report);
}

void Advector::start_composition(const ScalarField& phi0) {
  Impl& a = *impl_;
  if (phi0.size() != a.mesh.n_vertices())
    throw InputError(fmt::format("start_composition: {} values for {} vertices", phi0.size(), a.mesh.n_vertices()));
  Composition& c = a.composition;
  const Surface& s = a.surface;
  const std::size_t nv = s.points.size();
  c.started = true;
  c.base = phi0;
  c.base_gradients = vertex_gradients(a.mesh, phi0);
  c.feet.resize(nv);
  c.fresh.resize(nv);
  c.composed.assign(nv, 0);
  // Every foot is its vertex before the first sub-step (the first call's previous one is 0).
  c.calls = 0;
  c.carried.assign(nv, 0);
  for (std::size_t v = 0; v < nv; ++v)
    if (s.vertex_face[v] >= 0) c.feet[v] = vertex_location(s, int(v));
    else c.carried[v] = kNoFoot;
}

void Advector::advect_band_composed(const ScalarField& phi, const VectorField& velocity, double T,
                                    std::span<const int> traced, std::span<const int> known, ScalarField& out,
                                    const AdvectionOptions& options, AdvectionReport* report) {
  Impl& a = *impl_;
  Composition& c = a.composition;
  if (!c.started) throw InputError("advect_band_composed: start_composition was not called");
  const auto [epoch, vmax] = a.prepare_band(phi, velocity, T, traced, known, out, options);
  const Surface& s = a.surface;
  const std::uint32_t previous = c.calls++;
  // The known vertices no previous call carried get a foot where φ0 has their value.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, known.size(), 512), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t k = range.begin(); k != range.end(); ++k) {
      const int v = known[k];
      if (c.carried[v] == previous || s.vertex_face[v] < 0) continue;
      c.feet[v] = place_foot(s, c, phi, v);
      c.carried[v] = previous;
    }
  });
  trace_composed(s, c, phi, options.gradient_correction ? &a.gradients : nullptr, a.order, T, options, epoch, vmax,
                 out, report);
  for (int v : a.order) {
    c.carried[v] = c.composed[v] ? c.calls : kNoFoot;
    if (c.composed[v]) c.feet[v] = c.fresh[v];
  }
}

ScalarField advect(const SurfaceMesh& mesh, const ScalarField& phi, const VectorField& velocity, double T,
                   const AdvectionOptions& options, AdvectionReport* report) {
  check_inputs(mesh, phi.size(), velocity.size(), T, options, "the velocity");
  return Advector(mesh).advect(phi, velocity, T, options, report);
}

ScalarField advect_normal(const SurfaceMesh& mesh, const ScalarField& phi, const ScalarField& normal_speed,
                          double T, const AdvectionOptions& options, AdvectionReport* report) {
  check_inputs(mesh, phi.size(), normal_speed.size(), T, options, "the normal speed");
  const VectorField grad = vertex_gradients(mesh, phi);
  // A gradient this much smaller than the largest one is a flat spot of φ: no direction, V = 0.
  double largest = 0;
  for (const Vec3& g : grad) largest = std::max(largest, g.norm());
  const double vanishing = 1e-12 * largest;
  VectorField velocity(grad.size(), Vec3(0, 0, 0));
  for (std::size_t i = 0; i < grad.size(); ++i) {
    const double len = grad[i].norm();
    if (len > vanishing) velocity[i] = (normal_speed[i] / len) * grad[i];
  }
  return advect(mesh, phi, velocity, T, options, report);
}

}  // namespace bodyfit
